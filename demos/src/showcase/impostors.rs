//! The showcase's image-based sky and city: a sky of cumulus clouds over the billboard
//! forest, each cloud drawn through a runtime impostor ([`ibr::impostor`]), and a small city
//! district on the hills whose buildings are the objects of a planner ([`ibr::plan`]) that
//! chooses each frame how each is drawn: as its geometry, a runtime impostor or an image
//! layer ([`ibr::layers`]), the cheapest whose predicted error is within
//! [`CITY_ERROR_LEVELS`], the images rebuilt within a per-frame budget.
//!
//! - The sky: a [`CloudField`] of [`CLOUD_COUNT`] cumulus clouds of [`CLOUD_PARTICLES`]
//!   particles, their flat bases at [`CLOUD_BASE`] (the camera path climbs into one), lit
//!   by the scene's sun. A cloud is its impostor image from afar, re-rendered when its
//!   predicted parallax reaches the tolerance (1 px a 360-line image), worst first within
//!   the budget (a count, and the texels of captures a frame earns); within 1.25
//!   radii of its centre the image is refreshed every frame, and with the eye inside its
//!   bounding sphere it is drawn as its particles, so flying into it does not pop.
//! - The city: [`CITY_GRID`]² box buildings ([`crate::city::building`], faces split
//!   [`CITY_DETAIL`]² with a vertex-coloured window pattern, lit) around [`CITY_CENTER`], on
//!   a fairly flat stretch of the hills west of the plaza, their foundations sunk below the
//!   lowest ground under them. Trees and rocks keep out of the district ([`in_city`]). The
//!   planner's representations are [`CITY_REPRESENTATIONS`], in that order; an impostor's
//!   quad is drawn at the depth of its building's nearest box corner, so the ground in
//!   front of the walls does not hide the bottom of the image.
//!
//! Both are updated every frame before the draw list is built; their images are blended
//! quads, sorted back to front with the scene's other blended draws. The [`Readout`] of a
//! frame and the [`RunStats`] of a run feed the showcase's on-screen lines and its headless
//! statistics. [`Impostors::set_debug`] colours each cloud image by its predicted error
//! (green 0, yellow at the tolerance, red at twice it) and each building by its
//! representation ([`Impostors::legend`]: geometry flat white, impostors green, layers
//! blue).

mod chart;
mod readout;

pub use chart::tour_chart;
pub use readout::{CityReport, Readout, RunStats, HISTORY};

use crate::city;
use engine::procedural::{Terrain, XorShift};
use engine::{Draw, Lighting, Material, Rgba, Shading, Sphere};
use glam::{Mat4, Vec2, Vec3};
use ibr::cloud::CloudField;
use ibr::impostor::{Budget, Config, ImpostorSet, Mode, Shape, Tolerance};
use ibr::layers::{self, LayerSet};
use ibr::plan::{self, Budgets, Geometry, Planner, Representation};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::FrameView;
use std::sync::Arc;

