//! Eight rays looked up at once, lane by lane as one ray would be: depth correction's
//! surface point ([`Kernel::surfaces`]), each camera around the ray checked and read, the
//! samples blended and the pixels written. Everything is 8-lane arithmetic, lanes that
//! drop out masked, not branched around. Reads are shared where they can be: neighbouring
//! pixels' rays read the same cameras at neighbouring samples, so when every lane that
//! matters reads one camera's image in one row, within eight samples, that row is loaded
//! once and each lane's sample picked out of it (a lane permute); otherwise each lane
//! loads its own. All the cameras are checked before any is read, so their depth reads do
//! not wait on each other; empty samples (all bytes zero) are not blended in.

use super::lanes::{add, as_i8, count, nearest, offsets, pair, uniform, window, ALL};
use super::rays::Batch;
use super::source::Source;
use super::surface::{Cameras, Eyes, Followed, Point};
use super::{LightFieldFrame, Lookup, SAME_SURFACE};
use crate::techniques::lightfields::Slab;
use engine::simd::{F8, I8, LANES, M8};

/// Which image each lane reads: camera `(i[l], j[l])`'s, found once when it is the same
/// for all the lanes that matter (`shared`).
#[derive(Clone, Copy)]
pub(super) struct Images<I> {
    shared: Option<I>,
    i: I8,
    j: I8,
}

impl<I> Images<I> {
    /// No lane's image yet.
    pub(super) fn none() -> Self {
        Images {
            shared: None,
            i: I8::splat(0),
            j: I8::splat(0),
        }
    }
}

/// Where a camera is read around each ray's `(s, t)`: tap `k` (of the first four for
/// quadrilinear, else one) is sample `(s[k & 1], t[k >> 1])`, weighted `weights[k]`
/// (times the camera's weight); and, when every lane that matters reads within one
/// eight-sample window of rows `t[0]` and `t[1]`, those rows, the window's first sample and
/// each lane's place in it for `s[0]` and `s[1]`.
#[derive(Clone, Copy)]
struct Taps {
    s: [I8; 2],
    t: [I8; 2],
    weights: [F8; 4],
    window: Option<([u32; 2], u32, [[u32; LANES]; 2])>,
}

/// A frame's lookup: the source, the sample counts, the cameras' places.
pub(super) struct Kernel<'a, S> {
    src: &'a S,
    correct: bool,
    /// The last sample index along `u, v, s, t`, as a float and as an integer.
    last: [f32; 4],
    last_i: [i32; 4],
    /// Where the capture cameras are, for depth correction.
    pub(super) cameras: Cameras,
    /// The nearest and farthest depth any sample holds: where depth correction looks
    /// for surfaces.
    pub(super) range: Option<(f32, f32)>,
}

impl<'a, S: Source> Kernel<'a, S> {
    pub(super) fn new(slab: &Slab, src: &'a S, lookup: Lookup) -> Self {
        Kernel {
            src,
            correct: lookup.depth_correction,
            last: slab.counts().map(|n| n as f32 - 1.0),
            last_i: slab.counts().map(|n| n as i32 - 1),
            cameras: Cameras::new(slab),
            range: src.depth_range(),
        }
    }

    /// [`nearest`] along `axis` (`u, v, s, t`).
    #[inline(always)]
    pub(super) fn nearest(&self, x: F8, axis: usize) -> I8 {
        nearest(x, F8::splat(self.last[axis]))
    }

    /// [`pair`] along `axis` (`u, v, s, t`).
    #[inline(always)]
    pub(super) fn pair(&self, x: F8, axis: usize) -> ([I8; 2], F8) {
        pair(x, F8::splat(self.last[axis]), I8::splat(self.last_i[axis]))
    }

    /// Lane `l`'s camera `(i[l], j[l])`'s image, shared when the same for the lanes in
    /// `care` (not empty).
    #[inline(always)]
    pub(super) fn images(&self, i: I8, j: I8, care: M8) -> Images<S::Image> {
        let shared = match (uniform(care, i), uniform(care, j)) {
            (Some(u), Some(v)) => Some(self.src.image(u, v)),
            _ => None,
        };
        Images { shared, i, j }
    }

    /// Each lane's image, one by one.
    #[inline(always)]
    fn each_image(&self, images: &Images<S::Image>) -> [S::Image; LANES] {
        let (i, j) = (images.i.to_array(), images.j.to_array());
        let mut each = [S::Image::default(); LANES];
        for (l, e) in each.iter_mut().enumerate() {
            *e = images
                .shared
                .unwrap_or_else(|| self.src.image(i[l] as u32, j[l] as u32));
        }
        each
    }

