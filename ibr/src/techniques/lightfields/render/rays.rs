//! The rays of a row, eight pixels at a time: whether each crosses the slab, where it
//! crosses the `uv` and `st` planes, as sample coordinates, and what depth correction and
//! the written depth need of it. The crossings are the same IEEE operations in the same
//! order as one ray at a time with `glam` (a ray's near and far points a row's first
//! pixel's plus `x` steps, divided by their `w`; each plane met by the line's parameter),
//! so a lane's crossings are bit for bit that ray's.

use super::super::{Rect3, Slab};
use engine::simd::{F8, M8};
use engine::Camera;
use glam::{Vec3, Vec4};

/// Three lanes-wide coordinates.
#[derive(Clone, Copy)]
struct V8 {
    x: F8,
    y: F8,
    z: F8,
}

impl V8 {
    #[inline(always)]
    fn dot(self, v: Vec3) -> F8 {
        self.x * F8::splat(v.x) + self.y * F8::splat(v.y) + self.z * F8::splat(v.z)
    }

    #[inline(always)]
    fn minus(self, v: Vec3) -> V8 {
        V8 {
            x: self.x - F8::splat(v.x),
            y: self.y - F8::splat(v.y),
            z: self.z - F8::splat(v.z),
        }
    }
}

/// A rectangle's plane as a ray meets it: a corner, the normal, and the edges divided by
/// their squared lengths (a point's dot product with them is its fraction of each edge).
#[derive(Clone, Copy, Debug)]
struct Plane {
    origin: Vec3,
    normal: Vec3,
    a: Vec3,
    b: Vec3,
    /// At infinity: the rectangle holds directions, met by a ray's direction alone.
    infinite: bool,
}

impl Plane {
    fn of(r: &Rect3, infinite: bool) -> Plane {
        Plane {
            origin: r.origin,
            normal: r.edge_a.cross(r.edge_b),
            a: r.edge_a / r.edge_a.length_squared(),
            b: r.edge_b / r.edge_b.length_squared(),
            infinite,
        }
    }

    /// Where the lines `o + tau d` cross the plane: `tau`, the fractions of the edges, and
    /// the lanes whose rate across the plane is finite. A line parallel to the plane, or
    /// anything not finite, gives a NaN or infinite fraction, which fails any range test;
    /// only an infinite rate (a direction that overflows) could give finite ones, and its
    /// lane is left out. A plane at infinity is met by the line from the origin along `d`,
    /// ahead of it.
    #[inline(always)]
    fn cross(&self, o: V8, d: V8) -> (F8, F8, F8, M8) {
        if self.infinite {
            let zero = F8::splat(0.0);
            let (tau, a, b, ok) = self.cross_finite(
                V8 {
                    x: zero,
                    y: zero,
                    z: zero,
                },
                d,
            );
            return (tau, a, b, ok.and(tau.gt(zero)));
        }
        self.cross_finite(o, d)
    }

    #[inline(always)]
    fn cross_finite(&self, o: V8, d: V8) -> (F8, F8, F8, M8) {
        let along = d.dot(self.normal);
        let to = V8 {
            x: F8::splat(self.origin.x) - o.x,
            y: F8::splat(self.origin.y) - o.y,
            z: F8::splat(self.origin.z) - o.z,
        };
        let tau = to.dot(self.normal) / along;
        let p = V8 {
            x: o.x + d.x * tau,
            y: o.y + d.y * tau,
            z: o.z + d.z * tau,
        }
        .minus(self.origin);
        (
            tau,
            p.dot(self.a),
            p.dot(self.b),
            along.within(f32::INFINITY),
        )
    }
}

/// Eight pixels' rays, lane `l` pixel `x0 + l`. Lanes whose ray misses hold garbage, and
/// so, without depth correction, do `from_uv`, `rate_view` and the `start`s and `rate`s
/// along `st`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Batch {
    /// Sample coordinates (centres at integers) where the rays cross the planes.
    pub u: F8,
    pub v: F8,
    pub s: F8,
    pub t: F8,
    /// Depth (along the view axis) of where the rays cross the `st` plane.
    pub flat_depth: F8,
    /// The rays' starts' distances from the `uv` plane along the slab's forward, and their
    /// directions' rates along it, along the view axis, and along `st`'s edges (in
    /// samples, as are the starts').
    pub from_uv: F8,
    pub rate: F8,
    pub rate_view: F8,
    pub start_s: F8,
    pub rate_s: F8,
    pub start_t: F8,
    pub rate_t: F8,
}

/// A frame's rays: the camera's and the slab's constants.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rays {
    inv: glam::Mat4,
    /// The change of a pixel's near and far points (homogeneous) per pixel along `x`.
    step: Vec4,
    width: f32,
    height: f32,
    forward: Vec3,
    toward: Vec3,
    uv: Plane,
    st: Plane,
    uv_origin: Vec3,
    coords: [f32; 4],
    /// Whether depth correction needs the rays' [`Batch::from_uv`] and the rest.
    correct: bool,
}