/// Centre (XZ) of the city district.
pub const CITY_CENTER: Vec2 = Vec2::new(-38.0, 0.0);
/// Buildings per side of the district.
pub const CITY_GRID: u32 = 5;
/// Distance between neighbouring buildings' centres.
pub const CITY_SPACING: f32 = 5.5;
/// Faces of each building split this many times each way (`10 k²` triangles a building).
pub const CITY_DETAIL: u32 = 8;
/// Clouds in the sky.
pub const CLOUD_COUNT: usize = 14;
/// Particles per cloud.
pub const CLOUD_PARTICLES: usize = 200;
/// Height of the clouds' flat bases.
pub const CLOUD_BASE: f32 = 30.0;
/// Half the side of the square the clouds are scattered over (centred on the plaza).
const CLOUD_AREA: f32 = 56.0;
/// Cloud refreshes a frame may do (the city's rebuilds beside them: [`city_rebuilds`]). A cloud's
/// capture (200 blended puffs over up to 256² texels) costs about four times a building's
/// (measured 4.4 against 1.1 ms on a loaded core), and near a cloud the every-frame
/// refreshes come first.
const CLOUD_BUDGET: usize = 2;
/// Texels of cloud captures a frame earns ([`ImpostorSet::texel_budget`]): an eighth of
/// the largest capture, so about one 90² cloud a frame at 640x360 or one 256² every eighth
/// frame. A capture's cost is its fill (200 blended puffs, measured 5.3 shaded fragments a
/// texel over the 1280x720 tour); with the camera moving, clouds want a refresh nearly every
/// frame whatever the budget. At half the largest capture (until session 14) the 640x360
/// tour captured 3.15 M cloud texels in 171 refreshes on 93 of 120 frames, the largest
/// part of the `impostors` stage's median; at a quarter 1.69 M in 94, the frame's
/// fragments shaded 2.22 -> 2.31 a pixel from the stale clouds drawn as particles, the
/// clouds at 61.6 / 34.1 dB against 51.4 / 36.6 (BENCHMARKS.md, session 14). A cloud
/// whose image is too stale meanwhile is drawn as its particles
/// ([`Config::fallback_ratio`]), so no image over the tolerance is shown. The same at
/// every size: a share of the frame's pixels instead (4,096 at 640x360) was tried in
/// session 17 and cut the 640x360 tour's cloud texels 1.69 M -> 0.52 M, but at 240x136
/// the clouds' worst frame fell to 23.7 dB (BENCHMARKS.md, session 17). Since session 19
/// the images are sized to their discs ([`CLOUD_SIDE_STEP`]), about half the texels of
/// the power of two: at an eighth the 640x360 tour captures 0.89 M texels in 85 refreshes
/// (a quarter with powers of two: 1.69 M in 94), the clouds at 55.3 / 32.7 dB
/// (BENCHMARKS.md, session 19).
pub const CLOUD_TEXELS: u64 = (CLOUD_MAX_SIDE as u64 * CLOUD_MAX_SIDE as u64) / 8;

/// A cloud image's side is its disc on screen rounded up to a multiple of this
/// ([`ImpostorSet::side_step`]): a texel a screen pixel or more, refreshed once the disc
/// outgrows it. The power of two at or above the disc (until session 19) took 1 to 4
/// texels a pixel, and the fill is what a capture costs. 32 took as many texels in fewer
/// refreshes (72 against 85 over the 640x360 tour, BENCHMARKS.md, session 19).
pub const CLOUD_SIDE_STEP: u32 = 16;

/// Screens of cloud particles (their quads' areas summed over the clouds drawn as
/// particles, [`Cloud::fill`](ibr::cloud::Cloud::fill)) from which a frame draws them at the renderer's
/// reduced resolution ([`crate::showcase::CLOUD_LOW_RES`]). Below it the three-pass frame
/// and the composite cost more than the fragments saved: composited at full screen, the
/// small target took 4.7 ms at 1280x720 (2 threads), about what shading 0.6 screens of
/// particles at full resolution takes (BENCHMARKS.md, session 23).
pub const CLOUD_LOW_RES_FILL: f32 = 1.5;

/// Pixels of cloud particles below which a frame draws them at full resolution whatever
/// its size: a small frame's particles are cheap, and at half its size a puff's detail
/// is a pixel or two (at the tests' 240 x 136, with the fill alone, the clouds measured
/// 37.0 / 20.5 dB against 40.2 / 26.8: BENCHMARKS.md, session 23).
pub const CLOUD_LOW_RES_PIXELS: f32 = 1_200_000.0;

