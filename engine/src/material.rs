//! Materials: how a surface is shaded, tested and blended.
//!
//! A material is plain data; the shading stage (`shade`) reads it. Colours are straight
//! linear [`Rgba`]; textures are shared through `Arc` so cloning a material is cheap.

use crate::color::Rgba;
use crate::texture::{Sampler, Texture};
use std::sync::Arc;

/// The lighting model.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Shading {
    /// Base colour (times vertex colour and texture) with no lighting.
    #[default]
    Unlit,
    /// Lambert diffuse plus Blinn-Phong specular over the frame's lights.
    Lit {
        /// Specular strength: the highlight is `specular` times the light's colour at its
        /// peak (0 disables highlights; 0.25 in [`Material::lit`]).
        specular: f32,
        /// Blinn-Phong exponent on `n . h` (Schlick's approximation); larger is a smaller,
        /// sharper highlight. Negative values count as 0.
        shininess: f32,
    },
    /// Debug: RGB = little-endian 24-bit (triangle index + 1) within the draw, written as
    /// exact bytes; no lighting, no blending. Pair with a unorm target.
    FaceId,
    /// Per-face colour: mean vertex colour times `0.25 + 0.75 |n . L|` for a fixed light
    /// (the peers' `flat` rule), quantised to bytes. Pair with a unorm target.
    Flat,
}

/// How a fragment's alpha is used (glTF's `alphaMode`).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum AlphaMode {
    /// Alpha ignored; drawn in the opaque pass.
    #[default]
    Opaque,
    /// Fragments with alpha below the cutoff are discarded; opaque pass.
    Mask {
        /// Alpha threshold in [0, 1] (glTF's `alphaCutoff`, default 0.5 there): fragments
        /// whose shaded alpha (base colour times vertex colour and texture) is at least
        /// this are kept.
        cutoff: f32,
    },
    /// Blended in the second pass, back to front, without depth writes (unless
    /// [`Material::blend_depth`]).
    Blend,
    /// Screen-door transparency: a fragment is kept where its alpha exceeds a 4 x 4 ordered
    /// dither threshold at its pixel; opaque pass, with depth writes. Fades alpha-tested
    /// things (a billboard handing over to its fallback) smoothly without sorting.
    Dither,
}

/// How a blended fragment combines with the target (premultiplied colour).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BlendMode {
    /// `dst = src + dst * (1 - src.a)`.
    #[default]
    Alpha,
    /// `dst = src + dst` (fire, glows, lasers).
    Additive,
}

/// A material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The name the file gave it (MTL `newmtl`, glTF `name`), or empty; for messages and
    /// tools, never read when shading.
    pub name: String,
    /// Straight linear colour and alpha, multiplied by the vertex colour and the texture
    /// sample (glTF's `baseColorFactor`, MTL `Kd` and `d`).
    pub base_color: Rgba,
    /// Texture multiplied into the base colour at the mesh's `uvs`, or `None`; a mesh
    /// without uvs samples at (0, 0).
    pub base_texture: Option<Arc<Texture>>,
    /// How `base_texture` is filtered and wrapped.
    pub sampler: Sampler,
    /// Multiply by the mesh's vertex colours when it has them.
    pub vertex_colors: bool,
    /// The lighting model.
    pub shading: Shading,
    /// Opaque, alpha-tested, blended or dithered.
    pub alpha_mode: AlphaMode,
    /// How a blended fragment combines with the target; read only with
    /// [`AlphaMode::Blend`].
    pub blend: BlendMode,
    /// Not culled when back-facing, and lit from the side it is seen from.
    pub double_sided: bool,
    /// Test fragments against the depth buffer.
    pub depth_test: bool,
    /// Soft particles: a blended fragment closer than this distance (view units) in front
    /// of the opaque surface behind it fades out linearly. 0 disables.
    pub soft_distance: f32,
    /// Emitted colour added after lighting, straight linear RGB (alpha ignored); black
    /// (the default) adds nothing.
    pub emissive: Rgba,
    /// Blended only: also write depth where a fragment's alpha (after the soft fade) is at
    /// least this (`None`: blended fragments write no depth). An image standing in for an
    /// opaque object sets it, so that what reads the depth after it (the planner's
    /// occlusion, soft particles, image passes) sees the object.
    pub blend_depth: Option<f32>,
    /// A nailboard's per-texel depth (Schaufler 97), or `None`: read only with
    /// [`AlphaMode::Mask`] and a `base_texture`. See [`DepthOffset`].
    pub depth_offset: Option<DepthOffset>,
    /// Blended with [`BlendMode::Alpha`] and writing no depth only: soft enough (clouds,
    /// fog) to be shaded at a reduced resolution and composited over the frame, when the
    /// renderer's [`crate::Renderer::set_low_res_scale`] is above 1 (it is 1 by default,
    /// and then this is ignored). See the renderer's `lowres` module.
    pub low_res: bool,
}

