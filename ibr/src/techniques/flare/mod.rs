//! Lens flare: a light source projected to the screen, its visibility measured in the depth
//! buffer after the opaque pass and faded over time, and a row of additive sprites (glow,
//! halo, ring, ghosts, starburst) along the line from the light through the screen centre.
//!
//! Frame: render the scene (clearing) -> [`LensFlare::update`] -> render
//! [`LensFlare::draw`] with the same camera and `FrameOptions { clear: None, .. }`, or
//! [`LensFlare::blend`] the sprites straight into the target (only the pixels they reach). The
//! sprites are quads unprojected from pixel positions to world space in front of the eye,
//! so that camera puts them back exactly on those pixels. Draws that write no depth
//! (blended impostors, clouds, glass) hide the light too through
//! [`LensFlare::update_with_blended`], which captures them into a small [`probe`] around the
//! light and dims each tap by their opacity. All shapes live in one atlas
//! generated at start-up ([`atlas`]); the mesh is rewritten in place every frame.

mod blend;
mod technique;
pub use blend::{AtlasAlpha, Placed, Reach};
pub use technique::Flare;
mod occlusion;
pub mod probe;

pub use occlusion::{measure, occlusion, occlusion_through, project, Projected, Seen};

use crate::core::Capturer;
use crate::core::{push_quad, UvRect};
use engine::{
    BlendMode, Camera, Draw, Encoding, FrameStats, Lighting, Material, Mesh, Rgba, Target, Texture,
    Wrap,
};
use glam::{Mat4, Vec2, Vec3, Vec4};
use std::f32::consts::TAU;
use std::sync::Arc;

/// Where the light is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FlareSource {
    /// A point in the world (a lamp, an explosion). Absent behind the eye or outside the
    /// camera's depth range; hidden by anything drawn nearer than it, including a mesh drawn
    /// around it (a bulb): keep such a mesh out of the opaque pass or move the point out.
    Point(Vec3),
    /// A light at infinity in this world direction (toward the light, e.g. the sun).
    /// Visible only where nothing was drawn (the depth buffer keeps its cleared value 0),
    /// so do not draw an opaque sky over it. Needs a perspective camera.
    Directional(Vec3),
}

/// The sprite shapes of the flare atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlareShape {
    /// A bright core with a wide soft falloff.
    Glow,
    /// A soft thin ring with a wide falloff.
    Halo,
    /// A sharper thin ring.
    Ring,
    /// A soft-edged hexagon with a slightly brighter rim (an aperture ghost).
    Ghost,
    /// Rays of several lengths around a small core.
    Starburst,
}

impl FlareShape {
    /// Every shape, in atlas order ([`FlareShape::index`]).
    pub const ALL: [FlareShape; 5] = [
        FlareShape::Glow,
        FlareShape::Halo,
        FlareShape::Ring,
        FlareShape::Ghost,
        FlareShape::Starburst,
    ];

    /// The shape's alpha at `p` (in units of the sprite's half size, centre at 0). Every
    /// shape is exactly 0 at distance 1 and beyond, so quads show no edges.
    pub fn alpha(self, p: Vec2) -> f32 {
        let r = p.length();
        let edge = smoothstep(1.0, 0.8, r);
        let a = match self {
            FlareShape::Glow => crate::core::sprites::glow_profile(r),
            FlareShape::Halo => (-((r - 0.7) / 0.13).powi(2)).exp() * edge,
            FlareShape::Ring => (-((r - 0.8) / 0.035).powi(2)).exp() * edge,
            FlareShape::Ghost => {
                // Hexagon "radius": the largest projection on three normals 60 deg apart.
                let h = (0..3)
                    .map(|k| {
                        let (s, c) = (k as f32 * TAU / 6.0).sin_cos();
                        (p.x * c + p.y * s).abs()
                    })
                    .fold(0.0, f32::max);
                smoothstep(0.8, 0.68, h) * (0.55 + 0.45 * (h / 0.74).min(1.0).powi(3))
            }
            FlareShape::Starburst => {
                let t = p.y.atan2(p.x);
                let rays =
                    (6.0 * t).cos().abs().powi(48) + 0.5 * (17.0 * t + 0.4).cos().abs().powi(64);
                let fall = (1.0 - r).clamp(0.0, 1.0);
                ((-r * r * 60.0).exp() + 0.9 * rays * fall * fall) * edge
            }
        };
        a.clamp(0.0, 1.0)
    }