/// The city's rebuilds a frame whose clouds captured nothing ([`city_rebuilds`]); at
/// loading, every building may rebuild.
pub const CITY_BUDGET: usize = 2;
/// The most images each of the city's image representations rebuilds in one call.
const CITY_CAP: usize = 6;
/// Until session 16 the city rebuilt up to 6 images a frame whatever the clouds did: the
/// 640x360 tour's slowest frame (61, 66 to 80 ms quiet) was six 256² city captures and a
/// cloud's on one frame, and frames 1 and 2 took six each (BENCHMARKS.md, session 16).
/// The clouds and the city now share one budget of captures a frame: a frame whose
/// clouds captured an image rebuilds at most one building, others [`CITY_BUDGET`] (a
/// building's image is up to [`CITY_MAX_SIDE`]², eight times the clouds' texels a frame).
/// A deferred rebuild leaves its building to the planner's next frame (drawn as geometry
/// meanwhile when no image is within the error budget).
pub fn city_rebuilds(cloud_texels: u64) -> usize {
    if cloud_texels > 0 {
        1
    } else {
        CITY_BUDGET
    }
}
/// Largest impostor texture sides. Near a cloud its image spans a wide field of view
/// (up to 180 degrees at the switch to particles), so its centre gets few texels: at 128
/// the switch pops (the no-pop test measures a frame difference 2.5 times the typical),
/// at 256 it does not.
const CLOUD_MAX_SIDE: u32 = 256;
/// The city's: 256 (was 512 until session 13). At 3 texels a pixel ([`CITY_DENSITY`]) a
/// near building's image took up to 512² texels, and the 640 x 360 tour's `impostors`
/// stage (clouds and city) summed 5.6 s against 3.9 s at 256 (one pair of runs on a loaded machine, the same
/// 320 rebuilds), with the city at 45.3 / 26.8 dB against 44.8 / 26.8 (640 x 360) and
/// 37.1 / 29.7 against 34.3 / 29.7 (1280 x 720): above its goals either way.
const CITY_MAX_SIDE: u32 = 256;
/// Texels per screen pixel of the city's images, at least ([`ImpostorSet::density`]). At
/// 2 the tour's worst frame at 640x360 was 24.9 dB (a two-pixel sliver of a building
/// between two others, its lit windows resampled), at 3 26.8 (mean 41.9 to 45.3 dB); 4
/// gained nothing more (BENCHMARKS.md, session 12).
const CITY_DENSITY: f32 = 3.0;

/// Frames of the eye's present motion a city image the planner does not draw must stay
/// within its budget after a rebuild for the rebuild to be offered
/// ([`ImpostorSet::rebuild_life`]). Without it the moving camera's 640x360 tour rebuilt
/// 320 images (229 of them buildings drawn as geometry turned into images the next frame
/// would leave, the rest those images refreshed), mostly 256² captures for 64-pixel
/// discs; with 4, 148 rebuilds, the city at 44.7 / 33.0 dB against 44.8 / 26.8
/// (BENCHMARKS.md, session 14). Images in use are refreshed as before.
const CITY_REBUILD_LIFE: f32 = 4.0;

/// The city's impostors, drawn as cutouts ([`ImpostorSet::cutout`]) at [`CITY_CUTOUT`], each
/// on its relief ([`ImpostorSet::relief`]): drawn on a quad at its building's nearest
/// corner, an image covered the geometry of the buildings between that corner and its far
/// walls, the tour's worst frames (a sliver of a building peeking between two drawn as
/// geometry).
fn city_impostors(config: Config, n: usize) -> ImpostorSet {
    let mut set = ImpostorSet::new(config, n);
    set.cutout = Some(CITY_CUTOUT);
    set.shape = Shape::Box;
    set.rebuild_life = Some(CITY_REBUILD_LIFE);
    set.density = CITY_DENSITY;
    set
}

/// The coverage from which a city impostor's pixel is drawn (opaque): a pixel the
/// geometry covers by its centre. Blended, the bilinear image's half-texel fringe round
/// every building covered pixels the geometry leaves empty (the tour measured 23.9 dB
/// mean over the image-drawn buildings blended, 24.5 as cutouts, at 640x360).
const CITY_CUTOUT: f32 = 0.5;

/// Whether the XZ point `(x, z)` is in the city district or within `margin` of it.
pub fn in_city(x: f32, z: f32, margin: f32) -> bool {
    let half = CITY_GRID as f32 * CITY_SPACING * 0.5 + margin;
    (x - CITY_CENTER.x).abs() <= half && (z - CITY_CENTER.y).abs() <= half
}

/// The city planner's representations, in its order (their indices: [`GEOMETRY`],
/// [`IMPOSTORS`], [`LAYERS`]).
pub const CITY_REPRESENTATIONS: [&str; 3] = ["geometry", "impostors", "layers"];
pub const GEOMETRY: usize = 0;
pub const IMPOSTORS: usize = 1;
pub const LAYERS: usize = 2;

