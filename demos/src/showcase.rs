//! The showcase's built-in scene, its animation, its deterministic camera path and the fly
//! camera: everything the `showcase` binary shows, without the window, so it can be tested.
//!
//! The scene needs no download: a noise terrain with a flat plaza in the middle, a
//! vertex-coloured spinning torus on a pedestal, lit spheres, crates with a generated wood
//! texture, a checker-textured plaza, an alpha-tested lattice fence (`AlphaMode::Mask`),
//! blended glass (`AlphaMode::Blend`), a house, trees and rocks, lit by a sun and two point
//! lights (one orbiting the torus, marked by a glowing lamp). Its image-based layer
//! ([`crate::showcase::ibr_layer`]) adds a billboard forest, a laser exchange with explosions,
//! the sun's lens flare, a sky of clouds drawn through runtime impostors, and a city
//! district whose buildings a planner draws as geometry, impostors or image layers
//! ([`crate::showcase::impostors`]). Its moments: the building tour ([`building`]), the
//! views ([`views`]) and the world of many objects drawn per node of a hierarchy
//! ([`world`]).

pub mod attractions;
pub mod building;
pub mod ibr_layer;
pub mod impostors;
pub mod lightfield;
pub mod lod;
pub mod moment;
pub mod summary;
pub mod views;
pub mod world;

mod build;
mod fly;
mod path;
mod textures;

pub use fly::{toggled, FlyCamera, FlyInput, TapCounter};
pub use textures::{crate_texture, lattice_texture};

use crate::showcase::ibr_layer::IbrLayer;
use crate::showcase::lod::TourLod;
use engine::procedural::Terrain;
use engine::{Camera, FrameOptions, FrameStats, Light, Mesh, Renderer, Rgba, Scene, Target};
use glam::{Mat4, Vec3};

/// Clear colour of the showcase (a pale sky).
pub const SKY: Rgba = Rgba::new(0.42, 0.62, 0.86, 1.0);
/// Vertical field of view of the showcase cameras, radians.
pub const FOV_Y: f32 = 1.05;
/// Far plane of the showcase cameras.
pub const FAR: f32 = 250.0;

/// The scene plus the handles its animation needs.
#[derive(Debug)]
pub struct Showcase {
    pub scene: Scene,
    pub terrain: Terrain,
    /// Billboards, lasers, effects and the lens flare.
    pub ibr: IbrLayer,
    /// The tour's levels of detail (terrain patches, torus, spheres), applied for the span
    /// of each [`Showcase::render`].
    pub lod: TourLod,
    torus: usize,
    lamp: usize,
    lamp_light: usize,
    /// The last frame's draws by group, when counted ([`Showcase::count_draws`]).
    draws: Option<ibr_layer::DrawGroups>,
    /// How many times smaller each way the clouds' particles and fog (not their images,
    /// which write depth) are shaded, on the frames they fill the view ([`Renderer::set_low_res_scale`], set on the renderer by each
    /// [`Showcase::render`]): [`CLOUD_LOW_RES`] by default, 1 for full resolution.
    pub low_res_scale: u32,
}

/// The clouds' reduced resolution: half each way, a quarter of their blended fragments.
/// Soft subjects lose little to it (the cloud attraction's PSNR is measured on the frame
/// as drawn, against full-resolution particles); the 1280x720 tour's cloud fly-through
/// shaded 3.3 to 5.7 M blended cloud fragments a frame at full resolution (BENCHMARKS.md,
/// session 23).
pub const CLOUD_LOW_RES: u32 = 2;

impl Showcase {
    /// Builds the scene (deterministic: same triangles and pixels every time).
    pub fn new() -> Showcase {
        build::build()
    }

    /// Poses the animated parts at time `t` seconds: the torus spins, the lamp orbits, the
    /// lasers fire and the effects advance.
    pub fn animate(&mut self, t: f32) {
        self.ibr.pose(t);
        let s = &mut self.scene;
        s.instances[self.torus].transform = Mat4::from_translation(Vec3::new(0.0, 2.1, 0.0))
            * Mat4::from_rotation_y(t * 0.7)
            * Mat4::from_rotation_x(1.1 + 0.25 * (t * 0.9).sin());
        let p = lamp_position(t);
        s.instances[self.lamp].transform = Mat4::from_translation(p);
        if let Some(Light::Point { position, .. }) = s.lighting.lights.get_mut(self.lamp_light) {
            *position = p;
        }
    }
}