    /// The shape's cell index in the atlas.
    pub fn index(self) -> u32 {
        self as u32
    }
}

/// Atlas layout: `ATLAS_COLS` x `ATLAS_ROWS` cells, each inset by `GUTTER` texels on every
/// side (transparent), so bilinear taps at a region's border never reach a neighbour.
pub const ATLAS_COLS: u32 = 3;
/// Rows of atlas cells (see [`ATLAS_COLS`]).
pub const ATLAS_ROWS: u32 = 2;
/// Transparent border inside each atlas cell, texels (see [`ATLAS_COLS`]).
pub const GUTTER: u32 = 2;

/// The flare atlas: every [`FlareShape`] in its cell, `cell_px` texels square (gutter
/// included), white with the shape in alpha, unorm, premultiplied (every byte the alpha,
/// so the renderer's sampler reads the stored bytes as they are), mipmapped.
pub fn atlas(cell_px: u32) -> Texture {
    let cell = cell_px.max(2 * GUTTER + 4);
    let (w, h) = (cell * ATLAS_COLS, cell * ATLAS_ROWS);
    let half = (cell - 2 * GUTTER) as f32 * 0.5;
    let mut texels = Vec::with_capacity(w as usize * h as usize);
    for y in 0..h {
        for x in 0..w {
            let index = (y / cell) * ATLAS_COLS + x / cell;
            let local = Vec2::new((x % cell) as f32 + 0.5, (y % cell) as f32 + 0.5);
            let p = (local - Vec2::splat(cell as f32 * 0.5)) / half;
            let a = FlareShape::ALL
                .get(index as usize)
                .map_or(0.0, |s| s.alpha(p));
            texels.push(u32::from((a * 255.0).round() as u8) * 0x0101_0101);
        }
    }
    Texture::from_packed(w, h, texels, Encoding::Unorm, true).expect("size is valid")
}

/// The atlas region of `shape` for an atlas of `cell_px` cells: its cell minus the gutter.
pub fn region(shape: FlareShape, cell_px: u32) -> UvRect {
    let cell = cell_px.max(2 * GUTTER + 4);
    let c = UvRect::cell(ATLAS_COLS, ATLAS_ROWS, shape.index());
    let inset = Vec2::new(
        GUTTER as f32 / (cell * ATLAS_COLS) as f32,
        GUTTER as f32 / (cell * ATLAS_ROWS) as f32,
    );
    UvRect {
        min: c.min + inset,
        max: c.max - inset,
    }
}

/// One sprite of the flare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlareElement {
    /// Place along the line from the light (0) through the screen centre (1); 2 mirrors
    /// the light across the centre. Any value works.
    pub position: f32,
    /// Side of the square sprite as a fraction of the image height.
    pub size: f32,
    /// Straight linear colour; additive, so `rgb * a` is added at full visibility.
    pub tint: Rgba,
    /// The sprite drawn (its cell of the [`atlas`]).
    pub shape: FlareShape,
}

impl FlareElement {
    /// An element at `position` along the flare line, `size` (fraction of the image height)
    /// across, with straight linear `tint`, showing `shape`.
    pub const fn new(position: f32, size: f32, tint: Rgba, shape: FlareShape) -> Self {
        FlareElement {
            position,
            size,
            tint,
            shape,
        }
    }
}

