//! Light fields (Levoy and Hanrahan 96; Gortler et al. 96): the plenoptic function of a
//! static object reduced to the 4D set of rays that cross two parallel planes, sampled as
//! a light slab `L(u, v, s, t)` and rendered by looking rays up, not by drawing geometry.
//!
//! - [`Slab`]: the camera plane (`uv`) and the focal plane (`st`), two parallel
//!   rectangles, and how many samples each has. Sample `(i, j)` of a plane sits at the
//!   centre of cell `(i, j)` of its grid, as a pixel centre sits in its pixel.
//! - Capture ([`LightField::capture`]): one image per `uv` sample, taken by a camera at
//!   that sample whose off-axis frustum maps the `st` rectangle exactly onto its image, so
//!   pixel `(s, t)` of image `(u, v)` is the ray from `uv` sample `(u, v)` through `st`
//!   sample `(s, t)`. The images are rendered on both cores ([`capture_batch`]).
//! - Rendering ([`fn@render`]): each pixel's ray is intersected with both planes, giving
//!   continuous `(u, v, s, t)` in sample units, and the light field is looked up by nearest
//!   sample, bilinearly in `uv` (nearest `st`), or quadrilinearly (16 samples); with depth
//!   correction (the captured depths as the proxy) each camera is read where it saw the
//!   ray's surface point.
//! - Saved and loaded as one versioned file ([`mod@file`]: `LightField::save`, `load`).
//! - In a scene ([`LightFieldObject`], a technique): rendered into the screen rectangle
//!   its focal plane covers and composited by a depth-tested image pass.
//! - Among the planner's representations ([`LightFieldSet`], [`plan`]): baked per object
//!   on a cube of slabs, chosen by predicted error and cost.
//!
//! Samples are stored as the frame stores colour (packed premultiplied sRGB bytes,
//! [`ENCODING`]) and blended in that encoding, image `(u, v)` after image, each an
//! `ns` x `nt` row-major image.
//!
//! # Example
//!
//! A slab of 2 x 2 cameras with 8 x 8 images, built by hand: every camera sees red on
//! the left half of the focal plane and blue on the right. Rendered from the camera of
//! `uv` sample `(0, 0)` at the images' size, each pixel's ray is a stored ray.
//!
//! ```
//! use engine::color::Encoder;
//! use glam::Vec3;
//! use ibr::lightfield::{render, Interpolation, LightField, Lookup, RawRays, Rays, Slab};
//! use ibr::warp::{Warped, ENCODING};
//!
//! // Cameras on a plane 4 units behind the origin, looking along -Z at a sphere of
//! // radius 1 there: 2 x 2 cameras, 8 x 8 samples on the focal plane.
//! let slab = Slab::facing(Vec3::ZERO, 1.0, -Vec3::Z, Vec3::Y, [2, 2, 8, 8]).unwrap();
//! let encoder = Encoder::new(ENCODING);
//! let (red, blue) = (encoder.pack(1.0, 0.0, 0.0, 1.0), encoder.pack(0.0, 0.0, 1.0, 1.0));
//! // Image after image, each 8 x 8 row-major (s fastest): no depth kept.
//! let samples = (0..slab.len()).map(|i| if i % 8 < 4 { red } else { blue }).collect();
//! let field = LightField { slab, rays: Rays::Raw(RawRays::new(samples, Vec::new())) };
//! assert_eq!(field.sample(1, 1, 2, 7), red); // looked up by (u, v, s, t)
//!
//! let camera = slab.camera(0, 0);
//! let lookup = Lookup { interpolation: Interpolation::Nearest, depth_correction: false };
//! let mut out = Warped::new(0, 0, camera);
//! let frame = render(&field, &camera, 8, 8, lookup, &mut out);
//! assert_eq!(frame.rays, 64); // every pixel's ray crosses both rectangles
//! assert_eq!(out.color[3 * 8 + 1], red); // pixel (1, 3)
//! assert_eq!(out.color[3 * 8 + 6], blue); // pixel (6, 3)
//! ```