    /// Each lane's depth at `(s, t)` of its image, for the lanes in `care` (not empty;
    /// the others read something): one row window when they share it ([`window`]), else
    /// a load per lane.
    #[inline(always)]
    pub(super) fn depths(&self, images: &Images<S::Image>, s: I8, t: I8, care: M8) -> F8 {
        if let Some(image) = images.shared {
            if let Some((r, start)) = window(care, t, s, s, self.src.align()) {
                if let Some(w) = self.src.depth_row(image, r, start) {
                    return w.permute(offsets(s, start));
                }
            }
        }
        let (s, t) = (s.to_array(), t.to_array());
        let each = self.each_image(images);
        let mut out = [0.0; LANES];
        for (l, o) in out.iter_mut().enumerate() {
            *o = self.src.depth(each[l], s[l] as u32, t[l] as u32);
        }
        F8::from_array(out)
    }

    /// The taps around coordinates `(s, t)` ([`Taps`]), their row window found for the
    /// lanes in `care` (not empty).
    #[inline(always)]
    fn taps<const TAPS: usize>(&self, s: F8, t: F8, care: M8) -> Taps {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let align = self.src.align();
        if TAPS == 4 {
            let (ss, fs) = self.pair(s, 2);
            let (ts, ft) = self.pair(t, 3);
            let (gs, gt) = (one - fs, one - ft);
            let window = window(care, ts[0], ss[0], ss[1], align).map(|(r, start)| {
                let rows = [r, (r + 1).min(self.last_i[3] as u32)];
                (rows, start, [offsets(ss[0], start), offsets(ss[1], start)])
            });
            Taps {
                s: ss,
                t: ts,
                weights: [gs * gt, fs * gt, gs * ft, fs * ft],
                window,
            }
        } else {
            let (is, it) = (self.nearest(s, 2), self.nearest(t, 3));
            let window = window(care, it, is, is, align)
                .map(|(r, start)| ([r; 2], start, [offsets(is, start); 2]));
            Taps {
                s: [is; 2],
                t: [it; 2],
                weights: [one, zero, zero, zero],
                window,
            }
        }
    }

    /// Packed colours of the first `TAPS` of `taps` in each lane's image: row windows
    /// when the images are shared and the taps' window found, else a load per lane and
    /// tap.
    #[inline(always)]
    fn read_taps<const TAPS: usize>(&self, images: &Images<S::Image>, taps: &Taps) -> [I8; 4] {
        let zero = I8::splat(0);
        if let (Some(image), Some((rows, start, o))) = (images.shared, &taps.window) {
            let (rows, start) = (*rows, *start);
            if TAPS == 1 {
                if let Some(w0) = self.src.sample_row(image, rows[0], start) {
                    return [as_i8(w0.permute(o[0])), zero, zero, zero];
                }
            } else if let Some([w0, w1]) = self.src.sample_rows(image, rows, start) {
                return [
                    w0.permute(o[0]),
                    w0.permute(o[1]),
                    w1.permute(o[0]),
                    w1.permute(o[1]),
                ]
                .map(as_i8);
            }
        }
        let s = taps.s.map(|x| x.to_array().map(|i| i as u32));
        let t = taps.t.map(|x| x.to_array().map(|i| i as u32));
        let each = self.each_image(images);
        let mut q = [[0u32; LANES]; 4];
        for l in 0..LANES {
            let image = each[l];
            for (k, q) in q.iter_mut().enumerate().take(TAPS) {
                q[l] = self.src.sample(image, s[k & 1][l], t[k >> 1][l]);
            }
        }
        q.map(|q| I8::from_array(q.map(|c| c as i32)))
    }

    /// Looks up the rays of each of the `N` batches `rays` in its lanes `hits` (not
    /// none) and writes those that find something to lane `l`'s pixel `l` of its
    /// `(colors, disparities)`; the work done. `CAMERAS` and `TAPS` give the
    /// interpolation: one of each for the nearest sample, four cameras of one for
    /// bilinear in `uv`, four of four for quadrilinear.
    #[inline(always)]
    pub(super) fn shade<const CAMERAS: usize, const TAPS: usize, const N: usize>(
        &self,
        rays: [&Batch; N],
        hits: [u32; N],
        out: [(&mut [u32], &mut [f32]); N],
    ) -> LightFieldFrame {
        let hit = hits.map(M8::from_bits);
        let surfaces = if self.correct {
            self.surfaces(rays, hit)
        } else {
            [Followed::nothing(); N]
        };
        let mut frame = LightFieldFrame::default();
        for (b, (colors, disparities)) in out.into_iter().enumerate() {
            frame += self.blend::<CAMERAS, TAPS>(rays[b], hit[b], surfaces[b], colors, disparities);
        }
        frame
    }