impl Rays {
    pub(super) fn new(
        slab: &Slab,
        camera: &Camera,
        width: u32,
        height: u32,
        correct: bool,
    ) -> Self {
        let inv = camera.gl_view_proj().inverse();
        Rays {
            inv,
            step: inv.x_axis * (2.0 / width as f32),
            width: width as f32,
            height: height as f32,
            forward: camera.forward(),
            toward: slab.forward(),
            uv: Plane::of(&slab.uv, slab.infinite[0]),
            st: Plane::of(&slab.st, slab.infinite[1]),
            uv_origin: slab.uv.origin,
            coords: [slab.nu, slab.nv, slab.ns, slab.nt].map(|n| n as f32),
            correct,
        }
    }

    /// Row `y`'s first pixel's near and far points, homogeneous.
    pub(super) fn row(&self, y: usize) -> (Vec4, Vec4) {
        let ndc_x = 1.0 / self.width - 1.0;
        let ndc_y = 1.0 - 2.0 * (y as f32 + 0.5) / self.height;
        (
            self.inv * Vec4::new(ndc_x, ndc_y, -1.0, 1.0),
            self.inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0),
        )
    }

    /// Where the rays of pixels `x0..x0 + 8` of the row starting at `(near0, far0)`
    /// cross the planes, and a bit per lane whose ray crosses both rectangles, the `st`
    /// one ahead of its start, looking from the `uv` side (those past the row's end too).
    #[inline(always)]
    fn cross(&self, (near0, far0): (Vec4, Vec4), x0: usize) -> (Crossing, u32) {
        let x = F8::splat(x0 as f32) + F8::ramp();
        let lane = |base: f32, step: f32| F8::splat(base) + F8::splat(step) * x;
        let s = self.step;
        let nw = lane(near0.w, s.w);
        let fw = lane(far0.w, s.w);
        let o = V8 {
            x: lane(near0.x, s.x) / nw,
            y: lane(near0.y, s.y) / nw,
            z: lane(near0.z, s.z) / nw,
        };
        let d = V8 {
            x: lane(far0.x, s.x) / fw - o.x,
            y: lane(far0.y, s.y) / fw - o.y,
            z: lane(far0.z, s.z) / fw - o.z,
        };
        // Light leaves the st side toward the uv side: the eye must look across the
        // planes from the uv side.
        let rate = d.dot(self.toward);
        let zero = F8::splat(0.0);
        let (_, a_uv, b_uv, uv_ok) = self.uv.cross(o, d);
        let (tau, a_st, b_st, st_ok) = self.st.cross(o, d);
        // NaN fails every test: a range test is a finiteness test too.
        let inside = |a: F8| a.ge(zero).and(a.le(F8::splat(1.0)));
        let hit = rate
            .gt(zero)
            .and(uv_ok)
            .and(st_ok)
            .and(tau.gt(zero))
            .and(inside(a_uv))
            .and(inside(b_uv))
            .and(inside(a_st))
            .and(inside(b_st));
        let crossing = Crossing {
            o,
            d,
            rate,
            tau,
            fractions: [a_uv, b_uv, a_st, b_st],
        };
        (crossing, hit.bits())
    }

    /// A bit per lane whose ray of pixel `x0 + l` of the row starting at `ends` crosses
    /// the slab ([`Rays::batch`]).
    #[inline(always)]
    pub(super) fn hits(&self, ends: (Vec4, Vec4), x0: usize) -> u32 {
        self.cross(ends, x0).1
    }

    /// The rays of pixels `x0..x0 + 8` of the row starting at `ends`, and a bit per lane
    /// whose ray crosses both rectangles, the `st` one ahead of its start, looking from the
    /// `uv` side (those past the row's end too).
    #[inline(always)]
    pub(super) fn batch(&self, ends: (Vec4, Vec4), x0: usize) -> (Batch, u32) {
        let (
            Crossing {
                o,
                d,
                rate,
                tau,
                fractions,
            },
            bits,
        ) = self.cross(ends, x0);
        // Sample coordinates: centres at integers.
        let half = F8::splat(0.5);
        let [nu, nv, ns, nt] = self.coords.map(F8::splat);
        let [a_uv, b_uv, a_st, b_st] = fractions;
        let flat = V8 {
            x: d.x * tau,
            y: d.y * tau,
            z: d.z * tau,
        };
        let mut batch = Batch {
            u: a_uv * nu - half,
            v: b_uv * nv - half,
            s: a_st * ns - half,
            t: b_st * nt - half,
            // The st plane at infinity is infinitely deep.
            flat_depth: if self.st.infinite {
                F8::splat(f32::INFINITY)
            } else {
                flat.dot(self.forward)
            },
            from_uv: half,
            rate,
            rate_view: half,
            start_s: half,
            rate_s: half,
            start_t: half,
            rate_t: half,
        };
        if self.correct {
            let on_st = o.minus(self.st.origin);
            batch.from_uv = o.minus(self.uv_origin).dot(self.toward);
            batch.rate_view = d.dot(self.forward);
            batch.start_s = on_st.dot(self.st.a) * ns;
            batch.rate_s = d.dot(self.st.a) * ns;
            batch.start_t = on_st.dot(self.st.b) * nt;
            batch.rate_t = d.dot(self.st.b) * nt;
        }
        (batch, bits)
    }
}

/// Where eight rays `o + tau d` cross the planes: their rate along the slab's forward,
/// `tau` at the `st` plane, and the fractions of the edges `[a_uv, b_uv, a_st, b_st]`.
#[derive(Clone, Copy)]
struct Crossing {
    o: V8,
    d: V8,
    rate: F8,
    tau: F8,
    fractions: [F8; 4],
}