/// A warm sun flare: starburst, glow and halo on the light, ghosts and rings toward and
/// past the centre.
pub fn sun_elements() -> Vec<FlareElement> {
    use FlareShape::*;
    let c = Rgba::new;
    vec![
        FlareElement::new(0.0, 1.0, c(1.0, 0.85, 0.6, 0.6), Glow),
        FlareElement::new(0.0, 0.6, c(1.0, 0.95, 0.85, 1.0), Starburst),
        FlareElement::new(0.0, 1.3, c(0.9, 0.8, 0.7, 0.3), Halo),
        FlareElement::new(0.45, 0.09, c(0.5, 0.95, 0.4, 0.6), Ghost),
        FlareElement::new(0.7, 0.15, c(0.4, 0.6, 1.0, 0.75), Ghost),
        FlareElement::new(1.25, 0.07, c(1.0, 0.55, 0.25, 0.7), Ghost),
        FlareElement::new(1.5, 0.32, c(0.45, 0.8, 1.0, 0.45), Ring),
        FlareElement::new(1.8, 0.2, c(0.8, 0.45, 1.0, 0.5), Ghost),
        FlareElement::new(2.0, 0.55, c(0.5, 0.7, 1.0, 0.3), Halo),
    ]
}

/// Moves a displayed visibility toward `target` by at most `rate * dt` (linear fade). `dt`
/// of 0 (or negative, NaN) leaves it; a rate that is not positive and finite, or a huge
/// `dt`, snaps. The result stays in [0, 1].
pub fn approach(displayed: f32, target: f32, rate: f32, dt: f32) -> f32 {
    let unit = |x: f32| if x.is_nan() { 0.0 } else { x.clamp(0.0, 1.0) };
    let (target, displayed) = (unit(target), unit(displayed));
    if dt.is_nan() || dt <= 0.0 {
        return displayed;
    }
    if !(rate > 0.0 && rate.is_finite()) {
        return target;
    }
    let step = rate * dt;
    let diff = target - displayed;
    if diff.abs() <= step {
        target
    } else {
        displayed + step.copysign(diff)
    }
}

/// What the flare measured last frame.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct FlareState {
    /// Raw visible fraction from the depth buffer (0 when the light is absent).
    pub measured: f32,
    /// Faded visibility that scales the sprites.
    pub displayed: f32,
    /// The light's projection, if it had one.
    pub light: Option<Projected>,
}

/// A lens flare: its elements, occlusion and fade settings, atlas material and mesh.
#[derive(Clone, Debug)]
pub struct LensFlare {
    /// The sprites, each placed along the line from the light through the screen centre.
    pub elements: Vec<FlareElement>,
    /// Depth taps per frame (at least 1).
    pub samples: u32,
    /// Radius of the tap disc around the light, pixels.
    pub radius_px: f32,
    /// Visibility change per second (4 = a full fade in 0.25 s); not positive = no fade.
    pub fade_per_second: f32,
    /// The last measured and displayed visibility, and the light's projection.
    pub state: FlareState,
    material: Material,
    mesh: Mesh,
    /// The atlas's alphas and shapes' reach, for [`LensFlare::blend`].
    alpha: Arc<AtlasAlpha>,
    /// The sprites as placed by the last update (the mesh's quads, in pixels).
    placed: Vec<Placed>,
    /// Captures the blended occluders around the light.
    capturer: Capturer,
}

/// Atlas cell size used by [`LensFlare::new`].
pub const CELL_PX: u32 = 64;

/// Below this displayed visibility no quads are written.
pub const MIN_VISIBILITY: f32 = 1e-3;

impl Default for LensFlare {
    /// The sun preset ([`sun_elements`]).
    fn default() -> Self {
        Self::new(sun_elements())
    }
}

impl LensFlare {
    /// A flare of `elements` with 32 taps in a 6-pixel disc and a 0.25 s fade.
    pub fn new(elements: Vec<FlareElement>) -> Self {
        let texture = Arc::new(atlas(CELL_PX));
        let alpha = Arc::new(AtlasAlpha::new(&texture));
        let mut material = Material::unlit(Rgba::WHITE)
            .with_texture(texture)
            .blended(BlendMode::Additive)
            .double_sided(true);
        material.depth_test = false;
        material.sampler.wrap_u = Wrap::Clamp;
        material.sampler.wrap_v = Wrap::Clamp;
        material.name = "lens flare".into();
        LensFlare {
            elements,
            samples: 32,
            radius_px: 6.0,
            fade_per_second: 4.0,
            state: FlareState::default(),
            material,
            mesh: Mesh::default(),
            alpha,
            placed: Vec::new(),
            capturer: Capturer::new(),
        }
    }