    /// [`Kernel::shade`] for one batch, its surface found.
    #[inline(always)]
    fn blend<const CAMERAS: usize, const TAPS: usize>(
        &self,
        rays: &Batch,
        hit: M8,
        surface: Followed,
        colors: &mut [u32],
        disparities: &mut [f32],
    ) -> LightFieldFrame {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let cams = &self.cameras;
        let Followed {
            found, along, z, ..
        } = surface;
        let point = if self.correct {
            cams.point(rays, along, z)
        } else {
            Point::none()
        };
        let (cameras, eyes, shared) = self.around::<CAMERAS>(rays, hit, found);
        // Each camera's weight, the lanes it counts in, its images and, where depth
        // correction moved them, the coordinates it is read at: all the cameras checked
        // first (their depth reads are independent), then read.
        let mut weights = [zero; CAMERAS];
        let mut cares = [M8::from_bits(0); CAMERAS];
        let mut images = [Images::none(); CAMERAS];
        let mut moved = [None; CAMERAS];
        for k in 0..CAMERAS {
            let (i, j, mut w) = cameras[k];
            // Weights are never negative: zero or not.
            let mut care = w.gt(zero);
            if care.bits() != 0 {
                images[k] = match shared[k] {
                    Some(image) => Images {
                        shared: Some(image),
                        i,
                        j,
                    },
                    None => self.images(i, j, care),
                };
                let check = found.and(care);
                if check.bits() != 0 {
                    let (out, s, t) = self.seen(rays, found, &point, &eyes[k], &images[k], check);
                    w = out.select(zero, w);
                    care = care.and_not(out);
                    moved[k] = Some((s, t));
                }
            }
            weights[k] = w;
            cares[k] = care;
        }
        let (mut acc, mut total) = ([zero; 4], zero);
        // Taps read (with weight: not zero).
        let mut taps_read = 0u32;
        // Lanes where a camera that counts saw nothing at any of its taps.
        let mut disagree = M8::from_bits(0);
        // The taps where the rays cross the focal plane: the same for all the cameras not
        // moved (found once, for all the rays that hit).
        let mut flat = None;
        for k in 0..CAMERAS {
            let w = weights[k];
            total = total + w;
            // A ray without a surface that a camera before saw nothing for is not drawn:
            // the cameras after need not read it.
            let care = if self.correct {
                cares[k].and_not(disagree.and_not(found))
            } else {
                cares[k]
            };
            if care.bits() == 0 {
                continue;
            }
            let w = care.select(w, zero);
            let taps = match moved[k] {
                Some((s, t)) => self.taps::<TAPS>(s, t, care),
                None => *flat.get_or_insert_with(|| self.taps::<TAPS>(rays.s, rays.t, hit)),
            };
            let colors = self.read_taps::<TAPS>(&images[k], &taps);
            let mut saw = M8::from_bits(0);
            for (c, weight) in colors.into_iter().zip(taps.weights).take(TAPS) {
                let wt = w * weight;
                let alpha = c.and(I8::splat(0xff00_0000_u32 as i32));
                saw = saw.or(wt.gt(zero).and_not(alpha.eq(I8::splat(0))));
                let counted = wt.gt(zero).bits();
                taps_read += counted.count_ones();
                // Empty samples (all bytes zero) add nothing: skipped where every lane
                // that counts has one (light fields of objects have much empty space).
                if (c.eq(I8::splat(0)).bits() | !counted) & ALL != ALL {
                    add(&mut acc, c, wt);
                }
            }
            disagree = disagree.or(care.and_not(saw));
        }
        let taps = u64::from(taps_read);
        // Cameras left out give their weight to the others.
        let partial = total.gt(zero).and(total.lt(one));
        let acc = acc.map(|a| partial.select(a / total, a));
        // With depth correction, a ray along which no camera around it found a surface
        // is drawn (uncorrected) only where every camera saw something at the focal
        // plane: a silhouette's edge between samples, not one camera's shifted copy of a
        // part the ray passes by (a ghost).
        let drawn = if self.correct {
            found.or(hit.and_not(disagree))
        } else {
            hit
        };
        let write = drawn.and(acc[3].gt(zero));
        let frame = LightFieldFrame {
            rays: count(hit),
            taps,
            pixels: count(write),
        };
        if frame.pixels == 0 {
            return frame;
        }
        let depth = found.select(along * rays.rate_view, rays.flat_depth);
        Self::write(&acc, depth, write, colors, disparities);
        frame
    }