/// The clouds and their impostors, and the buildings' planner.
#[derive(Debug)]
pub struct Impostors {
    pub clouds: CloudField,
    /// One impostor per cloud of `clouds.clouds`, same order.
    pub cloud_set: ImpostorSet,
    /// The buildings (`city.objects`), each drawn as one of [`CITY_REPRESENTATIONS`].
    pub city: Planner<MeshGroup>,
    last: Readout,
    run: RunStats,
    /// Frames rendered at loading: the refresh budgets lifted ([`Impostors::set_loading`]).
    loading: bool,
    /// Screens of particles the last frame drew at reduced resolution (0: none).
    pub low_res_fill: f32,
}

impl Impostors {
    /// Builds the sky and the city on `terrain`, the clouds lit by `lighting`'s sun.
    pub fn new(terrain: &Terrain, lighting: &Lighting) -> Self {
        let mut clouds = CloudField::scatter(
            Vec2::splat(-CLOUD_AREA),
            Vec2::splat(CLOUD_AREA),
            CLOUD_BASE,
            CLOUD_COUNT,
            CLOUD_PARTICLES,
            2718,
        );
        if let Some((dir, color)) = lighting.sun() {
            clouds.relight(dir, color);
        }
        let config = |refreshes: usize, max_side: u32| Config {
            budget: Budget::count(refreshes),
            max_side,
            // Tolerance in image units: staleness may add a predicted mean absolute error of
            // 1.5 levels over the subject (the calibrated prediction, `bench impostors`).
            tolerance: Tolerance {
                levels: Some(TOLERANCE_LEVELS),
                ..Tolerance::default()
            },
            // The showcase shows no image over its tolerance: a subject the budget could
            // not refresh is drawn as its (cheap) geometry until it can be.
            fallback_ratio: 1.0,
            ..Config::default()
        };
        let buildings = buildings(terrain);
        let n = buildings.len();
        let reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
            Box::new(Geometry),
            Box::new(city_impostors(config(CITY_CAP, CITY_MAX_SIDE), n)),
            Box::new(LayerSet::new(
                layers::Config {
                    budget: Budget::count(CITY_CAP),
                    ..layers::Config::default()
                },
                n,
            )),
        ];
        let city = plan::Config {
            budgets: Budgets {
                error: CITY_ERROR_LEVELS,
                rebuilds: CITY_BUDGET,
                ..Budgets::default()
            },
            ..plan::Config::default()
        };
        // The clouds' images are judged by their parallax in pixels (module docs): their
        // blended puffs write no depth, so the level prediction sees no depth spread and
        // predicted 0 for images taken radii away (measured 6.8 dB against the particles).
        let cloud_config = Config {
            tolerance: Tolerance {
                pixels: Some(CLOUD_TOLERANCE_PX),
                ..Tolerance::default()
            },
            ..config(CLOUD_BUDGET, CLOUD_MAX_SIDE)
        };
        let mut cloud_set = ImpostorSet::new(cloud_config, clouds.clouds.len());
        cloud_set.texel_budget = Some(CLOUD_TEXELS);
        cloud_set.side_step = Some(CLOUD_SIDE_STEP);
        Impostors {
            cloud_set,
            city: Planner::new(city, buildings, reps),
            clouds,
            last: Readout::default(),
            run: RunStats::default(),
            loading: false,
            low_res_fill: 0.0,
        }
    }

    /// Predicts every cloud impostor's error for the view and refreshes the worst within
    /// the budget, and plans the city (each building's representation, its rebuilds).
    /// Counts the frame in [`Impostors::run_stats`].
    pub fn update(&mut self, view: &FrameView<'_>) -> Readout {
        let (camera, lighting) = (view.camera, view.lighting);
        if let Some((dir, color)) = lighting.sun() {
            // Reruns the light pass only if the sun moved.
            self.clouds.relight(dir, color);
        }
        // The parallax tolerance is for a 360-line image: the same angle, as many pixels
        // more as the image is taller.
        let lines = (view.height as f32 / CLOUD_TOLERANCE_LINES).max(1.0);
        self.cloud_set.config.tolerance.pixels = Some(CLOUD_TOLERANCE_PX * lines);
        let clouds = self
            .cloud_set
            .update(&mut self.clouds.clouds, camera, view.height, lighting);
        self.low_res_clouds(view);
        if !self.loading {
            self.city.config.budgets.rebuilds = city_rebuilds(clouds.capture_texels);
        }
        self.city.plan(view);
        self.last = Readout {
            clouds,
            city: CityReport::of(&self.city),
        };
        self.run.add(&self.last);
        self.last
    }

    /// Draws the clouds' particles at the renderer's reduced resolution this frame when
    /// those drawn as particles fill [`CLOUD_LOW_RES_FILL`] screens and
    /// [`CLOUD_LOW_RES_PIXELS`] pixels or more.
    fn low_res_clouds(&mut self, view: &FrameView<'_>) {
        let imps = &self.cloud_set.impostors;
        let particles = |i: usize| {
            imps.get(i)
                .is_some_and(|m| matches!(m.mode, Mode::Geometry(_)))
        };
        let clouds = &mut self.clouds.clouds;
        let fill: f32 = (0..clouds.len())
            .filter(|&i| particles(i))
            .map(|i| clouds[i].fill())
            .sum();
        let screen = view.width as f32 * view.height as f32;
        let on = fill >= (CLOUD_LOW_RES_FILL * screen).max(CLOUD_LOW_RES_PIXELS);
        for (i, c) in clouds.iter_mut().enumerate() {
            c.set_low_res(on && particles(i));
        }
        self.low_res_fill = if on { fill / screen.max(1.0) } else { 0.0 };
    }

    /// Appends this frame's draws (after [`Impostors::update`]): each building by its
    /// representation (an impostor's quad pulled to its building's nearest box corner),
    /// cloud images as blended quads and the rest as their particles.
    pub fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.city.draws(out);
        self.cloud_set.draws(&self.clouds.clouds, out);
    }

    /// Starts [`Impostors::run_stats`] afresh (after the frames prepared at loading).
    pub fn restart_run_stats(&mut self) {
        self.run = RunStats::default();
    }

    /// Lifts the per-frame refresh budgets (the clouds' count and texels, the city's
    /// rebuilds) for frames rendered at loading, which are not shown, or puts them back
    /// (a time budget, [`Impostors::set_time_budget`], is kept either way).
    pub fn set_loading(&mut self, loading: bool) {
        let (clouds, texels, city) = match loading {
            true => (self.clouds.clouds.len(), None, self.city.objects.len()),
            false => (CLOUD_BUDGET, Some(CLOUD_TEXELS), CITY_BUDGET),
        };
        self.cloud_set.config.budget.refreshes = clouds;
        self.cloud_set.texel_budget = texels;
        self.city.config.budgets.rebuilds = city;
        self.loading = loading;
    }

    /// Gives the clouds a time budget for their refreshes each frame, and the city's planner
    /// the same in predicted milliseconds of rebuilds (`None`: counts only).
    pub fn set_time_budget(&mut self, time: Option<std::time::Duration>) {
        self.cloud_set.config.budget.time = time;
        self.city.config.budgets.rebuild_ms = time.map(|t| t.as_secs_f32() * 1e3);
    }

    /// The debug view: cloud images tinted by their predicted error, buildings coloured by
    /// their representation ([`Impostors::legend`]).
    pub fn set_debug(&mut self, on: bool) {
        self.cloud_set.debug_tint = on;
        self.city.set_tints(on);
    }

    pub fn debug(&self) -> bool {
        self.cloud_set.debug_tint
    }

    /// The last update's reports.
    pub fn readout(&self) -> Readout {
        self.last
    }

    /// Totals over every update so far.
    pub fn run_stats(&self) -> &RunStats {
        &self.run
    }

    /// The index of the cloud the headless path flies through: the one nearest the
    /// district (so the path climbs into it after passing over the city).
    pub fn path_cloud_index(&self) -> Option<usize> {
        let near = |s: Sphere| Vec2::new(s.center.x, s.center.z).distance(CITY_CENTER);
        let clouds = self.clouds.clouds.iter().map(|c| near(c.bounds()));
        clouds
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }

    /// The bounding sphere of that cloud.
    pub fn path_cloud(&self) -> Sphere {
        match self.path_cloud_index() {
            Some(i) => self.clouds.clouds[i].bounds(),
            None => Sphere {
                center: Vec3::new(CITY_CENTER.x, CLOUD_BASE + 2.0, CITY_CENTER.y),
                radius: 1.0,
            },
        }
    }

    /// Triangles of the clouds and buildings drawn as geometry.
    pub fn triangle_count(&self) -> usize {
        let clouds = self.clouds.clouds.iter().map(Subject::triangle_count);
        let city = self.city.objects.iter().map(Subject::triangle_count);
        clouds.chain(city).sum()
    }

    /// The debug view's colours of the city's representations, for the readout:
    /// `geometry=white impostors=green layers=blue` ([`plan::TINTS`]).
    pub fn legend(&self) -> String {
        let names = self.city.names().into_iter().enumerate();
        let pairs: Vec<String> = names
            .map(|(r, name)| format!("{name}={}", plan::tint(r).0))
            .collect();
        pairs.join(" ")
    }
}