    /// Measures the light's visibility in `target`'s depth buffer (after the opaque pass),
    /// fades the displayed value by `dt` seconds and rewrites the mesh. Returns the displayed
    /// visibility. A light without a projection (behind the eye, NaN...) shows nothing and
    /// resets the fade, as its screen position is undefined. Only surfaces that wrote depth
    /// hide the light: a frame with blended draws uses [`LensFlare::update_with_blended`].
    pub fn update(
        &mut self,
        camera: &Camera,
        target: &Target,
        source: FlareSource,
        dt: f32,
    ) -> f32 {
        let (w, h) = (target.width(), target.height());
        let light = project(camera, source, w, h);
        let measured = light.map_or(0.0, |l| occlusion(target, &l, self.samples, self.radius_px));
        self.finish(camera, light, measured, dt, w, h)
    }

    /// [`LensFlare::update`] for a frame with blended draws: `draws` are the frame's draws
    /// (all of them may be passed; only the alpha-blended, non-additive ones are used), and
    /// each tap is dimmed by their accumulated opacity there, so an impostor hides the light
    /// by its coverage and a cloud by its opacity. Costs one capture of those draws into a
    /// [`probe::PROBE_SIDE`]-pixel square, skipped when the depth taps already see the light
    /// hidden or absent.
    pub fn update_with_blended<'a>(
        &mut self,
        camera: &Camera,
        target: &Target,
        source: FlareSource,
        dt: f32,
        lighting: &Lighting,
        draws: impl IntoIterator<Item = Draw<'a>>,
    ) -> f32 {
        let (w, h) = (target.width(), target.height());
        let light = project(camera, source, w, h);
        let measured = light.map_or(0.0, |l| {
            let (samples, radius) = (self.samples, self.radius_px);
            let seen = Seen {
                target,
                camera,
                lighting,
            };
            measure(&mut self.capturer, &seen, draws, &l, samples, radius)
        });
        self.finish(camera, light, measured, dt, w, h)
    }

    /// Takes a visibility measured elsewhere (by [`measure`] in a frame loop; `None` when the
    /// light had no projection), fades toward it by `dt` seconds and rewrites the mesh, as
    /// [`LensFlare::update`] does after measuring. Returns the displayed visibility.
    pub fn set_measured(
        &mut self,
        camera: &Camera,
        source: FlareSource,
        measured: Option<f32>,
        dt: f32,
        width: u32,
        height: u32,
    ) -> f32 {
        let light = project(camera, source, width, height);
        let measured = light.and(measured).unwrap_or(0.0);
        self.finish(camera, light, measured, dt, width, height)
    }

    /// Fades toward `measured` and rewrites the mesh.
    fn finish(
        &mut self,
        camera: &Camera,
        light: Option<Projected>,
        measured: f32,
        dt: f32,
        w: u32,
        h: u32,
    ) -> f32 {
        let displayed = match light {
            Some(_) => approach(self.state.displayed, measured, self.fade_per_second, dt),
            None => 0.0,
        };
        self.state = FlareState {
            measured,
            displayed,
            light,
        };
        self.build(camera, w, h);
        displayed
    }

    /// The raw visible fraction of the last update.
    pub fn measured(&self) -> f32 {
        self.state.measured
    }

    /// The faded visibility of the last update.
    pub fn visibility(&self) -> f32 {
        self.state.displayed
    }

    /// Writes one quad per element for the current state.
    fn build(&mut self, camera: &Camera, width: u32, height: u32) {
        let m = &mut self.mesh;
        m.clear();
        self.placed.clear();
        let Some(light) = self.state.light else {
            return;
        };
        let vis = self.state.displayed;
        if vis <= MIN_VISIBILITY {
            return;
        }
        let inv = camera.clip_from_world().inverse();
        // Reversed NDC depth 0.5: inside [near, far] for both projections (about twice the
        // near distance for a perspective camera). Depth is not tested, only placement.
        let z = 0.5;
        let (wf, hf) = (width as f32, height as f32);
        let unproject = |px: Vec2| {
            let p = inv * Vec4::new(2.0 * px.x / wf - 1.0, 1.0 - 2.0 * px.y / hf, z, 1.0);
            p.truncate() / p.w
        };
        let centre = Vec2::new(wf, hf) * 0.5;
        for e in &self.elements {
            let half = e.size.abs() * hf * 0.5;
            let pos = light.pixel + (centre - light.pixel) * e.position;
            if !(half > 0.0 && pos.is_finite()) {
                continue;
            }
            // Bottom-left, bottom-right, top-right, top-left as seen (pixel y grows down).
            let q = [(-1.0, 1.0), (1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]
                .map(|(sx, sy)| unproject(pos + Vec2::new(sx, sy) * half));
            if q.iter().all(|p| p.is_finite()) {
                push_quad(m, q, region(e.shape, CELL_PX), e.tint, vis);
                self.placed
                    .push(Placed::new(e, pos, half, vis, &self.alpha));
            }
        }
    }

    /// The pixels of a `width` x `height` image the last update's sprites cover, summed
    /// over the sprites (each its square clipped to the image): what drawing them blends.
    pub fn sprite_pixels(&self, width: u32, height: u32) -> u64 {
        let Some(light) = self.state.light else {
            return 0;
        };
        if self.quad_count() == 0 {
            return 0;
        }
        let (wf, hf) = (width as f32, height as f32);
        let centre = Vec2::new(wf, hf) * 0.5;
        let span = |lo: f32, hi: f32, n: f32| (hi.min(n) - lo.max(0.0)).max(0.0) as f64;
        let sum: f64 = self
            .elements
            .iter()
            .map(|e| {
                let half = e.size.abs() * hf * 0.5;
                let pos = light.pixel + (centre - light.pixel) * e.position;
                if !(half > 0.0 && pos.is_finite()) {
                    return 0.0;
                }
                span(pos.x - half, pos.x + half, wf) * span(pos.y - half, pos.y + half, hf)
            })
            .sum();
        sum.round() as u64
    }

    /// The pixels of a `width` x `height` image within the last update's sprites' reach
    /// (each sprite's disc or ring where its shape is not zero, clipped to the image),
    /// summed over the sprites: what [`LensFlare::blend`] looks at.
    pub fn reach_pixels(&self, width: u32, height: u32) -> u64 {
        self.placed
            .iter()
            .map(|p| p.reach_pixels(width, height))
            .sum()
    }

    /// The sprites as the last update placed them.
    pub fn placed(&self) -> &[Placed] {
        &self.placed
    }

    /// Adds the last update's sprites to `target` (the size given to the update) as an
    /// image pass over their reach only: the same light as rendering [`LensFlare::draw`]
    /// with `clear: None` (up to the float sums' order), without loading and resolving
    /// every tile. Keeps the target's depth and alpha.
    pub fn blend(&self, target: &mut Target) -> FrameStats {
        let atlas = self.material.base_texture.as_deref().expect("the atlas");
        blend::blend(&self.placed, &self.alpha, atlas, target)
    }

    /// Quads written by the last update.
    pub fn quad_count(&self) -> usize {
        self.mesh.positions.len() / 4
    }

    /// The mesh of the last update (world space).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// The additive, unlit, double-sided, depth-test-off atlas material.
    pub fn material(&self) -> &Material {
        &self.material
    }

    /// The draw for the renderer (identity transform), for the camera given to `update`.
    pub fn draw(&self) -> Draw<'_> {
        Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: Mat4::IDENTITY,
        }
    }
}

fn smoothstep(lo: f32, hi: f32, x: f32) -> f32 {
    let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod blend_tests;
#[cfg(test)]
mod tests;
