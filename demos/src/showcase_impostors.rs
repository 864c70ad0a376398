//! The showcase's impostored layer: a sky of cumulus clouds over the billboard forest and a
//! small city district on the hills, every cloud and every building drawn through a runtime
//! impostor ([`ibr::impostor`]) re-rendered only when its predicted error reaches the
//! tolerance (0.125 degrees of parallax, or an octave of resolution), within a per-frame
//! budget, largest error first.
//!
//! - The sky: a [`CloudField`] of [`CLOUD_COUNT`] cumulus clouds of [`CLOUD_PARTICLES`]
//!   particles, their flat bases at [`CLOUD_BASE`] (the camera path climbs into one), lit
//!   by the scene's sun. A cloud is its impostor image from afar; within 1.25 radii of its
//!   centre the image is refreshed every frame, and with the eye inside its bounding sphere
//!   it is drawn as its particles, so flying into it does not pop.
//! - The city: [`CITY_GRID`]² box buildings ([`crate::city::building`], faces split
//!   [`CITY_DETAIL`]² with a vertex-coloured window pattern, lit) around [`CITY_CENTER`], on
//!   a fairly flat stretch of the hills west of the plaza, their foundations sunk below the
//!   lowest ground under them. Trees and rocks keep out of the district ([`in_city`]).
//!
//! Both sets are updated every frame before the draw list is built; their images are
//! blended quads, sorted back to front with the scene's other blended draws. The
//! [`Readout`] of a frame and the [`RunStats`] of a run feed the showcase's on-screen line
//! and its headless statistics; [`Impostors::set_debug`] colours each image by its
//! predicted error (green 0, yellow at the tolerance, red at twice it).

mod chart;

pub use chart::tour_chart;

use crate::city;
use engine::procedural::{Terrain, XorShift};
use engine::{Camera, Draw, Lighting, Material, Rgba, Shading, Sphere};
use glam::{Mat4, Vec2, Vec3};
use ibr::cloud::CloudField;
use ibr::impostor::{Budget, Config, ImpostorSet, Mode, Report, Tolerance};
use ibr::subject::{MeshGroup, Subject};
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
/// Refreshes a frame may do, per set (8 in all). A cloud's capture (200 blended puffs
/// over up to 256² texels) costs about four times a building's (measured 4.4 against
/// 1.1 ms on a loaded core), and near a cloud the every-frame refreshes come first.
const CLOUD_BUDGET: usize = 2;
const CITY_BUDGET: usize = 6;
/// Largest impostor texture sides. Near a cloud its image spans a wide field of view
/// (up to 180 degrees at the switch to particles), so its centre gets few texels: at 128
/// the switch pops (the no-pop test measures a frame difference 2.5 times the typical),
/// at 256 it does not.
const CLOUD_MAX_SIDE: u32 = 256;
const CITY_MAX_SIDE: u32 = 256;

/// Whether the XZ point `(x, z)` is in the city district or within `margin` of it.
pub fn in_city(x: f32, z: f32, margin: f32) -> bool {
    let half = CITY_GRID as f32 * CITY_SPACING * 0.5 + margin;
    (x - CITY_CENTER.x).abs() <= half && (z - CITY_CENTER.y).abs() <= half
}

/// The clouds, the buildings and their impostors.
#[derive(Debug)]
pub struct Impostors {
    pub clouds: CloudField,
    /// One impostor per cloud of `clouds.clouds`, same order.
    pub cloud_set: ImpostorSet,
    pub buildings: Vec<MeshGroup>,
    /// One impostor per building, same order.
    pub city_set: ImpostorSet,
    /// Per building: the half extents of its footprint (see [`Impostors::draws`]).
    footprints: Vec<Vec2>,
    /// The eye of the last update.
    eye: Vec3,
    last: Readout,
    run: RunStats,
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
        let buildings = buildings(terrain);
        let footprints = buildings
            .iter()
            .map(|b| {
                let m = &b.parts[0].mesh;
                let lo = m.positions.iter().fold(Vec3::INFINITY, |a, &p| a.min(p));
                let hi = m
                    .positions
                    .iter()
                    .fold(Vec3::NEG_INFINITY, |a, &p| a.max(p));
                0.5 * Vec2::new(hi.x - lo.x, hi.z - lo.z)
            })
            .collect();
        let config = |refreshes: usize, max_side: u32| Config {
            budget: Budget {
                refreshes,
                time: None,
            },
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
        Impostors {
            cloud_set: ImpostorSet::new(config(CLOUD_BUDGET, CLOUD_MAX_SIDE), clouds.clouds.len()),
            city_set: ImpostorSet::new(config(CITY_BUDGET, CITY_MAX_SIDE), buildings.len()),
            clouds,
            buildings,
            footprints,
            eye: Vec3::ZERO,
            last: Readout::default(),
            run: RunStats::default(),
        }
    }

