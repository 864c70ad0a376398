//! Cameras: a view transform plus a projection, in the conventions of `ARCHITECTURE.md`.
//!
//! World space is right-handed, +Y up; the camera looks down its local -Z. Two clip spaces
//! exist. [`Camera::gl_view_proj`] is OpenGL's (`perspective_rh_gl`: NDC z in [-1, 1],
//! near -> -1): it is what the CLI flags describe and what depth files store. The pipeline
//! itself uses [`Camera::clip_from_world`], the same frustum with *reversed* depth in
//! [0, 1] (near -> 1, far -> 0), so that an `f32` depth buffer keeps its precision far away.
//! Both describe the same frustum, so the same points are visible either way.

use glam::{Mat4, Vec2, Vec3, Vec4};

/// A projection. Angles in radians; `near` and `far` are positive distances along -Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// A symmetric perspective frustum, as `gluPerspective`.
    Perspective {
        /// Full vertical field of view, radians, in (0, pi).
        fov_y: f32,
        /// Image width over height (of the target in pixels, for square pixels).
        aspect: f32,
        /// Distance of the near plane along -Z, view-space units; `0 < near < far`.
        near: f32,
        /// Distance of the far plane along -Z, view-space units.
        far: f32,
    },
    /// A parallel projection of the view-space box `[left, right] x [bottom, top] x
    /// [-far, -near]`, as `glOrtho`.
    Orthographic {
        /// View-space x of the image's left edge.
        left: f32,
        /// View-space x of the image's right edge; `right > left`.
        right: f32,
        /// View-space y of the image's bottom edge.
        bottom: f32,
        /// View-space y of the image's top edge; `top > bottom`.
        top: f32,
        /// Distance of the near plane along -Z, view-space units; `near < far`.
        near: f32,
        /// Distance of the far plane along -Z, view-space units.
        far: f32,
    },
    /// An off-axis (sheared) perspective frustum, OpenGL's `glFrustum`: the view-space
    /// rectangle `[left, right] x [bottom, top]` on the plane at distance `near` is the image.
    /// A crop of a perspective camera ([`Camera::crop`]), a cube face or a light-slab camera.
    Frustum {
        /// View-space x of the image's left edge on the near plane.
        left: f32,
        /// View-space x of the image's right edge on the near plane; `right > left`.
        right: f32,
        /// View-space y of the image's bottom edge on the near plane.
        bottom: f32,
        /// View-space y of the image's top edge on the near plane; `top > bottom`.
        top: f32,
        /// Distance of the near plane along -Z, view-space units; `0 < near < far`.
        near: f32,
        /// Distance of the far plane along -Z, view-space units.
        far: f32,
    },
}

impl Projection {
    /// The near and far distances.
    pub fn near_far(&self) -> (f32, f32) {
        match *self {
            Projection::Perspective { near, far, .. } => (near, far),
            Projection::Orthographic { near, far, .. } => (near, far),
            Projection::Frustum { near, far, .. } => (near, far),
        }
    }

    /// Whether points farther away look smaller (every projection but orthographic).
    pub fn is_perspective(&self) -> bool {
        !matches!(self, Projection::Orthographic { .. })
    }

    /// The image rectangle `[left, right, bottom, top]` on the plane at `near` (view space;
    /// for orthographic projections on every plane).
    pub fn extents(&self) -> [f32; 4] {
        match *self {
            Projection::Perspective {
                fov_y,
                aspect,
                near,
                ..
            } => {
                let top = near * (fov_y * 0.5).tan();
                let right = top * aspect;
                [-right, right, -top, top]
            }
            Projection::Orthographic {
                left,
                right,
                bottom,
                top,
                ..
            }
            | Projection::Frustum {
                left,
                right,
                bottom,
                top,
                ..
            } => [left, right, bottom, top],
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
            Projection::Frustum { near, far, .. } => {
                let (a, b) = (
                    -(far + near) / (far - near),
                    -2.0 * far * near / (far - near),
                );
                self.frustum_matrix(a, b)
            }
        }
    }