impl Showcase {
    /// Renders the scene and its image-based layer for `camera` (two passes: the scene
    /// with billboards, lasers and effects, then the lens flare), with the levels of
    /// detail picked for this view ([`TourLod::apply`]) and put back after it.
    pub fn render(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        self.lod.apply(&mut self.scene, camera, target.height());
        renderer.set_low_res_scale(self.low_res_scale);
        let stats = self.ibr.render(&self.scene, renderer, camera, target, opts);
        if let Some(groups) = &mut self.draws {
            let terrain = |k| self.lod.is_terrain(k);
            let costs = renderer.draw_costs();
            groups.error = self
                .ibr
                .draw_groups(&self.scene, terrain, costs, groups)
                .err();
        }
        self.lod.restore(&mut self.scene);
        stats
    }

    /// Counts each frame's draws by group from the next [`Showcase::render`] on (off by
    /// default: the renderer reads the clock twice per triangle and tile), or stops.
    pub fn count_draws(&mut self, renderer: &mut Renderer, on: bool) {
        renderer.set_draw_costs(on);
        self.draws = on.then(Default::default);
    }

    /// The last frame's draws by group (`None` unless [`Showcase::count_draws`] is on).
    pub fn draw_groups(&self) -> Option<&ibr_layer::DrawGroups> {
        self.draws.as_ref()
    }
}

/// Most frames [`Showcase::prepare`] renders at loading.
pub const PREPARE_FRAMES: usize = 8;

/// What [`Showcase::prepare`] did at loading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Prepared {
    /// Frames rendered (untimed, not shown).
    pub frames: usize,
    /// Impostor refreshes (clouds' and city's rebuilds) they did.
    pub refreshes: usize,
}

impl Showcase {
    /// Prepares the first frame at loading: poses the scene at time 0 and renders the
    /// view from `camera` (the camera path's first, known ahead) until the impostors
    /// refresh nothing more, at most
    /// [`PREPARE_FRAMES`] times, its refresh budgets lifted (no frame is shown), so the
    /// clouds' and the city's first captures (and every buffer's first growth) are done
    /// before frame 0 instead of in it and the frames after it (at 640x360 frame 0's
    /// `impostors` stage took 49 ms of its 83, issue 39). The impostors' run counters
    /// restart after it, so they count the tour's frames.
    pub fn prepare(
        &mut self,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> Prepared {
        let mut done = Prepared::default();
        self.animate(0.0);
        self.ibr.impostors.set_loading(true);
        while done.frames < PREPARE_FRAMES {
            self.render(renderer, camera, target, opts);
            done.frames += 1;
            let refreshes = self.ibr.impostors.readout().refreshes();
            done.refreshes += refreshes;
            if refreshes == 0 {
                break;
            }
        }
        self.ibr.impostors.set_loading(false);
        self.ibr.impostors.restart_run_stats();
        done
    }
}

impl Default for Showcase {
    fn default() -> Self {
        Self::new()
    }
}

fn lamp_position(t: f32) -> Vec3 {
    let a = t * 0.8;
    Vec3::new(3.2 * a.cos(), 1.6 + 0.4 * (t * 1.3).sin(), 3.2 * a.sin())
}

/// A camera for the showcase at `eye` looking at `target`, for a `width` x `height` image.
pub fn camera(eye: Vec3, target: Vec3, width: u32, height: u32) -> Camera {
    Camera::look_at(eye, target, Vec3::Y, FOV_Y, 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.1, FAR)
}

/// Checks a mesh list: every mesh valid (used by tests and debug builds).
pub fn validate(scene: &Scene) -> Result<(), String> {
    scene
        .meshes
        .iter()
        .enumerate()
        .try_for_each(|(i, m): (usize, &Mesh)| m.validate().map_err(|e| format!("mesh {i}: {e}")))
}

#[cfg(test)]
mod tests;
