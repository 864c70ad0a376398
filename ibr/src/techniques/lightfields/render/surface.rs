//! Depth correction's geometry, eight rays at a time: where the capture cameras sit, where
//! a camera sees a point of a ray on the `st` plane, and the fixed point that finds each
//! ray's surface point ([`Kernel::surfaces`]).

use super::kernel::{Images, Kernel};
use super::rays::Batch;
use super::source::Source;
use crate::techniques::lightfields::Slab;
use engine::simd::{F8, I8, M8};

/// A quantity affine in a camera's place on the `uv` plane: at fractions `(a, b)` of its
/// edges it is `at0 + a da + b db`.
#[derive(Clone, Copy, Debug)]
struct Affine {
    at0: f32,
    da: f32,
    db: f32,
}

impl Affine {
    #[inline(always)]
    fn at(&self, a: F8, b: F8) -> F8 {
        F8::splat(self.at0) + a * F8::splat(self.da) + b * F8::splat(self.db)
    }
}

/// The capture cameras as depth correction projects through them.
#[derive(Clone, Copy, Debug)]
pub(super) struct Cameras {
    /// The `st` plane's distance from the `uv` plane along the slab's forward.
    gap: f32,
    /// `1 / nu`, `1 / nv`.
    inv: [f32; 2],
    /// A camera's `st` coordinates ([`Eyes`]) and distance from the `uv` plane.
    at: [Affine; 3],
    /// Whether the cameras all lie in the `uv` plane's plane (their distance from it is
    /// zero).
    parallel: bool,
    /// The middle of the images' sample range along `s` and `t`: `(n - 1) / 2`.
    mid: [f32; 2],
}

/// Eight cameras: their places in `st` sample units (centres at `+ 0.5`) and their
/// distances from the `uv` plane along the slab's forward (zero, but for rounding and
/// planes parallel within tolerance).
#[derive(Clone, Copy)]
pub(super) struct Eyes {
    s: F8,
    t: F8,
    z: F8,
}

impl Default for Eyes {
    fn default() -> Self {
        let zero = F8::splat(0.0);
        Eyes {
            s: zero,
            t: zero,
            z: zero,
        }
    }
}

/// Points on eight rays as the cameras see them: where they sit along `st`'s edges (in
/// samples), their distance `z` from the `uv` plane, and, when the cameras all lie in the
/// `uv` plane's plane, the scale `gap / z` from a point's offset from a camera to where the
/// camera sees it on the `st` plane.
#[derive(Clone, Copy)]
pub(super) struct Point {
    s: F8,
    t: F8,
    pub(super) z: F8,
    scale: Option<F8>,
}

impl Point {
    /// A point no camera is asked about.
    pub(super) fn none() -> Point {
        let zero = F8::splat(0.0);
        Point {
            s: zero,
            t: zero,
            z: zero,
            scale: None,
        }
    }
}

impl Cameras {
    pub(super) fn new(slab: &Slab) -> Self {
        let toward = slab.forward();
        let (uv, st) = (&slab.uv, &slab.st);
        let [ns, nt] = [slab.ns, slab.nt].map(|n| n as f32);
        let a = st.edge_a / st.edge_a.length_squared() * ns;
        let b = st.edge_b / st.edge_b.length_squared() * nt;
        let affine = |along: glam::Vec3, at0: f32| Affine {
            at0,
            da: uv.edge_a.dot(along),
            db: uv.edge_b.dot(along),
        };
        let from_st = uv.origin - st.origin;
        Cameras {
            gap: (st.origin - uv.origin).dot(toward),
            inv: [1.0 / slab.nu as f32, 1.0 / slab.nv as f32],
            at: [
                affine(a, from_st.dot(a)),
                affine(b, from_st.dot(b)),
                affine(toward, 0.0),
            ],
            parallel: uv.edge_a.dot(toward) == 0.0 && uv.edge_b.dot(toward) == 0.0,
            mid: [ns, nt].map(|n| 0.5 * (n - 1.0)),
        }
    }