    /// Predicts every impostor's error for `camera` (an image `height` pixels tall),
    /// refreshes the worst within each set's budget and decides how each cloud and
    /// building is drawn this frame. Counts the frame in [`Impostors::run_stats`].
    pub fn update(&mut self, camera: &Camera, height: u32, lighting: &Lighting) -> Readout {
        if let Some((dir, color)) = lighting.sun() {
            // Reruns the light pass only if the sun moved.
            self.clouds.relight(dir, color);
        }
        let clouds = self
            .cloud_set
            .update(&mut self.clouds.clouds, camera, height, lighting);
        let city = self
            .city_set
            .update(&mut self.buildings, camera, height, lighting);
        self.eye = camera.eye();
        self.last = Readout { clouds, city };
        self.run.add(&self.last);
        self.last
    }

    /// Appends this frame's draws (after [`Impostors::update`]): images as blended quads,
    /// the rest as clouds' particles and buildings' meshes.
    ///
    /// A building's image quad stands through its centre, so from low down the ground
    /// between its front walls and the quad would hide the bottom of the image. Each
    /// building's quad is therefore scaled about the eye (the same pixels, only nearer in
    /// depth) to the depth of the footprint's nearest corner: the image is never hidden by
    /// ground in front of its walls, and the foundations it shows below the ground line
    /// are only the little they are sunk.
    pub fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        let buildings = self.buildings.iter().zip(&self.footprints).enumerate();
        for (i, (b, &half)) in buildings {
            match self.city_set.impostors[i].mode {
                Mode::Culled => {}
                Mode::Geometry(_) => b.draws(out),
                Mode::Image => {
                    if let Some(mut d) = self.city_set.image_draw(i) {
                        let to = b.bounds().center - self.eye;
                        let dist = to.length().max(1e-3);
                        let dir = to / dist;
                        let pull = half.x * dir.x.abs() + half.y * dir.z.abs();
                        let s = ((dist - pull) / dist).clamp(0.05, 1.0);
                        d.transform = Mat4::from_translation(self.eye)
                            * Mat4::from_scale(Vec3::splat(s))
                            * Mat4::from_translation(-self.eye);
                        out.push(d);
                    }
                }
            }
        }
        self.cloud_set.draws(&self.clouds.clouds, out);
    }

    /// Gives both sets a time budget for their refreshes each frame (`None`: counts only).
    pub fn set_time_budget(&mut self, time: Option<std::time::Duration>) {
        self.cloud_set.config.budget.time = time;
        self.city_set.config.budget.time = time;
    }

    /// The debug view: impostor images tinted by their predicted error.
    pub fn set_debug(&mut self, on: bool) {
        self.cloud_set.debug_tint = on;
        self.city_set.debug_tint = on;
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
        let city = self.buildings.iter().map(Subject::triangle_count);
        clouds.chain(city).sum()
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

/// What one frame's impostor updates did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Readout {
    pub clouds: Report,
    pub city: Report,
}