    /// Where the camera at `eyes` saw the surface `point` of the rays that `check`: the
    /// lanes it leaves out of the blend (it saw something else there, nearer or nothing)
    /// and the coordinates it is read at (zero where left out).
    #[inline(always)]
    fn seen(
        &self,
        rays: &Batch,
        found: M8,
        point: &Point,
        eyes: &Eyes,
        images: &Images<S::Image>,
        check: M8,
    ) -> (M8, F8, F8) {
        let zero = F8::splat(0.0);
        let (ps, pt, inside) = self.cameras.project(eyes, point);
        let (is, it) = (self.nearest(ps, 2), self.nearest(pt, 3));
        let seen = self.depths(images, is, it, check);
        let z = point.z;
        let same = (seen - z).abs().le(F8::splat(SAME_SURFACE) * z);
        let out = found.and_not(inside.and(same));
        let s = out.select(zero, found.select(ps, rays.s));
        let t = out.select(zero, found.select(pt, rays.t));
        (out, s, t)
    }

    /// The cameras around each ray and their weights (zero in lanes that missed), where
    /// they are when depth correction needs it (some lanes `found` a surface), and each
    /// one's image when all the rays that `hit` share it.
    #[inline(always)]
    #[allow(clippy::type_complexity)] // reason: a hot kernel's three results, named at the call
    fn around<const CAMERAS: usize>(
        &self,
        rays: &Batch,
        hit: M8,
        found: M8,
    ) -> ([(I8, I8, F8); 4], [Eyes; 4], [Option<S::Image>; 4]) {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let cams = &self.cameras;
        let cameras: [(I8, I8, F8); 4];
        let mut eyes = [Eyes::default(); 4];
        let mut shared = [None; 4];
        if CAMERAS == 1 {
            let (i, j) = (self.nearest(rays.u, 0), self.nearest(rays.v, 1));
            cameras = [(i, j, hit.select(one, zero)); 4];
            if found.bits() != 0 {
                eyes[0] = cams.eyes(cams.fraction(i, 0), cams.fraction(j, 1));
            }
            if let (Some(i), Some(j)) = (uniform(hit, i), uniform(hit, j)) {
                shared[0] = Some(self.src.image(i, j));
            }
        } else {
            let ([u0, u1], fu) = self.pair(rays.u, 0);
            let ([v0, v1], fv) = self.pair(rays.v, 1);
            let (gu, gv) = (one - fu, one - fv);
            let weight = |w: F8| hit.select(w, zero);
            cameras = [
                (u0, v0, weight(gu * gv)),
                (u1, v0, weight(fu * gv)),
                (u0, v1, weight(gu * fv)),
                (u1, v1, weight(fu * fv)),
            ];
            if found.bits() != 0 {
                let [a0, a1] = [u0, u1].map(|i| cams.fraction(i, 0));
                let [b0, b1] = [v0, v1].map(|j| cams.fraction(j, 1));
                eyes = [
                    cams.eyes(a0, b0),
                    cams.eyes(a1, b0),
                    cams.eyes(a0, b1),
                    cams.eyes(a1, b1),
                ];
            }
            if let (Some(i), Some(j)) = (uniform(hit, u0), uniform(hit, v0)) {
                let (i1, j1) = (
                    (i + 1).min(self.last_i[0] as u32),
                    (j + 1).min(self.last_i[1] as u32),
                );
                shared =
                    [(i, j), (i1, j), (i, j1), (i1, j1)].map(|(i, j)| Some(self.src.image(i, j)));
            }
        }
        (cameras, eyes, shared)
    }

    /// Writes the blended colours `acc` and the disparities of `depth` to lane `l`'s
    /// pixel `l` of `(colors, disparities)` in the lanes `write`.
    #[inline(always)]
    fn write(acc: &[F8; 4], depth: F8, write: M8, colors: &mut [u32], disparities: &mut [f32]) {
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let byte = |x: F8| {
            (x + F8::splat(0.5))
                .max(zero)
                .min(F8::splat(255.0))
                .to_i32()
        };
        let packed = byte(acc[0])
            .or(byte(acc[1]).shl::<8>())
            .or(byte(acc[2]).shl::<16>())
            .or(byte(acc[3]).shl::<24>());
        let disparity = depth.gt(zero).select(one / depth, zero);
        if colors.len() == LANES && disparities.len() == LANES {
            let packed = write.select_i32(packed, I8::load_u32(colors));
            colors.copy_from_slice(&packed.to_array().map(|c| c as u32));
            disparity.blend_into(write, disparities);
        } else {
            let (packed, disparity) = (packed.to_array(), disparity.to_array());
            let mut bits = write.bits();
            while bits != 0 {
                let l = bits.trailing_zeros() as usize;
                bits &= bits - 1;
                colors[l] = packed[l] as u32;
                disparities[l] = disparity[l];
            }
        }
    }
}
