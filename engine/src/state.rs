//! Per-draw pipeline state: which shader family and pixel mode a draw uses and where its
//! vertices, varyings and triangles sit in the frame's buffers. The renderer fills it once
//! per draw; the front end and the raster stage read it.

use crate::material::{AlphaMode, BlendMode, Material};
use crate::mesh::Mesh;
use crate::shade::{ColorShader, ConstShader};
use crate::vertex::Layout;
use glam::Mat4;

/// How fragments that survive shading reach the tile.
#[derive(Clone, Copy, Debug)]
pub struct PixelMode {
    pub depth_test: bool,
    pub depth_write: bool,
    /// Blended fragments write depth where their alpha is at least this (above 1: never).
    pub blend_depth: f32,
    pub alpha: AlphaMode,
    pub blend: BlendMode,
    /// Soft-particle fade distance (view units); 0 = off.
    pub soft: f32,
    /// Depth peeling: only fragments strictly behind the tile's peel depth
    /// ([`TileBuf::peel`]) pass, the second depth compare.
    pub peel: bool,
}

impl PixelMode {
    /// Whether any of its fragments may write depth.
    pub fn writes_depth(&self) -> bool {
        self.depth_write || self.blend_depth <= 1.0
    }
}

/// The fragment shader family a draw uses.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Kind {
    Const(ConstShader),
    Color(ColorShader),
    General,
}

/// What the stages need to know about one draw this frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct DrawInfo<'a> {
    pub(crate) mesh: &'a Mesh,
    pub(crate) material: &'a Material,
    pub(crate) transform: Mat4,
    pub(crate) layout: Layout,
    pub(crate) kind: Kind,
    pub(crate) vert_base: usize,
    pub(crate) vary_base: usize,
    pub(crate) tri_base: usize,
    pub(crate) prim_base: u32,
    pub(crate) cull_back: bool,
    pub(crate) mode: PixelMode,
}