    /// Where cameras `i` sit along the `uv` plane's edge `axis` (0 or 1), as fractions.
    #[inline(always)]
    pub(super) fn fraction(&self, i: I8, axis: usize) -> F8 {
        (i.to_f32() + F8::splat(0.5)) * F8::splat(self.inv[axis])
    }

    /// The cameras at fractions `(a, b)` of the `uv` plane's edges.
    #[inline(always)]
    pub(super) fn eyes(&self, a: F8, b: F8) -> Eyes {
        Eyes {
            s: self.at[0].at(a, b),
            t: self.at[1].at(a, b),
            z: self.at[2].at(a, b),
        }
    }

    /// The rays' points `along` them at distance `z` from the `uv` plane.
    #[inline(always)]
    pub(super) fn point(&self, rays: &Batch, along: F8, z: F8) -> Point {
        Point {
            s: rays.start_s + along * rays.rate_s,
            t: rays.start_t + along * rays.rate_t,
            z,
            scale: self.parallel.then(|| F8::splat(self.gap) / z),
        }
    }

    /// The lanes whose `st` coordinates `(s, t)` (centres at integers) fall in the
    /// images: a camera sees nothing outside them, and clamping would read its edge.
    #[inline(always)]
    pub(super) fn inside(&self, s: F8, t: F8) -> M8 {
        let [ms, mt] = self.mid;
        (s - F8::splat(ms))
            .within(ms + 0.5)
            .and((t - F8::splat(mt)).within(mt + 0.5))
    }

    /// The `st` coordinates where `eyes` see `point`, and the lanes where they fall in the
    /// camera's image.
    #[inline(always)]
    pub(super) fn project(&self, eyes: &Eyes, point: &Point) -> (F8, F8, M8) {
        let m = point
            .scale
            .unwrap_or_else(|| F8::splat(self.gap) / (point.z - eyes.z));
        let half = F8::splat(0.5);
        let s = eyes.s + m * (point.s - eyes.s) - half;
        let t = eyes.t + m * (point.t - eyes.t) - half;
        (s, t, self.inside(s, t))
    }
}