mod field;
pub mod file;
pub(crate) mod object;
mod outline;
pub(crate) mod plan;
pub mod rebin;
pub mod render;
pub mod vq;

use crate::core::capture_batch;
use crate::warp::ENCODING;
use engine::color::Encoder;
use engine::{Camera, Draw, Lighting, Projection};
pub use field::{LightField, RawRays, Rays};
use glam::{Mat4, Vec3};
pub use object::{LightFieldObject, Showing};
pub use plan::LightFieldSet;
pub use rebin::{rebin, Rebinned};
pub use render::{render, Interpolation, LightFieldFrame, Lookup};
use std::sync::OnceLock;
pub use vq::{Quantised, TileShape, VqError, VqReport, VqSettings};

/// A rectangle in space: a corner and its two edges (at right angles).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect3 {
    /// The corner at fractions `(0, 0)`, in world space (a direction when the rectangle
    /// lies on a plane at infinity).
    pub origin: Vec3,
    /// The first edge, from `origin` to fractions `(1, 0)`, world units.
    pub edge_a: Vec3,
    /// The second edge, from `origin` to fractions `(0, 1)`, world units; at right angles
    /// to `edge_a`.
    pub edge_b: Vec3,
}

impl Rect3 {
    /// The rectangle centred on `center` with edges `edge_a` and `edge_b`.
    pub fn centered(center: Vec3, edge_a: Vec3, edge_b: Vec3) -> Self {
        Rect3 {
            origin: center - 0.5 * (edge_a + edge_b),
            edge_a,
            edge_b,
        }
    }

    /// The point at fractions `(a, b)` of its edges.
    pub fn at(&self, a: f32, b: f32) -> Vec3 {
        self.origin + self.edge_a * a + self.edge_b * b
    }

    /// Where the line `o + tau d` crosses the rectangle's plane: `tau` and the fractions
    /// of the edges (inside the rectangle when both are in `[0, 1]`); `None` when parallel
    /// or not finite.
    pub fn cross(&self, o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
        let normal = self.edge_a.cross(self.edge_b);
        let along = d.dot(normal);
        if along == 0.0 || !along.is_finite() {
            return None;
        }
        let tau = (self.origin - o).dot(normal) / along;
        let p = o + d * tau - self.origin;
        let a = p.dot(self.edge_a) / self.edge_a.length_squared();
        let b = p.dot(self.edge_b) / self.edge_b.length_squared();
        (tau.is_finite() && a.is_finite() && b.is_finite()).then_some((tau, a, b))
    }

    /// The bounds of its corners' `x` and `y` as `view` transforms them.
    fn bounds_in(&self, view: &Mat4) -> (glam::Vec2, glam::Vec2) {
        let (mut lo, mut hi) = (glam::Vec2::splat(f32::INFINITY), glam::Vec2::NEG_INFINITY);
        for c in self.corners() {
            let v = view.transform_point3(c);
            lo = lo.min(v.truncate());
            hi = hi.max(v.truncate());
        }
        (lo, hi)
    }

    fn corners(&self) -> [Vec3; 4] {
        [
            self.at(0.0, 0.0),
            self.at(1.0, 0.0),
            self.at(1.0, 1.0),
            self.at(0.0, 1.0),
        ]
    }
}

