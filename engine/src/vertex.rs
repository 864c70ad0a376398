//! Vertex stage: object space -> the pipeline's reversed-depth clip space, plus the
//! varyings each material's shader reads, written into flat per-frame buffers.
//!
//! Runs in parallel over fixed-size chunks of vertices; every output element depends only
//! on its own vertex, so the result is the same at any thread count.

use crate::mesh::Mesh;
use glam::{Mat3, Mat4, Vec3, Vec4};
use rayon::prelude::*;

/// Most floats a vertex can carry to the fragment stage.
pub const MAX_VARYINGS: usize = 12;

/// Which varyings a draw's shader reads, and so how many floats each vertex carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Nothing: colour is constant per triangle.
    None,
    /// Straight linear vertex colour `r g b a`.
    Color,
    /// World position (3), world normal (3), uv (2), colour (4).
    Full,
}

impl Layout {
    pub const fn stride(self) -> usize {
        match self {
            Layout::None => 0,
            Layout::Color => 4,
            Layout::Full => 12,
        }
    }
}

/// Offsets inside a `Full` vertex.
pub const POS: usize = 0;
pub const NRM: usize = 3;
pub const UV: usize = 6;
pub const COL: usize = 8;

const CHUNK: usize = 4096;

/// Transforms one draw's vertices. `clip` has one entry per vertex; `vary` has
/// `layout.stride()` floats per vertex.
pub fn transform(
    mesh: &Mesh,
    object_to_world: Mat4,
    clip_from_world: Mat4,
    layout: Layout,
    clip: &mut [Vec4],
    vary: &mut [f32],
) {
    let mvp = clip_from_world * object_to_world;
    clip.par_chunks_mut(CHUNK)
        .zip(mesh.positions.par_chunks(CHUNK))
        .for_each(|(out, pos)| {
            for (o, p) in out.iter_mut().zip(pos) {
                *o = mvp * p.extend(1.0);
            }
        });
    let stride = layout.stride();
    if stride == 0 {
        return;
    }
    let normal_m = Mat3::from_mat4(object_to_world).inverse().transpose();
    let normal_m = if normal_m.is_finite() {
        normal_m
    } else {
        Mat3::IDENTITY
    };
    vary.par_chunks_mut(CHUNK * stride)
        .enumerate()
        .for_each(|(ci, out)| {
            let first = ci * CHUNK;
            for (k, o) in out.chunks_exact_mut(stride).enumerate() {
                let i = first + k;
                let col = mesh.colors.get(i).map_or([1.0; 4], |c| c.to_array());
                match layout {
                    Layout::None => {}
                    Layout::Color => o.copy_from_slice(&col),
                    Layout::Full => {
                        let p = object_to_world.transform_point3(mesh.positions[i]);
                        let n = mesh
                            .normals
                            .get(i)
                            .map_or(Vec3::ZERO, |n| (normal_m * *n).normalize_or_zero());
                        let uv = mesh.uvs.get(i).copied().unwrap_or_default();
                        o[POS..POS + 3].copy_from_slice(&p.to_array());
                        o[NRM..NRM + 3].copy_from_slice(&n.to_array());
                        o[UV..UV + 2].copy_from_slice(&uv.to_array());
                        o[COL..COL + 4].copy_from_slice(&col);
                    }
                }
            }
        });
}
