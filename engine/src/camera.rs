//! Cameras: a view transform plus a projection, in the conventions of `ARCHITECTURE.md`.
//!
//! World space is right-handed, +Y up; the camera looks down its local -Z. Two clip spaces
//! exist. [`Camera::gl_view_proj`] is OpenGL's (`perspective_rh_gl`: NDC z in [-1, 1],
//! near -> -1): it is what the CLI flags describe and what depth files store. The pipeline
//! itself uses [`Camera::clip_from_world`], the same frustum with *reversed* depth in
//! [0, 1] (near -> 1, far -> 0), so that an `f32` depth buffer keeps its precision far away.
//! Both describe the same frustum, so the same points are visible either way.

use glam::{Mat4, Vec3, Vec4};

/// A projection. Angles in radians; `near` and `far` are positive distances along -Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    Perspective {
        fov_y: f32,
        aspect: f32,
        near: f32,
        far: f32,
    },
    Orthographic {
        left: f32,
        right: f32,
        bottom: f32,
        top: f32,
        near: f32,
        far: f32,
    },
}

impl Projection {
    fn near_far(&self) -> (f32, f32) {
        match *self {
            Projection::Perspective { near, far, .. } => (near, far),
            Projection::Orthographic { near, far, .. } => (near, far),
        }
    }

    /// OpenGL-style projection (NDC z in [-1, 1]).
    pub fn gl_matrix(&self) -> Mat4 {
        match *self {
            Projection::Perspective {
                fov_y,
                aspect,
                near,
                far,
            } => Mat4::perspective_rh_gl(fov_y, aspect, near, far),
            Projection::Orthographic {
                left,
                right,
                bottom,
                top,
                near,
                far,
            } => Mat4::orthographic_rh_gl(left, right, bottom, top, near, far),
        }
    }

    /// Reversed-depth projection (NDC z in [0, 1], near plane -> 1, far plane -> 0).
    pub fn reversed_z_matrix(&self) -> Mat4 {
        match *self {
            // Swapping near and far in a [0, 1]-depth projection reverses depth exactly.
            Projection::Perspective {
                fov_y,
                aspect,
                near,
                far,
            } => Mat4::perspective_rh(fov_y, aspect, far, near),
            Projection::Orthographic {
                left,
                right,
                bottom,
                top,
                near,
                far,
            } => Mat4::orthographic_rh(left, right, bottom, top, far, near),
        }
    }
}

/// Depth of a point as the pipeline stores it (reversed, [0, 1]) and as OpenGL's window
/// depth (`0.5 * ndc_z + 0.5`, [0, 1], near -> 0). For every projection here the two are
/// related by `gl = 1 - reversed`: both are the same affine function of the interpolated
/// quantity (1/w for perspective, z for orthographic) with the ends swapped.
pub fn gl_window_depth(reversed: f32) -> f32 {
    1.0 - reversed
}

/// A camera: where it is (`view`, world -> view space) and how it projects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub view: Mat4,
    pub projection: Projection,
}

impl Camera {
    /// A perspective camera looking from `eye` at `target`; `fov_y` in radians.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_y: f32, aspect: f32) -> Self {
        Camera {
            view: Mat4::look_at_rh(eye, target, up),
            projection: Projection::Perspective {
                fov_y,
                aspect,
                near: 0.1,
                far: 100.0,
            },
        }
    }

    /// The same camera with other near and far distances.
    pub fn with_depth_range(mut self, near: f32, far: f32) -> Self {
        match &mut self.projection {
            Projection::Perspective {
                near: n, far: f, ..
            }
            | Projection::Orthographic {
                near: n, far: f, ..
            } => {
                *n = near;
                *f = far;
            }
        }
        self
    }

    /// The same camera with the aspect ratio of a `width` x `height` target.
    pub fn with_aspect(mut self, width: u32, height: u32) -> Self {
        if let Projection::Perspective { aspect, .. } = &mut self.projection {
            *aspect = width.max(1) as f32 / height.max(1) as f32;
        }
        self
    }

    /// World -> OpenGL clip space (`proj_gl * view`).
    pub fn gl_view_proj(&self) -> Mat4 {
        self.projection.gl_matrix() * self.view
    }

    /// World -> the pipeline's reversed-depth clip space.
    pub fn clip_from_world(&self) -> Mat4 {
        self.projection.reversed_z_matrix() * self.view
    }

    /// Camera position in world space.
    pub fn eye(&self) -> Vec3 {
        self.view.inverse().w_axis.truncate()
    }

    /// Unit view direction (camera -Z) in world space.
    pub fn forward(&self) -> Vec3 {
        -self.view.inverse().z_axis.truncate().normalize_or_zero()
    }

    pub fn near_far(&self) -> (f32, f32) {
        self.projection.near_far()
    }

    /// Distance along the view direction (view-space -z) of a stored reversed depth,
    /// for soft-particle style effects. Returns `far` for the cleared value 0.
    pub fn view_depth_from_reversed(&self, d: f32) -> f32 {
        let (n, f) = self.near_far();
        match self.projection {
            // reversed d = n (f - w) / (w (f - n))  =>  w = n f / (d (f - n) + n)
            Projection::Perspective { .. } => n * f / (d * (f - n) + n),
            Projection::Orthographic { .. } => f - d * (f - n),
        }
    }

    /// World-space ray through a pixel centre of a `width` x `height` image: (origin, dir).
    pub fn pixel_ray(&self, x: f32, y: f32, width: u32, height: u32) -> (Vec3, Vec3) {
        let inv = self.gl_view_proj().inverse();
        let ndc_x = 2.0 * x / width as f32 - 1.0;
        let ndc_y = 1.0 - 2.0 * y / height as f32;
        let near = inv * Vec4::new(ndc_x, ndc_y, -1.0, 1.0);
        let far = inv * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
        let near = near.truncate() / near.w;
        let far = far.truncate() / far.w;
        (near, (far - near).normalize_or_zero())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera::look_at(Vec3::new(0.3, 0.2, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.5)
            .with_depth_range(0.1, 100.0)
    }

    #[test]
    fn reversed_depth_is_one_minus_gl_window_depth() {
        let c = cam();
        for p in [
            Vec3::ZERO,
            Vec3::new(0.5, -0.2, 1.0),
            Vec3::new(-3.0, 1.0, -40.0),
        ] {
            let gl = c.gl_view_proj() * p.extend(1.0);
            let rev = c.clip_from_world() * p.extend(1.0);
            let gl_win = 0.5 * gl.z / gl.w + 0.5;
            assert!((gl_window_depth(rev.z / rev.w) - gl_win).abs() < 1e-5);
            assert!((gl.x / gl.w - rev.x / rev.w).abs() < 1e-5);
        }
    }

    #[test]
    fn view_depth_inverts_reversed_depth() {
        let c = cam();
        let p = Vec3::new(0.1, 0.1, -5.0);
        let clip = c.clip_from_world() * p.extend(1.0);
        let d = clip.z / clip.w;
        let dist = (c.view * p.extend(1.0)).z.abs();
        assert!((c.view_depth_from_reversed(d) - dist).abs() < 1e-3);
    }

    #[test]
    fn eye_and_forward() {
        let c = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
        assert!((c.eye() - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-5);
        assert!((c.forward() - Vec3::NEG_Z).length() < 1e-5);
    }
}
