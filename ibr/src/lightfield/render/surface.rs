//! Depth correction's geometry, eight rays at a time: where the capture cameras sit, where
//! a camera sees a point of a ray on the `st` plane, and the fixed point that finds each
//! ray's surface point ([`Kernel::surfaces`]).

use super::kernel::{Images, Kernel};
use super::rays::Batch;
use super::source::Source;
use crate::lightfield::Slab;
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

    /// The `st` coordinates where `eyes` see `point`, and the lanes where they are
    /// finite.
    #[inline(always)]
    pub(super) fn project(&self, eyes: &Eyes, point: &Point) -> (F8, F8, M8) {
        let m = point
            .scale
            .unwrap_or_else(|| F8::splat(self.gap) / (point.z - eyes.z));
        let half = F8::splat(0.5);
        let s = eyes.s + m * (point.s - eyes.s) - half;
        let t = eyes.t + m * (point.t - eyes.t) - half;
        let finite = s.within(f32::INFINITY).and(t.within(f32::INFINITY));
        (s, t, finite)
    }
}

impl<S: Source> Kernel<'_, S> {
    /// Where each batch's rays meet the surface: the lanes that found it, how far along
    /// the ray, and its distance from the `uv` plane, as the nearest camera saw it
    /// ([`Kernel::follow`]).
    #[inline(always)]
    pub(super) fn surfaces<const N: usize>(
        &self,
        rays: [&Batch; N],
        hit: [M8; N],
    ) -> [(M8, F8, F8); N] {
        let near = rays.map(|r| (self.nearest(r.u, 0), self.nearest(r.v, 1)));
        self.follow(rays, hit, near)
    }

    /// The surface along each ray as camera `cams[b]` (per lane) saw it, followed to a
    /// fixed point: start where the ray crosses the focal plane, read the depth the camera
    /// saw there, move along the ray to that depth, and again (four times at most; a lane
    /// is done when it reads a sample twice in a row, as all after it would be). Each step
    /// depends on the one before: the `N` batches' steps interleave, and a step is one
    /// division from the depth read to the next place ([`Cameras::project`] rearranged:
    /// `k1 + k2 / (z - ez)`).
    #[inline(always)]
    fn follow<const N: usize>(
        &self,
        rays: [&Batch; N],
        hit: [M8; N],
        cams: [(I8, I8); N],
    ) -> [(M8, F8, F8); N] {
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
        let mut last = [(I8::splat(-1), I8::splat(-1)); N];
        let (mut active, mut found) = (hit, [none; N]);
        let (mut along, mut z) = ([zero; N], [zero; N]);
        for _ in 0..4 {
            let mut any = false;
            for b in 0..N {
                let at = (self.nearest(st[b].0, 2), self.nearest(st[b].1, 3));
                active[b] = active[b].and_not(at.0.eq(last[b].0).and(at.1.eq(last[b].1)));
                if active[b].bits() == 0 {
                    continue;
                }
                any = true;
                last[b] = at;
                let seen = self.depths(&images[b], at.0, at.1, active[b]);
                let to = (seen - rays[b].from_uv) / rays[b].rate;
                let ok = seen
                    .gt(zero)
                    .and(seen.within(f32::INFINITY))
                    .and(to.gt(zero));
                active[b] = active[b].and(ok);
                found[b] = found[b].or(active[b]);
                along[b] = active[b].select(to, along[b]);
                z[b] = active[b].select(seen, z[b]);
                let d = seen - ez[b];
                let next = (k1[b].0 + k2[b].0 / d, k1[b].1 + k2[b].1 / d);
                let finite = next
                    .0
                    .within(f32::INFINITY)
                    .and(next.1.within(f32::INFINITY));
                active[b] = active[b].and(finite);
                st[b] = next;
            }
            if !any {
                break;
            }
        }
        std::array::from_fn(|b| (found[b], along[b], z[b]))
    }
}