impl<S: Source> Kernel<'_, S> {
    /// Where each batch's rays meet the surface: the lanes that found it, how far along
    /// the ray, and its distance from the `uv` plane. The nearest camera is asked first
    /// ([`Kernel::follow`]); where it found nothing (it saw nothing there, or saw a
    /// surface the ray passes beside), each of the four cameras around the ray is asked,
    /// and the nearest point any of them found is taken.
    #[inline(always)]
    pub(super) fn surfaces<const N: usize>(
        &self,
        rays: [&Batch; N],
        hit: [M8; N],
    ) -> [Followed; N] {
        let near = rays.map(|r| (self.nearest(r.u, 0), self.nearest(r.v, 1)));
        let mut best = self.follow(rays, hit, near);
        let need: [M8; N] = std::array::from_fn(|b| best[b].unsure);
        if need.iter().all(|m| m.bits() == 0) {
            return best;
        }
        let around = rays.map(|r| (self.pair(r.u, 0).0, self.pair(r.v, 1).0));
        for corner in 0..4 {
            let cams = around.map(|(u, v)| (u[corner & 1], v[corner >> 1]));
            let other = self.follow(rays, need, cams);
            for b in 0..N {
                let (o, w) = (other[b], &mut best[b]);
                let unfound = need[b].and_not(w.found);
                let take = o.found.and(need[b]).and(unfound.or(o.along.lt(w.along)));
                w.found = w.found.or(take);
                w.along = take.select(o.along, w.along);
                w.z = take.select(o.z, w.z);
            }
        }
        best
    }

    /// The surface along each ray as camera `cams[b]` (per lane) saw it: found by a march
    /// along the ray ([`Kernel::march`]), then followed to a fixed point: read the depth
    /// the camera saw there, move along the ray to that depth, and again (four times at
    /// most; a lane is done when it reads a sample twice in a row, as all after it would
    /// be). A lane the march found nothing for, or that then reads nothing (or a point
    /// behind the ray's start, or outside the camera's image), finds nothing. Each step
    /// depends on the one before: the `N` batches' steps interleave, and a step is one
    /// division from the depth read to the next place ([`Cameras::project`] rearranged:
    /// `k1 + k2 / (z - ez)`).
    #[inline(always)]
    fn follow<const N: usize>(
        &self,
        rays: [&Batch; N],
        hit: [M8; N],
        cams: [(I8, I8); N],
    ) -> [Followed; N] {
        let cameras = &self.cameras;
        let (zero, half, gap) = (F8::splat(0.0), F8::splat(0.5), F8::splat(cameras.gap));
        let none = M8::from_bits(0);
        let mut images = [Images::none(); N];
        let mut k1 = [(zero, zero); N];
        let mut k2 = [(zero, zero); N];
        let mut ez = [zero; N];
        let mut st = [(zero, zero); N];
        for b in 0..N {
            let r = rays[b];
            let (ci, cj) = cams[b];
            if hit[b].bits() == 0 {
                continue;
            }
            images[b] = self.images(ci, cj, hit[b]);
            let eye = cameras.eyes(cameras.fraction(ci, 0), cameras.fraction(cj, 1));
            // The ray's place along st's edges per unit of distance from the uv plane,
            // and at the uv plane.
            let (per_s, per_t) = (r.rate_s / r.rate, r.rate_t / r.rate);
            let (at_s, at_t) = (r.start_s - r.from_uv * per_s, r.start_t - r.from_uv * per_t);
            k1[b] = (eye.s - half + gap * per_s, eye.t - half + gap * per_t);
            k2[b] = (
                gap * (at_s - eye.s + eye.z * per_s),
                gap * (at_t - eye.t + eye.z * per_t),
            );
            ez[b] = eye.z;
            st[b] = (r.s, r.t);
        }
        let marched = self.march(rays, hit, &images, k1, k2, ez);
        let mut last = marched.at;
        let (mut active, mut found) = (marched.crossed, [none; N]);
        let (mut along, mut z) = ([zero; N], [zero; N]);
        // The first step's read is the march's.
        for step in 0..5 {
            let mut any = false;
            for b in 0..N {
                let seen = if step == 0 {
                    marched.seen[b]
                } else {
                    let at = (self.nearest(st[b].0, 2), self.nearest(st[b].1, 3));
                    active[b] = active[b].and_not(at.0.eq(last[b].0).and(at.1.eq(last[b].1)));
                    if active[b].bits() == 0 {
                        continue;
                    }
                    last[b] = at;
                    self.depths(&images[b], at.0, at.1, active[b])
                };
                if active[b].bits() == 0 {
                    continue;
                }
                any = true;
                let to = (seen - rays[b].from_uv) / rays[b].rate;
                let ok = seen
                    .gt(zero)
                    .and(seen.within(f32::INFINITY))
                    .and(to.gt(zero));
                // A point found before that the camera now sees nothing at (or behind) was
                // off the surface it saw: the ray passes beside it.
                found[b] = found[b].and_not(active[b].and_not(ok));
                active[b] = active[b].and(ok);
                found[b] = found[b].or(active[b]);
                along[b] = active[b].select(to, along[b]);
                z[b] = active[b].select(seen, z[b]);
                let d = seen - ez[b];
                let next = (k1[b].0 + k2[b].0 / d, k1[b].1 + k2[b].1 / d);
                // Out of the image the camera cannot confirm the point.
                let inside = cameras.inside(next.0, next.1);
                found[b] = found[b].and_not(active[b].and_not(inside));
                active[b] = active[b].and(inside);
                st[b] = next;
            }
            if !any {
                break;
            }
        }
        std::array::from_fn(|b| Followed {
            found: found[b],
            along: along[b],
            z: z[b],
            unsure: hit[b]
                .and_not(found[b])
                .and(marched.unsure[b].or(marched.crossed[b])),
        })
    }

    /// Marches along each ray through the depths the light field holds, in steps of about
    /// one sample of the camera's image (at most [`MARCH_STEPS`]), from the nearest (or the
    /// ray's start) to the farthest, to where the camera first sees a surface at or in
    /// front of the ray's point: the ray has reached what the camera saw there ([`March`]).
    /// Camera `b` sees the ray's point at distance `z` from the `uv` plane at
    /// `k1 + k2 w`, `w = 1 / (z - ez)`: the steps are even in `w`.
    #[inline(always)]
    fn march<const N: usize>(
        &self,
        rays: [&Batch; N],
        hit: [M8; N],
        images: &[Images<S::Image>; N],
        k1: [(F8, F8); N],
        k2: [(F8, F8); N],
        ez: [F8; N],
    ) -> March<N> {
        let none = M8::from_bits(0);
        let (zero, one) = (F8::splat(0.0), F8::splat(1.0));
        let mut out = March {
            crossed: [none; N],
            seen: [zero; N],
            at: [(I8::splat(-1), I8::splat(-1)); N],
            unsure: hit,
        };
        let Some((lo, hi)) = self.range else {
            return out;
        };
        for b in 0..N {
            if hit[b].bits() == 0 {
                continue;
            }
            let r = rays[b];
            let z0 = F8::splat(lo).max(r.from_uv);
            let w0 = one / (z0 - ez[b]);
            let w1 = one / (F8::splat(hi) - ez[b]);
            let span = k2[b].0.abs().max(k2[b].1.abs()) * (w0 - w1);
            let ok = hit[b].and(span.ge(zero)).and(span.within(f32::INFINITY));
            let most = ok
                .select(span, zero)
                .to_array()
                .into_iter()
                .fold(0.0f32, f32::max);
            let n = (most.ceil() as usize).clamp(1, MARCH_STEPS);
            let dw = (w0 - w1) * F8::splat(1.0 / n as f32);
            let mut todo = ok;
            // Lanes that looked outside the image or saw a surface they did not reach.
            let mut unsure = hit[b].and_not(ok);
            for i in 0..=n {
                let w = w0 - dw * F8::splat(i as f32);
                let y = (k1[b].0 + k2[b].0 * w, k1[b].1 + k2[b].1 * w);
                let inside = self.cameras.inside(y.0, y.1);
                unsure = unsure.or(todo.and_not(inside));
                let look = todo.and(inside);
                if look.bits() == 0 {
                    continue;
                }
                let at = (self.nearest(y.0, 2), self.nearest(y.1, 3));
                let seen = self.depths(&images[b], at.0, at.1, look);
                let z = ez[b] + one / w;
                let something = look.and(seen.gt(zero)).and(seen.within(f32::INFINITY));
                let crossed = something.and(seen.le(z));
                unsure = unsure.or(something.and_not(crossed));
                out.seen[b] = crossed.select(seen, out.seen[b]);
                out.at[b] = (
                    crossed.select_i32(at.0, out.at[b].0),
                    crossed.select_i32(at.1, out.at[b].1),
                );
                out.crossed[b] = out.crossed[b].or(crossed);
                todo = todo.and_not(crossed);
                if todo.bits() == 0 {
                    break;
                }
            }
            out.unsure[b] = unsure;
        }
        out
    }
}

/// What [`Kernel::march`] found: the lanes that reached a surface the camera saw, the
/// depth it saw there and the sample it read; and the lanes that may have missed one (they
/// looked outside the image, or saw a surface they did not reach).
struct March<const N: usize> {
    crossed: [M8; N],
    seen: [F8; N],
    at: [(I8, I8); N],
    unsure: [M8; N],
}

/// The surface along eight rays as one camera saw it ([`Kernel::follow`]): the lanes that
/// found it, how far along the ray, its distance from the `uv` plane; and the lanes that
/// found none but where another camera might (the camera saw something near the ray, or
/// the ray left its image).
#[derive(Clone, Copy)]
pub(super) struct Followed {
    pub(super) found: M8,
    pub(super) along: F8,
    pub(super) z: F8,
    unsure: M8,
}

impl Followed {
    /// No surface, and nothing unsure.
    pub(super) fn nothing() -> Self {
        let zero = F8::splat(0.0);
        Followed {
            found: M8::from_bits(0),
            along: zero,
            z: zero,
            unsure: M8::from_bits(0),
        }
    }
}

/// Most steps a ray's march takes through a camera's image.
const MARCH_STEPS: usize = 24;