    /// `glFrustum` with the depth rows `z_clip = a z + b` (view-space z, `w_clip = -z`).
    fn frustum_matrix(&self, a: f32, b: f32) -> Mat4 {
        let [l, r, bo, t] = self.extents();
        let (n, _) = self.near_far();
        Mat4::from_cols(
            Vec4::new(2.0 * n / (r - l), 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0 * n / (t - bo), 0.0, 0.0),
            Vec4::new((r + l) / (r - l), (t + bo) / (t - bo), a, -1.0),
            Vec4::new(0.0, 0.0, b, 0.0),
        )
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
            // Reversed depth n (f + z) / ((f - n) (-z)): near -> 1, far -> 0, as above.
            Projection::Frustum { near, far, .. } => {
                let k = near / (far - near);
                self.frustum_matrix(k, k * far)
            }
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
///
/// A point the camera looks at lands at the centre of the image (NDC x = y = 0), in front
/// of it (reversed depth in (0, 1]):
///
/// ```rust
/// use engine::Camera;
/// use glam::Vec3;
///
/// let target = Vec3::new(1.0, 2.0, -3.0);
/// let camera = Camera::look_at(Vec3::new(4.0, 5.0, 6.0), target, Vec3::Y, 1.0, 16.0 / 9.0);
/// let ndc = camera.clip_from_world().project_point3(target);
/// assert!(ndc.x.abs() < 1e-5 && ndc.y.abs() < 1e-5);
/// assert!(ndc.z > 0.0 && ndc.z <= 1.0);
/// // The distance along the view direction comes back from the stored depth.
/// let distance = (target - camera.eye()).length();
/// assert!((camera.view_depth_from_reversed(ndc.z) - distance).abs() < 1e-3 * distance);
/// // A point to the camera's right lands right of the centre.
/// let right = camera.forward().cross(Vec3::Y).normalize();
/// assert!(camera.clip_from_world().project_point3(target + right).x > 0.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World space -> view space (camera at the origin looking down -Z, +Y up); a rigid
    /// transform for the cameras made here.
    pub view: Mat4,
    /// View space -> clip space; see [`Projection`].
    pub projection: Projection,
}

impl Camera {
    /// A perspective camera looking from `eye` at `target`; `fov_y` in radians. When `up`
    /// is parallel to the view direction (looking straight down with `up = Y`), or zero,
    /// another up is chosen ([`stable_up`]) so the view stays a rotation.
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_y: f32, aspect: f32) -> Self {
        Camera {
            view: Mat4::look_at_rh(eye, target, stable_up(target - eye, up)),
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
            }
            | Projection::Frustum {
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

    /// The camera whose image is the pixel rectangle `min..max` (x right, y down) of this
    /// camera's `width` x `height` image: same eye, same depth range, an off-axis frustum
    /// (a box for orthographic cameras). A point lands in the crop exactly where it lands in
    /// the full image, scaled; the rectangle may reach past the image.
    pub fn crop(&self, min: Vec2, max: Vec2, width: u32, height: u32) -> Camera {
        let [l, r, b, t] = self.projection.extents();
        let (w, h) = (width.max(1) as f32, height.max(1) as f32);
        let x = |px: f32| l + (r - l) * px / w;
        let y = |py: f32| t + (b - t) * py / h;
        let (near, far) = self.near_far();
        let (left, right, bottom, top) = (x(min.x), x(max.x), y(max.y), y(min.y));
        let projection = match self.projection {
            Projection::Orthographic { .. } => Projection::Orthographic {
                left,
                right,
                bottom,
                top,
                near,
                far,
            },
            _ => Projection::Frustum {
                left,
                right,
                bottom,
                top,
                near,
                far,
            },
        };
        Camera {
            view: self.view,
            projection,
        }
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

    /// The projection's near and far distances along the view direction, view-space units.
    pub fn near_far(&self) -> (f32, f32) {
        self.projection.near_far()
    }

    /// Distance along the view direction (view-space -z) of a stored reversed depth,
    /// for soft-particle style effects. Returns `far` for the cleared value 0.
    pub fn view_depth_from_reversed(&self, d: f32) -> f32 {
        let (n, f) = self.near_far();
        match self.projection {
            // reversed d = n (f - w) / (w (f - n))  =>  w = n f / (d (f - n) + n)
            Projection::Perspective { .. } | Projection::Frustum { .. } => {
                n * f / (d * (f - n) + n)
            }
            Projection::Orthographic { .. } => f - d * (f - n),
        }
    }

    /// The stored reversed depth of a point at distance `z` along the view direction: the
    /// inverse of [`Camera::view_depth_from_reversed`]. Points at or beyond the far plane
    /// (infinity too) map to the smallest positive depth, so they still pass a depth test
    /// against the cleared value 0; nearer than the near plane, above 1 (clipped away).
    pub fn reversed_from_view_depth(&self, z: f32) -> f32 {
        let (n, f) = self.near_far();
        let d = match self.projection {
            Projection::Perspective { .. } | Projection::Frustum { .. } => {
                n * (f - z) / (z * (f - n))
            }
            Projection::Orthographic { .. } => (f - z) / (f - n),
        };
        if z >= f || d.is_nan() {
            f32::MIN_POSITIVE
        } else {
            d.max(f32::MIN_POSITIVE)
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

/// `up`, or when it is zero or parallel to `forward` (within about 0.06 degrees) another:
/// for a view along the Y axis `-Z` looking down and `+Z` looking up (the screen's right
/// stays +X, as for a camera that tilted down or up from facing -Z), otherwise `+Y`.
pub fn stable_up(forward: Vec3, up: Vec3) -> Vec3 {
    let f = forward.normalize_or_zero();
    let u = up.normalize_or_zero();
    if f == Vec3::ZERO || (u != Vec3::ZERO && f.cross(u).length_squared() > 1e-6) {
        return up;
    }
    let a = f.abs();
    if a.y >= a.x && a.y >= a.z {
        Vec3::Z * f.y.signum()
    } else {
        Vec3::Y
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
    fn reversed_depth_of_a_view_depth_is_what_the_projection_stores() {
        let ortho = Camera {
            view: Mat4::IDENTITY,
            projection: Projection::Orthographic {
                left: -1.0,
                right: 1.0,
                bottom: -1.0,
                top: 1.0,
                near: 0.5,
                far: 20.0,
            },
        };
        for c in [cam(), ortho] {
            for z in [0.5f32, 0.7, 3.0, 19.0] {
                // A point on the axis at distance z, through the pipeline's projection.
                let p = c.view.inverse().transform_point3(Vec3::new(0.0, 0.0, -z));
                let clip = c.clip_from_world() * p.extend(1.0);
                let want = clip.z / clip.w;
                let got = c.reversed_from_view_depth(z);
                assert!((got - want).abs() < 1e-5, "{z}: {got} vs {want}");
                assert!((c.view_depth_from_reversed(got) - z).abs() < 1e-3 * z);
            }
            for far in [100.0, 1e9, f32::INFINITY] {
                assert_eq!(c.reversed_from_view_depth(far), f32::MIN_POSITIVE);
            }
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

    #[test]
    fn looking_straight_down_or_up_keeps_a_rotation_and_right_is_x() {
        for (target, up) in [
            (Vec3::new(0.0, -5.0, 0.0), Vec3::Y),
            (Vec3::new(0.0, 5.0, 0.0), Vec3::Y),
            (Vec3::new(0.0, -5.0, 0.0), Vec3::ZERO),
            (Vec3::new(0.0, 0.0, -5.0), Vec3::Z),
            (Vec3::new(3.0, 0.0, 0.0), Vec3::NEG_X),
        ] {
            let c = Camera::look_at(Vec3::ZERO, target, up, 1.0, 1.0);
            assert!(c.view.is_finite(), "{target} {up}");
            let m = glam::Mat3::from_mat4(c.view);
            assert!((m.determinant() - 1.0).abs() < 1e-4, "{target} {up}");
            assert!((c.forward() - target.normalize()).length() < 1e-5);
        }
        // Straight down from above: the point below is at the image centre, +X to the right.
        let c = Camera::look_at(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
        let ndc = |p: Vec3| c.clip_from_world().project_point3(p);
        assert!(ndc(Vec3::ZERO).truncate().length() < 1e-5);
        assert!(ndc(Vec3::X).x > 0.05 && ndc(Vec3::X).y.abs() < 1e-5);
        assert!(ndc(Vec3::NEG_Z).y > 0.05, "-Z is up on screen");
    }

    #[test]
    fn a_crop_shows_its_rectangle_of_the_full_image() {
        let (w, h) = (320u32, 200u32);
        for c in [
            cam(),
            Camera {
                view: cam().view,
                projection: Projection::Orthographic {
                    left: -2.0,
                    right: 3.0,
                    bottom: -1.0,
                    top: 1.5,
                    near: 0.5,
                    far: 50.0,
                },
            },
        ] {
            let (min, max) = (Vec2::new(100.0, 40.0), Vec2::new(140.0, 90.0));
            let crop = c.crop(min, max, w, h);
            let pixel = |cam: &Camera, p: Vec3, w: f32, h: f32| {
                let q = cam.clip_from_world().project_point3(p);
                (
                    Vec2::new(q.x * 0.5 + 0.5, 0.5 - q.y * 0.5) * Vec2::new(w, h),
                    q.z,
                )
            };
            for p in [
                Vec3::ZERO,
                Vec3::new(-0.4, 0.3, 0.5),
                Vec3::new(2.0, -1.0, -8.0),
            ] {
                let (full, z_full) = pixel(&c, p, w as f32, h as f32);
                let (local, z_crop) = pixel(&crop, p, 40.0, 50.0);
                assert!((full - (min + local)).length() < 1e-3, "{full} {local}");
                assert!((z_full - z_crop).abs() < 1e-5, "depth unchanged");
                let gl = crop.gl_view_proj().project_point3(p);
                let rev = crop.clip_from_world().project_point3(p);
                assert!((gl_window_depth(rev.z) - (0.5 * gl.z + 0.5)).abs() < 1e-5);
            }
            let d = crop
                .clip_from_world()
                .project_point3(Vec3::new(0.1, 0.1, -5.0))
                .z;
            let dist = (crop.view * Vec3::new(0.1, 0.1, -5.0).extend(1.0)).z.abs();
            assert!((crop.view_depth_from_reversed(d) - dist).abs() < 1e-3);
        }
    }
}
