//! Where a portal's LDI is captured from: the build's five cameras through the opening, the
//! room's box, and the LDI's size for a camera.

use super::opening::Opening;
use crate::core::{MeshGroup, Subject};
use engine::{Camera, Projection};
use glam::{Vec2, Vec3};

/// The cameras of a build from `eye`: the eye, then four side eyes `reach` away in the
/// opening's plane directions. Each looks straight through the opening (along its
/// inward normal, so the image plane is parallel to the opening, as in Popescu 98) with an
/// off-axis frustum framing the opening widened by `reach` on every side: every LDI pixel
/// is one that can be seen through the opening, from anywhere in the region.
pub(super) fn build_cameras(
    opening: &Opening,
    behind: &MeshGroup,
    eye: Vec3,
    reach: f32,
) -> [Camera; 5] {
    let n = opening.normal();
    let up = (Vec3::Y - n * n.y).normalize_or(Vec3::Z);
    let right = (-n).cross(up);
    let bounds = behind.bounds();
    let eyes = [
        eye,
        eye - right * reach,
        eye + right * reach,
        eye + up * reach,
        eye - up * reach,
    ];
    eyes.map(|e| {
        let view = glam::Mat4::look_at_rh(e, e - n, up);
        let dist = opening.side(e).max(1e-4);
        let near = (dist * 0.5).clamp(1e-3, 0.5);
        let far = (e.distance(bounds.center) + bounds.radius) * 1.5 + 1.0;
        // The opening in view space (all at depth `dist`), widened for the region: an
        // eye `reach` nearer sees, far behind the opening, up to `dist / (dist - reach)`
        // times the opening's half size off its centre, and one `reach` aside that much
        // more; scaled to the near plane.
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::NEG_INFINITY);
        for c in opening.corners {
            let v = view.transform_point3(c);
            let p = Vec2::new(v.x, v.y);
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let k = near / dist;
        let (center, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let grow = dist / (dist - reach).max(0.25 * dist);
        let half = half * grow + Vec2::splat(reach);
        let (lo, hi) = ((center - half) * k, (center + half) * k);
        Camera {
            view,
            projection: Projection::Frustum {
                left: lo.x,
                right: hi.x,
                bottom: lo.y,
                top: hi.y,
                near,
                far,
            },
        }
    })
}

/// The box around the vertices of `group`'s parts, `None` when it has none.
pub(super) fn room_box(group: &MeshGroup) -> Option<[Vec3; 2]> {
    let mut draws = Vec::new();
    group.draws(&mut draws);
    let points = draws.iter().flat_map(|d| {
        let t = d.transform;
        d.mesh.positions.iter().map(move |&p| t.transform_point3(p))
    });
    points
        .filter(|p| p.is_finite())
        .fold(None, |b: Option<[Vec3; 2]>, p| {
            Some(b.map_or([p, p], |[lo, hi]| [lo.min(p), hi.max(p)]))
        })
}

/// The LDI's size for `camera` (a frustum): `side` across its wider extent.
pub(super) fn ldi_size(camera: &Camera, side: u32) -> (u32, u32) {
    let [l, r, b, t] = camera.projection.extents();
    let (w, h) = ((r - l).abs(), (t - b).abs());
    let side = side.max(1) as f32;
    if !(w > 0.0 && h > 0.0) {
        return (side as u32, side as u32);
    }
    let (pw, ph) = if w >= h {
        (side, side * h / w)
    } else {
        (side * w / h, side)
    };
    (pw.round().max(1.0) as u32, ph.round().max(1.0) as u32)
}