/// Per-texel depth for an alpha-tested material (a nailboard: an image of an object on
/// one quad, each texel's surface standing behind the quad by its own distance).
///
/// `texture` is read at the base texture's uv, filtered bilinearly on the mip level
/// nearest the base texture's level of detail (so it should have the base texture's size;
/// the material's wrap modes apply), and so is the base texture itself (a trilinear
/// sampler is read on one level, not blended across two: on the showcase's forest at
/// 1280 x 720 the blend cost 13 to 19% of the sprites' raster time for 0.015 dB). Its texels are premultiplied unorm bytes: red over alpha
/// is the fraction of the largest offset; the mip levels then hold the alpha-weighted mean
/// offset; where the read's alpha is 0 there is no surface, and the fragment is dropped. A
/// fragment's surface lies `scale * red / alpha * unit` behind the triangle's plane, along
/// its normal. `unit` is the world length per unit of `u` on the object's reference
/// plane, of which the triangle is the image scaled about the eye to stand `lift * unit`
/// nearer the eye (it covers the same pixels with the same texels): the shader finds it
/// from the triangle's own length per unit of `u`, `len = s * unit`, and the eye's
/// distance `d` to its plane, `s = 1 - lift * len / d`; so one material serves quads of
/// any size at any distance (a unit carried in the vertices' normals was tried: the vertex
/// stage makes them unit length). The shader turns the offset into view depth exactly for
/// perspective cameras (`offset * w / d`, `w` the fragment's view depth; orthographic
/// cameras get `offset / d`, not meaningful). The rasterizer tests the triangle's own
/// depth first (so a quad drawn at its surface's nearest keeps early and hierarchical
/// rejects conservative), then reads the offset and tests the moved depth, and shades and
/// writes only the fragments that pass it, at the moved depth.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthOffset {
    /// Premultiplied unorm texels, offset fraction in red, coverage in alpha.
    pub texture: Arc<Texture>,
    /// The offset of red over alpha = 1, in `unit`s.
    pub scale: f32,
    /// How far the triangle stands in front of the reference plane, in `unit`s.
    pub lift: f32,
    /// `None`: each fragment shows the texel straight behind it on the reference plane,
    /// right for surfaces on that plane and off by their offset's parallax elsewhere (a
    /// pine's lowest rim a third of a pixel high, seen from 40 tree heights). `Some(tol)`:
    /// the images are an orthographic view along the triangle's normal, and each fragment
    /// shows the texel whose surface lies on its own ray, found by a search of one or two
    /// steps, a step kept where the texel reached has the offset it was reached with,
    /// within `tol` (fractions of `scale`), else its own texel (the search, in the shade
    /// stage's `nailboard` module; two or three offset reads a fragment, not one).
    pub parallax: Option<f32>,
    /// The coarsest level of detail read (colour and offset); `f32::INFINITY` for none. A
    /// nailboard stands for a mesh the rasterizer draws sharp (one sample a pixel), which a
    /// view prefiltered over each pixel's footprint is not: reading finer levels keeps the
    /// image's outline as sharp as the mesh's.
    pub max_lod: f32,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            name: String::new(),
            base_color: Rgba::WHITE,
            base_texture: None,
            sampler: Sampler::default(),
            vertex_colors: true,
            shading: Shading::Unlit,
            alpha_mode: AlphaMode::Opaque,
            blend: BlendMode::Alpha,
            double_sided: false,
            depth_test: true,
            soft_distance: 0.0,
            emissive: Rgba::new(0.0, 0.0, 0.0, 0.0),
            blend_depth: None,
            depth_offset: None,
            low_res: false,
        }
    }
}

impl Material {
    /// An unlit material of one colour.
    pub fn unlit(color: Rgba) -> Self {
        Material {
            base_color: color,
            ..Default::default()
        }
    }

    /// A lit (Lambert + Blinn-Phong) material of one colour.
    pub fn lit(color: Rgba) -> Self {
        Material {
            base_color: color,
            shading: Shading::Lit {
                specular: 0.25,
                shininess: 32.0,
            },
            ..Default::default()
        }
    }

    /// The same material with `texture` as its base texture.
    pub fn with_texture(mut self, texture: Arc<Texture>) -> Self {
        self.base_texture = Some(texture);
        self
    }

    /// The same material, double-sided (`true`: never culled, lit from the side seen) or
    /// not.
    pub fn double_sided(mut self, yes: bool) -> Self {
        self.double_sided = yes;
        self
    }

    /// The same material blended ([`AlphaMode::Blend`]) with `mode`.
    pub fn blended(mut self, mode: BlendMode) -> Self {
        self.alpha_mode = AlphaMode::Blend;
        self.blend = mode;
        self
    }

    /// Drawn in the second, sorted, pass.
    pub fn is_blended(&self) -> bool {
        self.alpha_mode == AlphaMode::Blend
    }
}
