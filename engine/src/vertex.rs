//! Vertex stage: object space -> the pipeline's reversed-depth clip space, the clip outcode,
//! and (for vertices inside every clip plane) the snapped screen position, plus the varyings
//! each material's shader reads, written into flat per-frame buffers. Doing the divide and
//! the snap once per vertex, not once per triangle corner, saves most of the front end's
//! work on shared vertices.
//!
//! Runs in parallel over fixed-size chunks of vertices (and, from the renderer, over
//! draws); every output element depends only on its own vertex and draw, so the result is
//! the same at any thread count.

use crate::mesh::Mesh;
use crate::space::{outcode, ScreenVert, Viewport};
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

/// Vertices per parallel task.
pub(crate) const CHUNK: usize = 4096;

/// Outcode bit for a vertex with a non-finite position (its triangles are rejected).
pub const NOT_FINITE: u8 = 0x80;

/// Per-vertex positions: clip space, outcode, and the screen position when the outcode is 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexPos {
    pub clip: Vec4,
    pub screen: ScreenVert,
    pub code: u8,
}

impl Default for VertexPos {
    fn default() -> Self {
        VertexPos {
            clip: Vec4::ZERO,
            screen: ScreenVert::default(),
            code: NOT_FINITE,
        }
    }
}

/// Transforms one draw's vertices. `pos` has one entry per vertex; `vary` has
/// `layout.stride()` floats per vertex.
pub fn transform(
    mesh: &Mesh,
    object_to_world: Mat4,
    clip_from_world: Mat4,
    layout: Layout,
    vp: &Viewport,
    pos: &mut [VertexPos],
    vary: &mut [f32],
) {
    // In f64: with huge coordinates (a ground plane 1e4 units wide) the f32 products cancel
    // to a small view depth and lose most of its digits; the transform is a small part of a
    // frame, so it is done in double precision.
    let mvp = clip_from_world.as_dmat4() * object_to_world.as_dmat4();
    let guard = vp.guard();
    pos.par_chunks_mut(CHUNK)
        .zip(mesh.positions.par_chunks(CHUNK))
        .for_each(|(out, src)| {
            for (o, p) in out.iter_mut().zip(src) {
                let clip = (mvp * p.as_dvec3().extend(1.0)).as_vec4();
                o.clip = clip;
                o.code = if !clip.is_finite() {
                    NOT_FINITE
                } else {
                    outcode(clip, guard)
                };
                if o.code == 0 {
                    match vp.to_screen(clip) {
                        Some(s) => o.screen = s,
                        None => o.code = NOT_FINITE,
                    }
                }
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