impl Readout {
    pub fn refreshes(&self) -> usize {
        self.clouds.refreshes + self.city.refreshes
    }
    pub fn images(&self) -> usize {
        self.clouds.images + self.city.images
    }
    pub fn geometry(&self) -> usize {
        self.clouds.geometry + self.city.geometry
    }
    pub fn culled(&self) -> usize {
        self.clouds.culled + self.city.culled
    }
    /// Invalid impostors left stale (over budget).
    pub fn stale(&self) -> usize {
        self.clouds.stale + self.city.stale
    }
    /// Images drawn with a predicted error over their tolerance.
    pub fn over_tolerance(&self) -> usize {
        self.clouds.over_tolerance + self.city.over_tolerance
    }
    /// Subjects drawn as geometry because their image was too stale to show.
    pub fn stale_fallbacks(&self) -> usize {
        self.clouds.stale_fallbacks + self.city.stale_fallbacks
    }
    /// Refreshes of subjects about to come into view.
    pub fn prewarmed(&self) -> usize {
        self.clouds.prewarmed + self.city.prewarmed
    }
    /// Largest predicted error ratio over the drawn images (1 is the tolerance).
    pub fn max_ratio(&self) -> f32 {
        self.clouds.max_ratio.max(self.city.max_ratio)
    }
    /// Mean predicted error ratio over the drawn images.
    pub fn mean_ratio(&self) -> f32 {
        let (a, b) = (&self.clouds, &self.city);
        let n = a.images + b.images;
        if n == 0 {
            0.0
        } else {
            (a.mean_ratio * a.images as f32 + b.mean_ratio * b.images as f32) / n as f32
        }
    }

    /// The on-screen line (upper case, for the bitmap font).
    pub fn line(&self) -> String {
        format!(
            "IMPOSTORS {}  IMG {}  GEO {}  REFRESH {}  STALE {}  ERR MAX {:.2} MEAN {:.2}",
            self.images() + self.geometry(),
            self.images(),
            self.geometry(),
            self.refreshes(),
            self.stale(),
            self.max_ratio(),
            self.mean_ratio()
        )
        .to_uppercase()
    }
}

/// The impostors' tolerance: predicted mean absolute 8-bit error over the subject.
pub const TOLERANCE_LEVELS: f32 = 1.5;

/// Frames whose per-frame figures [`RunStats::per_frame`] keeps (the first ones).
pub const HISTORY: usize = 1 << 14;

/// Impostor statistics over a run of frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RunStats {
    pub frames: usize,
    pub refreshes: usize,
    /// Most refreshes in one frame.
    pub peak_refreshes: usize,
    /// Invalid impostors left stale, summed over the frames.
    pub stale: usize,
    /// Largest predicted error ratio of a drawn image over the run.
    pub max_ratio: f32,
    /// Frames that showed an image over its tolerance, and over twice it.
    pub frames_over: usize,
    pub frames_over_twice: usize,
    /// Stale images replaced by geometry, summed over the frames; pre-warming refreshes.
    pub stale_fallbacks: usize,
    pub prewarmed: usize,
    /// Per frame (the first [`HISTORY`]): the largest predicted error ratio shown, and the
    /// refreshes.
    pub per_frame: Vec<(f32, usize)>,
    /// Sum over the frames of the mean predicted ratio, and the frames with images.
    ratio_sum: f64,
    ratio_frames: usize,
}

impl RunStats {
    fn add(&mut self, r: &Readout) {
        self.frames += 1;
        self.refreshes += r.refreshes();
        self.peak_refreshes = self.peak_refreshes.max(r.refreshes());
        self.stale += r.stale();
        self.max_ratio = self.max_ratio.max(r.max_ratio());
        self.frames_over += (r.max_ratio() > 1.0) as usize;
        self.frames_over_twice += (r.max_ratio() > 2.0) as usize;
        self.stale_fallbacks += r.stale_fallbacks();
        self.prewarmed += r.prewarmed();
        if self.per_frame.len() < HISTORY {
            // Reserved once, so recording never reallocates mid-run.
            self.per_frame.reserve_exact(HISTORY - self.per_frame.len());
            self.per_frame.push((r.max_ratio(), r.refreshes()));
        }
        if r.images() > 0 {
            self.ratio_sum += r.mean_ratio() as f64;
            self.ratio_frames += 1;
        }
    }

    pub fn mean_refreshes(&self) -> f64 {
        self.refreshes as f64 / self.frames.max(1) as f64
    }

    /// The mean over the frames (with images) of the mean predicted error ratio.
    pub fn mean_ratio(&self) -> f64 {
        self.ratio_sum / self.ratio_frames.max(1) as f64
    }
}

#[cfg(test)]
mod tests;
