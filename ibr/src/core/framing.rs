//! One impostor capture: the eye it was taken from, the perspective camera fitted to the
//! subject's bounding sphere, and the quad through the sphere's centre that shows it.

use crate::core::Subject;
use engine::{Camera, Projection};
use glam::{Mat4, Vec3};

/// Where and how an impostor image was taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capture {
    /// World-space eye position the image was taken from.
    pub eye: Vec3,
    /// Centre of the subject's bounding sphere, world space.
    pub center: Vec3,
    /// Radius of that sphere, world units.
    pub radius: f32,
    /// The stored near point, world space: the near end of the sphere's diameter along the
    /// capture ray (its direction from the eye coincides with the far end's only from the
    /// capture eye).
    pub near: Vec3,
    /// The far end of that diameter (see [`Capture::near`]), world space.
    pub far: Vec3,
    /// Texture side, pixels.
    pub side: u32,
    /// The subject's version when captured.
    pub version: u64,
    /// The quad through the centre, perpendicular to the capture ray, exactly filling the
    /// capture frustum there: bottom-left, bottom-right, top-right, top-left as seen.
    pub corners: [Vec3; 4],
    /// Half the capture camera's field of view, radians.
    pub half_fov: f32,
    /// How busy the image is: the mean absolute difference between neighbouring texels,
    /// 8-bit levels per texel (RGB, over the whole square). A displacement of `d` texels
    /// changes the image by about `d` times this: what turns parallax in pixels into an
    /// image error ([`super::Predicted::levels`]). Set when the image is rendered.
    pub gradient: f32,
    /// The same differences, each weighted by how far its surface lies from the quad's
    /// plane (in radii, 0 to 1): parallax moves a texel in proportion to that distance, so
    /// this times half the parallax in texels is the error the parallax makes.
    pub depth_gradient: f32,
}

impl Capture {
    /// A capture of the sphere (`center`, `radius`) from `eye`; `None` from inside the
    /// sphere or for non-finite input.
    pub fn new(eye: Vec3, center: Vec3, radius: f32, side: u32, version: u64) -> Option<Self> {
        let to = center - eye;
        let dist = to.length();
        if !(eye.is_finite() && center.is_finite() && radius > 0.0 && dist > radius * 1.0001) {
            return None;
        }
        let dir = to / dist;
        let sin = radius / dist;
        let half_fov = sin.asin();
        let up = capture_up(dir);
        let right = dir.cross(up).normalize();
        let up = right.cross(dir);
        // The frustum's half-width at the centre's distance: dist * tan(half_fov).
        let half = dist * half_fov.tan();
        let c = center;
        let corners = [
            c - right * half - up * half,
            c + right * half - up * half,
            c + right * half + up * half,
            c - right * half + up * half,
        ];
        corners.iter().all(|p| p.is_finite()).then_some(Capture {
            eye,
            center,
            radius,
            near: center - dir * radius,
            far: center + dir * radius,
            side,
            version,
            corners,
            half_fov,
            gradient: 0.0,
            depth_gradient: 0.0,
        })
    }

    /// The camera the image is rendered with.
    pub fn camera(&self) -> Camera {
        capture_camera(self.eye, self.center, self.radius, self.half_fov)
    }
}

/// A square perspective camera from `eye` at `center` whose frustum just holds the sphere
/// of `radius` (half field of view `half_fov`), near and far planes hugging the sphere.
pub(crate) fn capture_camera(eye: Vec3, center: Vec3, radius: f32, half_fov: f32) -> Camera {
    let dist = eye.distance(center);
    let dir = (center - eye) / dist.max(1e-12);
    Camera {
        view: Mat4::look_at_rh(eye, center, capture_up(dir)),
        projection: Projection::Perspective {
            fov_y: 2.0 * half_fov,
            aspect: 1.0,
            near: (dist - radius * 1.001).max(dist * 1e-4),
            far: dist + radius * 1.001,
        },
    }
}

/// World +Y, or +Z when looking nearly straight up or down.
fn capture_up(dir: Vec3) -> Vec3 {
    if dir.cross(Vec3::Y).length_squared() > 1e-6 {
        Vec3::Y
    } else {
        Vec3::Z
    }
}

/// The transform that scales an image's quad about `eye` (the same pixels, only nearer) to
/// the depth of `s`'s nearest corner along the line of sight ([`ImpostorSet::draws_near`]).
pub(crate) fn pull_near<S: Subject>(s: &S, eye: Vec3) -> Mat4 {
    let to = s.bounds().center - eye;
    let dist = to.length().max(1e-6);
    let dir = to / dist;
    let nearest = s
        .corners()
        .iter()
        .map(|&c| (c - eye).dot(dir))
        .fold(dist, f32::min);
    let k = (nearest / dist).clamp(0.05, 1.0);
    Mat4::from_translation(eye) * Mat4::from_scale(Vec3::splat(k)) * Mat4::from_translation(-eye)
}

/// Appends to `out` the triangles of a grid of `cols` x `rows` cells whose vertices are
/// laid out row by row from `base` (`cols + 1` to a row, rows growing downward as image
/// rows do): each cell as bottom-left, bottom-right, top-right and bottom-left, top-right,
/// top-left, counter-clockwise as seen. Relief images and billboard sprites stand on such
/// grids.
pub(crate) fn grid_triangles(cols: u32, rows: u32, base: u32, out: &mut Vec<u32>) {
    let at = |x: u32, y: u32| base + y * (cols + 1) + x;
    for y in 0..rows {
        for x in 0..cols {
            let (a, b, c, d) = (at(x, y + 1), at(x + 1, y + 1), at(x + 1, y), at(x, y));
            out.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
}