/// A light slab's geometry: the camera plane `uv` (`nu` x `nv` samples) and the focal
/// plane `st` (`ns` x `nt` samples), parallel, with `st`'s edges giving its images' x
/// (along `edge_a`) and y (along `edge_b`) axes.
///
/// Either plane may be at infinity, as in Stanford's `.lid` slabs ([`Slab::infinite`]):
/// its rectangle then holds directions, not points, and a ray's coordinates on it are
/// where its direction (from the `uv` side toward the `st` side) meets the rectangle.
/// With `uv` at infinity each `uv` sample is a direction and its camera a parallel
/// (orthographic, sheared) projection of the `st` rectangle along it; with `st` at
/// infinity each `uv` camera is a pinhole seeing the directions of the `st` rectangle, an
/// environment seen from a region. Such slabs keep no depth: depth correction needs both
/// planes finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab {
    /// The camera plane: sample `(i, j)` sits at fractions `((i + 0.5) / nu, (j + 0.5) / nv)`
    /// of it.
    pub uv: Rect3,
    /// The focal plane each `uv` camera's image frames exactly (image x along its
    /// `edge_a`, y along its `edge_b`).
    pub st: Rect3,
    /// Samples along `uv.edge_a` (cameras per row), at least 1.
    pub nu: u32,
    /// Samples along `uv.edge_b` (rows of cameras), at least 1.
    pub nv: u32,
    /// Samples along `st.edge_a`: each camera image's width in pixels, at least 1.
    pub ns: u32,
    /// Samples along `st.edge_b`: each camera image's height in pixels, at least 1.
    pub nt: u32,
    /// The capture cameras' depth range, distances along `forward` from the `uv` plane
    /// (from the `st` plane's, when `uv` is at infinity).
    pub near: f32,
    /// The far end of the capture cameras' depth range (world units, `near < far`).
    pub far: f32,
    /// Whether the `uv` and the `st` plane are at infinity (not both).
    pub infinite: [bool; 2],
}

/// Why a slab cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SlabError {
    /// A sample count is zero: the counts given as `nu`, `nv`, `ns`, `nt`.
    #[error("a light slab needs at least one sample on each axis (got {0} x {1} x {2} x {3})")]
    NoSamples(u32, u32, u32, u32),
    #[error("the slab's rectangles must have edges of non-zero length at right angles")]
    /// An edge has zero length, or a rectangle's edges are not at right angles.
    Degenerate,
    /// The `uv` and `st` rectangles do not lie in parallel planes.
    #[error("the uv and st planes must be parallel")]
    NotParallel,
    #[error(
        "the st plane must lie in front of the uv plane along st's edge_a x edge_b (it is {0} behind)"
    )]
    /// The `st` plane is not ahead of the `uv` plane along `st.edge_a x st.edge_b`: by
    /// how far behind it lies (world units).
    Behind(f32),
    /// The depth range given, `near` and `far`, does not satisfy `0 < near < far`.
    #[error("the depth range must satisfy 0 < near < far (got {0} and {1})")]
    DepthRange(f32, f32),
    /// Both planes were asked to be at infinity.
    #[error("the uv and st planes cannot both be at infinity")]
    BothAtInfinity,
    #[error(
        "a plane at infinity holds directions from the uv side toward the st side: its rectangle must lie ahead along st's edge_a x edge_b (it is {0} behind)"
    )]
    /// A plane at infinity's rectangle of directions does not lie ahead along
    /// `st.edge_a x st.edge_b`: by how far behind it lies.
    DirectionsBehind(f32),
}

impl Slab {
    /// A slab, checked: parallel rectangles with the `st` plane ahead of the `uv` plane
    /// along `st.edge_a x st.edge_b`, at least one sample per axis.
    pub fn new(
        uv: Rect3,
        st: Rect3,
        counts: [u32; 4],
        near: f32,
        far: f32,
    ) -> Result<Self, SlabError> {
        Self::with_infinite(uv, st, counts, near, far, [false; 2])
    }

