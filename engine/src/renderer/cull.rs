//! Draw culling and the draws' view depths: each mesh's object-space bounding box, found
//! once a frame however many draws share the mesh, tested against the camera's frustum
//! with the draw's transform (a draw wholly outside one plane is dropped before its
//! vertices are transformed), and the depths the renderer orders draws by.

use crate::camera::Camera;
use crate::mesh::Mesh;
use glam::{BVec3, DMat4, DVec4, Mat4, Vec3};
use std::collections::HashMap;

/// How far outside a plane (relative to the size of the clip coordinates) every corner of
/// a box must lie for its draw to be culled. The vertex stage rounds clip coordinates to
/// `f32` (relative error 6e-8) and the front end snaps to 1/256 pixel, while a triangle
/// outside an image side by any amount covers no pixel centre (half a pixel inside it):
/// a culled draw could have drawn nothing.
const MARGIN: f64 = 1e-6;

/// The frame's meshes' object-space bounding boxes, by address. A mesh is borrowed for
/// the whole frame, so one address holds one mesh, unchanged, until the frame ends; the
/// map is cleared (its memory kept) when the next frame begins, as a mesh may have been
/// rewritten in between.
#[derive(Debug, Default)]
pub(super) struct Boxes(HashMap<usize, Option<(Vec3, Vec3)>>);

impl Boxes {
    /// Forgets the last frame's boxes.
    pub(super) fn clear(&mut self) {
        self.0.clear();
    }

    /// `mesh`'s [`Mesh::bounding_box`], walked once a frame.
    pub(super) fn of(&mut self, mesh: &Mesh) -> Option<(Vec3, Vec3)> {
        let key = mesh as *const Mesh as usize;
        *self.0.entry(key).or_insert_with(|| mesh.bounding_box())
    }
}

/// The eight corners of the box `(lo, hi)`.
fn corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| Vec3::select(BVec3::new(k & 1 != 0, k & 2 != 0, k & 4 != 0), hi, lo))
}

/// Whether the object-space box `(lo, hi)` lies wholly outside one plane of the frustum
/// (near, far, or one of the image's four sides: not the guard band) once carried to clip
/// space by `clip_from_world * object_to_world` (in `f64`, as the vertex stage does). Every
/// vertex inside the box is a convex combination of its corners, and the planes are linear
/// in clip space, so then every triangle of the draw is too: the front end would reject
/// them all, or set them up over no pixel centre. Non-finite corners never cull.
pub(super) fn outside_frustum(
    (lo, hi): (Vec3, Vec3),
    object_to_world: Mat4,
    clip_from_world: Mat4,
) -> bool {
    let m: DMat4 = clip_from_world.as_dmat4() * object_to_world.as_dmat4();
    let clip: [DVec4; 8] = corners(lo, hi).map(|c| m * c.as_dvec3().extend(1.0));
    // The planes' signed distances, positive inside (reversed depth: near at z = w, far
    // at z = 0), as `space::distance64` has them without the guard band.
    let planes: [fn(DVec4) -> f64; 6] = [
        |p| p.w - p.z,
        |p| p.z,
        |p| p.w + p.x,
        |p| p.w - p.x,
        |p| p.w + p.y,
        |p| p.w - p.y,
    ];
    planes.iter().any(|d| {
        clip.iter().all(|p| {
            let size = p.x.abs() + p.y.abs() + p.z.abs() + p.w.abs();
            d(*p) < -MARGIN * size
        })
    })
}

/// A draw's bounding box `(lo, hi)` under `object_to_world`, seen from `camera`: the
/// distance in front of the eye to its nearest corner (0 when a corner lies beside or
/// behind the eye), and the view z of its centre (negative in front).
pub(super) fn draw_depths(
    (lo, hi): (Vec3, Vec3),
    object_to_world: Mat4,
    camera: &Camera,
) -> (f32, f32) {
    let to_view = |p: Vec3| {
        camera
            .view
            .transform_point3(object_to_world.transform_point3(p))
            .z
    };
    let nearest = corners(lo, hi)
        .into_iter()
        .map(to_view)
        .fold(f32::MIN, f32::max);
    // The centre as blended draws were always ordered by (the same arithmetic).
    let centre = to_view((lo + hi) * 0.5);
    ((-nearest).max(0.0), centre)
}

#[cfg(test)]
mod tests;