/// The district: a grid of box buildings, taller toward the middle, each standing on the
/// lowest ground under its footprint (sunk a little further, so no gap shows on a slope).
fn buildings(terrain: &Terrain) -> Vec<MeshGroup> {
    let mut rng = XorShift::new(1789);
    let material = Arc::new(Material {
        shading: Shading::Lit {
            specular: 0.1,
            shininess: 16.0,
        },
        ..Material::default()
    });
    let half = CITY_GRID as f32 * CITY_SPACING * 0.5;
    let mut out = Vec::new();
    for gz in 0..CITY_GRID {
        for gx in 0..CITY_GRID {
            let (w, d) = (rng.range(2.6, 4.2), rng.range(2.6, 4.2));
            let x = CITY_CENTER.x + (gx as f32 + 0.5) * CITY_SPACING - half;
            let z = CITY_CENTER.y + (gz as f32 + 0.5) * CITY_SPACING - half;
            let centrality = 1.0 - Vec2::new(x, z).distance(CITY_CENTER) / (half * 1.42);
            let h = rng.range(3.5, 7.0) + 9.0 * centrality.max(0.0) * rng.range(0.5, 1.0);
            let mut ground = f32::INFINITY;
            for (sx, sz) in [
                (-1.0, -1.0),
                (1.0, -1.0),
                (-1.0, 1.0),
                (1.0, 1.0),
                (0.0, 0.0),
            ] {
                let (px, pz) = (x + sx * w * 0.5, z + sz * d * 0.5);
                let top = terrain.height_at(px, pz);
                ground = ground.min(top);
            }
            let sink = 0.3;
            let wall = Rgba::new(
                rng.range(0.3, 0.7),
                rng.range(0.25, 0.55),
                rng.range(0.2, 0.45),
                1.0,
            );
            let mesh = Arc::new(city::building(Vec3::new(w, h + sink, d), CITY_DETAIL, wall));
            let at = Mat4::from_translation(Vec3::new(x, ground - sink, z));
            out.push(MeshGroup::new().with(mesh, material.clone(), at));
        }
    }
    out
}

/// The impostors' tolerance: predicted mean absolute 8-bit error over the subject.
pub const TOLERANCE_LEVELS: f32 = 1.5;

/// The clouds' tolerance instead: the parallax between the near and far ends of a cloud's
/// bounding sphere, screen pixels.
pub const CLOUD_TOLERANCE_PX: f32 = 1.0;

/// The image height [`CLOUD_TOLERANCE_PX`] is for: taller images scale it, so the
/// tolerance is the same angle at any size (a cloud's soft features span as many more
/// pixels, so the same angle of parallax makes about the same error in levels).
pub const CLOUD_TOLERANCE_LINES: f32 = 360.0;

/// The city planner's error budget: predicted mean absolute 8-bit error over a building,
/// all of it (the impostors' tolerance is what staleness adds to a fresh image's own
/// error). Twice the tolerance: the error a building's impostor showed before the planner
/// (a fresh image's resampling makes about as much as the staleness allowed on top). At the
/// tolerance itself no fresh image of a building is predicted within the hysteresis band
/// (1.4 to 1.8 levels against 1.125), so the planner would draw the city as geometry only.
pub const CITY_ERROR_LEVELS: f32 = 2.0 * TOLERANCE_LEVELS;

#[cfg(test)]
mod tests;