    /// A slab whose `uv` or `st` plane may be at infinity (`infinite`; see [`Slab`]),
    /// checked as [`Slab::new`] checks, a plane at infinity's rectangle of directions
    /// ahead of the origin along `st.edge_a x st.edge_b` instead of the `st` plane ahead of
    /// the `uv` plane.
    pub fn with_infinite(
        uv: Rect3,
        st: Rect3,
        counts: [u32; 4],
        near: f32,
        far: f32,
        infinite: [bool; 2],
    ) -> Result<Self, SlabError> {
        let [nu, nv, ns, nt] = counts;
        if counts.contains(&0) {
            return Err(SlabError::NoSamples(nu, nv, ns, nt));
        }
        for r in [&uv, &st] {
            let (a, b) = (r.edge_a, r.edge_b);
            let square = a.length() * b.length();
            if !(square > 0.0 && square.is_finite() && a.dot(b).abs() <= 1e-4 * square) {
                return Err(SlabError::Degenerate);
            }
        }
        let n_st = st.edge_a.cross(st.edge_b).normalize();
        let n_uv = uv.edge_a.cross(uv.edge_b).normalize();
        if n_st.cross(n_uv).length() > 1e-4 {
            return Err(SlabError::NotParallel);
        }
        match infinite {
            [true, true] => return Err(SlabError::BothAtInfinity),
            [false, false] => {
                let gap = (st.origin - uv.origin).dot(n_st);
                if gap.is_nan() || gap <= 0.0 {
                    return Err(SlabError::Behind(-gap));
                }
            }
            [uv_far, _] => {
                let ahead = if uv_far { uv.origin } else { st.origin }.dot(n_st);
                if ahead.is_nan() || ahead <= 0.0 {
                    return Err(SlabError::DirectionsBehind(-ahead));
                }
            }
        }
        if !(near > 0.0 && near < far) {
            return Err(SlabError::DepthRange(near, far));
        }
        Ok(Slab {
            uv,
            st,
            nu,
            nv,
            ns,
            nt,
            near,
            far,
            infinite,
        })
    }

    /// This slab with its `uv` plane moved to infinity: each `uv` sample becomes the
    /// direction from it to the `st` rectangle's centre, so its camera sees the `st`
    /// rectangle along that direction from infinitely far (the same rays through the
    /// centre, parallel elsewhere). The depth range is kept, now from the `st` plane.
    pub fn with_uv_at_infinity(&self) -> Result<Slab, SlabError> {
        let c = self.st.at(0.5, 0.5);
        let uv = Rect3 {
            origin: c - self.uv.origin,
            edge_a: -self.uv.edge_a,
            edge_b: -self.uv.edge_b,
        };
        let (near, far) = (self.near, self.far);
        Slab::with_infinite(uv, self.st, self.counts(), near, far, [true, false])
    }

    /// This slab with its `st` plane moved to infinity: each `st` sample becomes the
    /// direction to it from the `uv` rectangle's centre, so every `uv` camera sees what lies
    /// in those directions infinitely far off (an environment).
    pub fn with_st_at_infinity(&self) -> Result<Slab, SlabError> {
        let c = self.uv.at(0.5, 0.5);
        let st = Rect3 {
            origin: self.st.origin - c,
            ..self.st
        };
        let (near, far) = (self.near, self.far);
        Slab::with_infinite(self.uv, st, self.counts(), near, far, [false, true])
    }

    /// A viewpoint on the camera side at fractions `(a, b)` of the `uv` rectangle: that
    /// point, or, with `uv` at infinity, a point that far back along that direction from
    /// the `st` rectangle's centre, twice its diagonal away.
    pub fn viewpoint(&self, a: f32, b: f32) -> Vec3 {
        let p = self.uv.at(a, b);
        if !self.infinite[0] {
            return p;
        }
        let diagonal = (self.st.edge_a + self.st.edge_b).length();
        self.st.at(0.5, 0.5) - p.normalize_or_zero() * 2.0 * diagonal
    }

    /// What a view from `eye` looks at: the `st` rectangle's centre, or, with `st` at
    /// infinity, a point in its centre's direction from `eye`.
    pub fn look_target(&self, eye: Vec3) -> Vec3 {
        let c = self.st.at(0.5, 0.5);
        if self.infinite[1] {
            eye + c
        } else {
            c
        }
    }

    /// Whether either plane is at infinity.
    pub fn is_projective(&self) -> bool {
        self.infinite.contains(&true)
    }

    /// Where the line `o + tau d` meets plane `k` (0 `uv`, 1 `st`): `tau` and the
    /// fractions of the rectangle's edges, as [`Rect3::cross`]; a plane at infinity is met
    /// by the direction `d` alone (`tau` infinite, and `None` when `d` points away).
    pub fn cross(&self, k: usize, o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
        let r = if k == 0 { &self.uv } else { &self.st };
        if self.infinite[k] {
            let (tau, a, b) = r.cross(Vec3::ZERO, d)?;
            (tau > 0.0).then_some((f32::INFINITY, a, b))
        } else {
            r.cross(o, d)
        }
    }

    /// A slab that sees a sphere of `radius` around `center` from one side, its cameras
    /// looking along `look` with `up` upward in their images: the `st` plane through the
    /// centre, 4 `radius` square (every ray within 45 degrees of `look` that meets the
    /// sphere crosses it), the `uv` plane 4 `radius` back, 3 `radius` square; depth range
    /// from `radius` to 8 `radius` past the `uv` plane.
    pub fn facing(
        center: Vec3,
        radius: f32,
        look: Vec3,
        up: Vec3,
        counts: [u32; 4],
    ) -> Result<Slab, SlabError> {
        let r = radius;
        Slab::around(
            center,
            look,
            up,
            [2.0 * r, 4.0 * r, 1.5 * r],
            counts,
            [r, 8.0 * r],
        )
    }

    /// Six slabs on a cube around a sphere of `radius` at `center`, one looking along
    /// each axis, both ways (+X, -X, +Y, -Y, +Z, -Z), each taking rays up to 63 degrees
    /// off its axis: `st` planes through the centre 4.4 `radius` square, `uv` planes 3
    /// `radius` back, 16.4 `radius` square. From every eye more than about 8 radii away
    /// one slab sees the whole sphere (from nearer eyes off the axes none may, and
    /// [`LightFieldObject`] falls back).
    pub fn cube(center: Vec3, radius: f32, counts: [u32; 4]) -> Result<[Slab; 6], SlabError> {
        let r = radius;
        let faces = [
            (Vec3::X, Vec3::Y),
            (Vec3::NEG_X, Vec3::Y),
            (Vec3::Y, Vec3::Z),
            (Vec3::NEG_Y, Vec3::NEG_Z),
            (Vec3::Z, Vec3::Y),
            (Vec3::NEG_Z, Vec3::Y),
        ];
        let size = [2.2 * r, 3.0 * r, 8.2 * r];
        let [a, b, c, d, e, f] = faces
            .map(|(look, up)| Slab::around(center, look, up, size, counts, [0.5 * r, 8.0 * r]));
        Ok([a?, b?, c?, d?, e?, f?])
    }

    /// A slab looking along `look` (`up` upward in its images) at `center`: `st` plane
    /// through it, `st_half` its half-size; `uv` plane `back` behind, `uv_half` its
    /// half-size.
    fn around(
        center: Vec3,
        look: Vec3,
        up: Vec3,
        [st_half, back, uv_half]: [f32; 3],
        counts: [u32; 4],
        [near, far]: [f32; 2],
    ) -> Result<Slab, SlabError> {
        let look = look.normalize_or_zero();
        let right = look.cross(up).normalize_or_zero();
        let down = look.cross(right);
        let at = |back: f32, half: f32| {
            Rect3::centered(center - look * back, right * 2.0 * half, down * 2.0 * half)
        };
        Slab::new(at(back, uv_half), at(0.0, st_half), counts, near, far)
    }

    /// The direction from the `uv` plane to the `st` plane (unit).
    pub fn forward(&self) -> Vec3 {
        self.st.edge_a.cross(self.st.edge_b).normalize()
    }

    /// The position of `uv` sample `(i, j)`.
    pub fn uv_point(&self, i: u32, j: u32) -> Vec3 {
        let a = (i as f32 + 0.5) / self.nu as f32;
        let b = (j as f32 + 0.5) / self.nv as f32;
        self.uv.at(a, b)
    }

    /// The capture camera of `uv` sample `(i, j)`: at the sample, its image plane parallel
    /// to the planes, its off-axis frustum framing the `st` rectangle exactly (image x
    /// along `st.edge_a`, y down along `st.edge_b`).
    pub fn camera(&self, i: u32, j: u32) -> Camera {
        let a = (i as f32 + 0.5) / self.nu as f32;
        let b = (j as f32 + 0.5) / self.nv as f32;
        self.camera_through(a, b)
    }

    /// The capture camera at fractions `(a, b)` of the `uv` rectangle: at that point, or,
    /// with `uv` at infinity, looking along that direction by a parallel projection
    /// sheared so that its image is the `st` rectangle.
    pub fn camera_through(&self, a: f32, b: f32) -> Camera {
        if !self.infinite[0] {
            return self.camera_at(self.uv.at(a, b));
        }
        let d = self.uv.at(a, b);
        let f = self.forward();
        let (x, y) = (self.st.edge_a.normalize(), -self.st.edge_b.normalize());
        let o = self.st.origin;
        // A point's place on the st plane along d, as x and y; its distance behind the st
        // plane along f (toward the uv side), so depth runs from near to far behind it.
        let slide = |e: Vec3| e - f * (e.dot(d) / f.dot(d));
        let (sx, sy) = (slide(x), slide(y));
        let back = 2.0 * self.far;
        let view = Mat4::from_cols(
            glam::Vec4::new(sx.x, sy.x, -f.x, 0.0),
            glam::Vec4::new(sx.y, sy.y, -f.y, 0.0),
            glam::Vec4::new(sx.z, sy.z, -f.z, 0.0),
            glam::Vec4::new(-sx.dot(o), -sy.dot(o), f.dot(o) - back, 1.0),
        );
        let (lo, hi) = self.st.bounds_in(&view);
        Camera {
            view,
            projection: Projection::Orthographic {
                left: lo.x,
                right: hi.x,
                bottom: lo.y,
                top: hi.y,
                near: back - self.far,
                far: back + self.far,
            },
        }
    }

    /// A capture camera at `eye` (a point of the `uv` plane) framing the `st` rectangle
    /// as [`Slab::camera`] does.
    pub fn camera_at(&self, eye: Vec3) -> Camera {
        // With st at infinity the camera sees its directions as a rectangle in front of it.
        let st = if self.infinite[1] {
            Rect3 {
                origin: eye + self.st.origin,
                ..self.st
            }
        } else {
            self.st
        };
        let x = self.st.edge_a.normalize();
        let y = -self.st.edge_b.normalize();
        let z = -self.forward();
        let view = Mat4::from_cols(
            glam::Vec4::new(x.x, y.x, z.x, 0.0),
            glam::Vec4::new(x.y, y.y, z.y, 0.0),
            glam::Vec4::new(x.z, y.z, z.z, 0.0),
            glam::Vec4::new(-x.dot(eye), -y.dot(eye), -z.dot(eye), 1.0),
        );
        let dist = (st.origin - eye).dot(self.forward());
        let k = self.near / dist;
        let (lo, hi) = st.bounds_in(&view);
        Camera {
            view,
            projection: Projection::Frustum {
                left: lo.x * k,
                right: hi.x * k,
                bottom: lo.y * k,
                top: hi.y * k,
                near: self.near,
                far: self.far,
            },
        }
    }

    /// Samples in all, `nu nv ns nt` (saturating).
    pub fn len(&self) -> usize {
        [self.nu, self.nv, self.ns, self.nt]
            .iter()
            .try_fold(1usize, |p, &n| p.checked_mul(n as usize))
            .unwrap_or(usize::MAX)
    }

    /// Sample counts `[nu, nv, ns, nt]`.
    pub fn counts(&self) -> [u32; 4] {
        [self.nu, self.nv, self.ns, self.nt]
    }

    /// Whether it holds no samples (never, for a checked slab).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod infinity_tests;
#[cfg(test)]
mod outline_tests;
#[cfg(test)]
mod rebin_tests;
#[cfg(test)]
mod stability_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod vq_tests;

/// The nearest and farthest positive finite depth of `depth`, if any.
pub(crate) fn depth_range(depth: &[f32]) -> Option<(f32, f32)> {
    let (lo, hi) = depth
        .iter()
        .filter(|z| z.is_finite() && **z > 0.0)
        .fold((f32::INFINITY, 0.0f32), |(lo, hi), &z| {
            (lo.min(z), hi.max(z))
        });
    (lo <= hi).then_some((lo, hi))
}
