//! The `bench budget` sweep: the planner ([`ibr::plan`]) against each single representation
//! used everywhere, on the same frames of three scenes: the showcase's city district
//! along the showcase's own path (its buildings planned, the rest of its scene as
//! geometry), the procedural [`City`] of the impostor benchmarks (16 buildings, sliding
//! sideways) and a large [`World`] (tens of thousands of objects, over ten million
//! triangles, flown over).
//!
//! Methods: `geometry` (every object's triangles, frustum-culled by the planner),
//! `impostors` (runtime impostors with their own policy: refresh past a tolerance in
//! levels, geometry for stale images), `layers` (image layers with theirs: re-render past a
//! geometric error in pixels, the `budget` column's unit for these rows only), each other
//! representation alone (`octahedral`, `depth images`, `LDIs`, `billboards`, `light
//! fields`: wherever its predicted error is within the budget, geometry elsewhere,
//! [`ALONE`]), `planner` (any of the eight [`REPRESENTATIONS`] per object, chosen by
//! predicted error and cost within [`MEMORY`], every object within the budget) and
//! `planner-frame` (the same, with the budget on the frame's error with a margin for its
//! spread, [`Scope::Frame`]). All but layers are swept over the same error budgets in
//! levels, layers over as many thresholds, all with the same rebuild budget per frame (a
//! sixteenth of the objects, at least [`Settings::rebuilds`]). Each run first holds still for
//! [`Settings::warmup`] frames at its first view (images are taken as a game loading a level
//! would); then every frame is timed (the frame loop's `prepare`, rebuilds included, and the
//! render) and measured against a render of all the geometry from the same eye:
//! - per visible object, the mean absolute 8-bit error over its screen rectangle (the unit
//!   the budget is in), from a summed-area table of the frame's error;
//! - the frame's error: the mean over the pixels the visible objects' rectangles cover,
//!   each pixel once (`measured_mean` is its mean over frames, `measured_p99` its 99th
//!   percentile, `within` the fraction of frames at or under the budget), and
//!   `objects_over`, the fraction of visible objects over the budget;
//! - PSNR over the whole frame.
//!
//! Per frame the planner also reports its predicted error (the frame's, its 99% bound,
//! and the largest object's), the objects drawn each way, switches and rebuilds, and the memory images hold.

mod calibrate;
mod flight;
mod objects;
mod report;
mod trace;

pub use crate::world::{World, TREE_REBUILD_MS, TREE_SIDE};
pub use calibrate::{calibrate, Calibration};
pub use objects::{objects, ObjectRow};
pub use report::{
    charts, BudgetCommand, BudgetFlags, BudgetSweep, CalibrateSweep, ObjectsSweep, TraceSweep,
};
pub use trace::{trace, TraceRow};

use flight::{fly, fly_with};

use crate::bench::impostors::frame_camera;
use crate::bench::sweep::{self, CsvRow};
use crate::city::{City, Path as CityPath};
use crate::showcase::{self, Showcase};
use crate::timing::Summary;
use engine::{Camera, Lighting, Material, Mesh};
use ibr::impostor::{self, ImpostorSet, Impostored};
use ibr::layers::{self, LayerSet, Layered};
use ibr::plan::tree::Hierarchy;
use ibr::plan::{self, Budgets, Geometry, Planner, Representation, Scope};
use ibr::schedule::Budget;
use ibr::subject::MeshGroup;
use std::sync::{Arc, LazyLock};

/// What a sweep measures.
#[derive(Clone, Debug)]
pub struct Settings {
    pub size: (u32, u32),
    /// Error budgets, levels.
    pub budgets: Vec<f32>,
    /// Larger budgets for the frame scope alone (its frame model errs high in crowds, so
    /// its measured error reaches the single techniques' only there).
    pub frame_budgets: Vec<f32>,
    /// Fewest rebuilds per frame (image refreshes) for every method; a sixteenth of the
    /// objects when that is more.
    pub rebuilds: usize,
    /// Layers' thresholds, pixels.
    pub layer_px: Vec<f32>,
    /// Frames held at the first view before measuring (enough for every object's first
    /// image at the rebuild budget, and a retry), and frames measured.
    pub warmup: usize,
    pub frames: usize,
    /// The city's grid and detail; the world's lots per side (0: no world).
    pub city: (u32, u32),
    pub world: u32,
    /// The showcase's city district along the showcase's own path.
    pub showcase: bool,
    /// Only the scene of this name (`showcase`, `city`, `world`; `None`: all).
    pub only: Option<String>,
    /// Only the methods of these names (the CSV's `method` column; empty: all).
    pub methods: Vec<String>,
    /// The planners' [`plan::Config::spread`] (`None`: the default, [`plan::SPREAD`]).
    pub spread: Option<f32>,
    /// Print each measured frame's stage times and work counters to stderr (one line a
    /// frame, starting `stages`): where a world frame's time goes.
    pub stages: bool,
}

impl Settings {
    /// 640 x 360; the city (16 buildings of 12,000 triangles) and a 150 x 150 world.
    pub fn full() -> Settings {
        Settings {
            size: (640, 360),
            budgets: vec![1.0, 2.0, 4.0, 8.0, 16.0],
            frame_budgets: vec![32.0, 64.0, 128.0, 256.0],
            rebuilds: 16,
            layer_px: vec![0.5, 1.0, 2.0, 4.0, 8.0],
            warmup: 20,
            frames: 24,
            city: (4, 10),
            world: 150,
            showcase: true,
            only: None,
            methods: Vec::new(),
            spread: None,
            stages: false,
        }
    }

    /// Every point, fewer frames.
    pub fn quick() -> Settings {
        Settings {
            frames: 8,
            ..Settings::full()
        }
    }

    /// A seconds-long smoke run (tests).
    pub fn tiny() -> Settings {
        Settings {
            size: (160, 96),
            budgets: vec![4.0],
            frame_budgets: vec![16.0],
            rebuilds: 16,
            layer_px: vec![2.0],
            warmup: 2,
            frames: 3,
            city: (2, 2),
            world: 8,
            showcase: false,
            only: None,
            methods: Vec::new(),
            spread: None,
            stages: false,
        }
    }
}

/// One run.
#[derive(Clone, Debug)]
pub struct Row {
    pub scene: &'static str,
    /// `geometry`, `impostors`, `layers`, `planner` (the error budget per object),
    /// `planner-frame` (over the frame, [`Scope::Frame`]) or a representation run alone
    /// ([`ALONE`]).
    pub method: &'static str,
    /// Levels (pixels for layers, 0 for geometry).
    pub budget: f32,
    pub objects: usize,
    pub triangles: usize,
    pub width: u32,
    pub height: u32,
    pub time: Summary,
    pub measured_mean: f64,
    pub measured_p99: f64,
    pub within: f64,
    pub objects_over: f64,
    pub psnr_db: f64,
    pub predicted_mean: f64,
    pub predicted_max: f64,
    /// The planner's bound on the frame's error (mean over frames), and the spread that
    /// would have made it hold on 99% of frames ([`flight::spread_fit`]).
    pub predicted_bound: f64,
    pub spread_fit: f64,
    pub geometry_per_frame: f64,
    pub images_per_frame: f64,
    /// The planners' objects per frame by representation ([`REPRESENTATIONS`]), e.g.
    /// `geometry 8.9 impostors 3.0 layers 4.1 octahedral 0.0` (empty for other methods).
    pub mix: String,
    pub switches_per_frame: f64,
    pub rebuilds_per_frame: f64,
    pub memory_mb: f64,
    /// The planner's own time a frame (predicting and choosing; captures left out),
    /// milliseconds: mean, 99th percentile and largest over the frames,
    pub planning_ms: f64,
    pub planning_p99_ms: f64,
    pub planning_max_ms: f64,
    /// and the fraction of frames planned within [`PLANNING_MS`].
    pub planning_within: f64,
    /// The reference frames' pixels (all the geometry) the visible objects' screen
    /// rectangles cover, and those nothing covers (sky), fractions of the frame (means
    /// over the frames; 0 in older files).
    pub covered: f64,
    pub sky: f64,
}

/// The planner's own time a frame the world's goal allows, milliseconds (issue 41).
pub const PLANNING_MS: f64 = 2.0;

impl CsvRow for Row {
    const HEADER: &'static str = "scene,method,budget,objects,triangles,width,height,frames,median_ms,mean_ms,measured_mean,measured_p99,within,objects_over,psnr_db,predicted_mean,predicted_max,predicted_bound,spread_fit,geometry_per_frame,images_per_frame,mix,switches_per_frame,rebuilds_per_frame,memory_mb,planning_ms,planning_p99_ms,planning_max_ms,planning_within,covered,sky";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{:.3},{:.3},{:.4},{:.4},{:.4},{:.5},{:.3},{:.4},{:.4},{:.4},{:.4},{:.1},{:.1},{},{:.2},{:.2},{:.2},{:.3},{:.3},{:.3},{:.4},{:.4},{:.4}",
            self.scene,
            self.method,
            self.budget,
            self.objects,
            self.triangles,
            self.width,
            self.height,
            self.time.frames,
            self.time.median_ms,
            self.time.mean_ms,
            self.measured_mean,
            self.measured_p99,
            self.within,
            self.objects_over,
            self.psnr_db,
            self.predicted_mean,
            self.predicted_max,
            self.predicted_bound,
            self.spread_fit,
            self.geometry_per_frame,
            self.images_per_frame,
            self.mix,
            self.switches_per_frame,
            self.rebuilds_per_frame,
            self.memory_mb,
            self.planning_ms,
            self.planning_p99_ms,
            self.planning_max_ms,
            self.planning_within,
            self.covered,
            self.sky,
        )
    }
}

/// Frame `f` of `n`'s camera for a target of the given size.
type Frames = Box<dyn Fn(usize, usize, (u32, u32)) -> Camera>;

/// A scene to plan over: its objects, the rest as plain geometry, the light and the frames.
struct Scene {
    name: &'static str,
    objects: Vec<MeshGroup>,
    ground: MeshGroup,
    lighting: Lighting,
    camera: Frames,
}

fn scenes(settings: &Settings) -> Vec<Scene> {
    let city = City::new(settings.city.0, settings.city.1, 7);
    let mut out = Vec::new();
    if settings.showcase {
        out.push(showcase_scene());
    }
    out.push(Scene {
        name: "city",
        objects: city.buildings.clone(),
        ground: city.ground.clone(),
        lighting: city.lighting.clone(),
        camera: Box::new(move |f, n, size| {
            frame_camera(&city, CityPath::Translate, 0.25, f, n, size)
        }),
    });
    if settings.world > 0 {
        out.push(world_scene(settings.world));
    }
    out.retain(|s| settings.only.as_deref().is_none_or(|o| o == s.name));
    out
}

/// The world of `side` x `side` lots and its fly-over.
fn world_scene(side: u32) -> Scene {
    world_scene_flown(World::new(side, 11), |w, f, n, size| {
        w.camera(f as f32 / n.max(2) as f32 * 0.25, size)
    })
}

/// `world` flown by `camera` (the world, frame, frames, size).
fn world_scene_flown(world: World, camera: WorldFlight) -> Scene {
    let (objects, ground, lighting) = (
        world.objects.clone(),
        world.ground.clone(),
        world.lighting.clone(),
    );
    Scene {
        name: "world",
        objects,
        ground,
        lighting,
        camera: Box::new(move |f, n, size| camera(&world, f, n, size)),
    }
}

/// A flight over a [`World`]: its camera at frame `f` of `n` for a target of `size`.
pub type WorldFlight = fn(&World, usize, usize, (u32, u32)) -> Camera;

/// `bench objects`: per number of objects in `counts` (`world` of the nearest square
/// number of lots a side, the same mix of objects, so the same triangles per object on
/// average), the geometry (up to `geometry_up_to` objects) and the per-node planner at
/// each of `settings.budgets`, flown by `flight` and measured as the budget sweep's runs.
pub fn by_count(
    settings: &Settings,
    (counts, geometry_up_to): (&[usize], usize),
    (world, flight): (fn(u32) -> World, WorldFlight),
    progress: &mut dyn FnMut(usize, usize, &str),
) -> Vec<Row> {
    let runs = counts
        .iter()
        .map(|&n| usize::from(n <= geometry_up_to) + settings.budgets.len())
        .sum();
    let mut tick = sweep::ticker(runs, progress);
    let mut rows = Vec::new();
    for &n in counts {
        let side = ((n as f64).sqrt().round() as u32).max(1);
        let scene = world_scene_flown(world(side), flight);
        if n <= geometry_up_to {
            tick(format!("{n} objects: geometry"));
            let mut geometry = planner(&scene, settings, 0.0, false);
            rows.push(
                fly(&scene, settings, 0.0, &mut geometry).row(&scene, "geometry", 0.0, settings),
            );
        }
        for &b in &settings.budgets {
            tick(format!("{n} objects: planner-tree {b}"));
            let mut tree = hierarchy(&scene, settings, b);
            rows.push(fly(&scene, settings, b, &mut tree).row(&scene, "planner-tree", b, settings));
        }
    }
    rows
}

/// The showcase's planned objects (its city district's buildings), the rest of its scene
/// as plain geometry, and the part of its headless path that flies over the district (the
/// tour's 72% to 82%).
fn showcase_scene() -> Scene {
    let show = Showcase::new();
    let objects = show.ibr.impostors.city.objects.clone();
    let s = &show.scene;
    let mut ground = MeshGroup::new();
    let meshes: Vec<Arc<Mesh>> = s.meshes.iter().cloned().map(Arc::new).collect();
    let materials: Vec<Arc<Material>> = s.materials.iter().cloned().map(Arc::new).collect();
    for i in &s.instances {
        if let (Some(m), Some(mat)) = (meshes.get(i.mesh), materials.get(i.material)) {
            ground = ground.with(m.clone(), mat.clone(), i.transform);
        }
    }
    let lighting = s.lighting.clone();
    Scene {
        name: "showcase",
        objects,
        ground,
        lighting,
        camera: Box::new(move |f, n, (w, h)| {
            const STEPS: usize = 10_000;
            let at = 0.72 + 0.1 * f as f32 / n.max(1) as f32;
            let (eye, target) = show.path((at * STEPS as f32) as usize, STEPS);
            showcase::camera(eye, target, w, h)
        }),
    }
}

/// Runs the sweep.
pub fn run(settings: &Settings, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let scenes = scenes(settings);
    let wanted = |m: &str| settings.methods.is_empty() || settings.methods.iter().any(|w| w == m);
    let alone = REPRESENTATIONS[ALONE..]
        .iter()
        .filter(|&&m| wanted(m))
        .count();
    let each = |m: &str| usize::from(wanted(m));
    let per_budget = each("impostors") + each("planner") + each("planner-frame") + alone;
    let runs = scenes.len()
        * (each("geometry")
            + per_budget * settings.budgets.len()
            + each("planner-frame") * settings.frame_budgets.len()
            + each("layers") * settings.layer_px.len());
    let mut tick = sweep::ticker(runs, progress);
    let mut rows = Vec::new();
    for scene in &scenes {
        if wanted("geometry") {
            tick(format!("{} geometry", scene.name));
            let mut geometry = planner(scene, settings, 0.0, false);
            rows.push(
                fly(scene, settings, 0.0, &mut geometry).row(scene, "geometry", 0.0, settings),
            );
        }
        for &b in &settings.budgets {
            if wanted("impostors") {
                tick(format!("{} impostors {b}", scene.name));
                let flown = fly(scene, settings, b, &mut impostored(scene, settings, b));
                rows.push(flown.row(scene, "impostors", b, settings));
            }
            if wanted("planner") {
                tick(format!("{} planner {b}", scene.name));
                let flown = fly(scene, settings, b, &mut planner(scene, settings, b, true));
                rows.push(flown.row(scene, "planner", b, settings));
            }
            if wanted("planner-frame") {
                rows.push(frame_scope(scene, settings, b, &mut tick));
            }
            for (k, &name) in REPRESENTATIONS.iter().enumerate().skip(ALONE) {
                if !wanted(name) {
                    continue;
                }
                tick(format!("{} {name} {b}", scene.name));
                let flown = fly(
                    scene,
                    settings,
                    b,
                    &mut planner_of(scene, settings, b, &[k]),
                );
                rows.push(flown.row(scene, name, b, settings));
            }
        }
        for &b in settings
            .frame_budgets
            .iter()
            .filter(|_| wanted("planner-frame"))
        {
            rows.push(frame_scope(scene, settings, b, &mut tick));
        }
        for &px in settings.layer_px.iter().filter(|_| wanted("layers")) {
            tick(format!("{} layers {px} px", scene.name));
            let flown = fly(
                scene,
                settings,
                f32::INFINITY,
                &mut layered(scene, settings, px),
            );
            rows.push(flown.row(scene, "layers", px, settings));
        }
    }
    rows
}

/// The frame-scope planner's run at `budget`: per node of a hierarchy over the objects
/// ([`hierarchy`]) in scenes of [`TREE_FROM`] objects or more, else per object.
fn frame_scope(
    scene: &Scene,
    settings: &Settings,
    budget: f32,
    tick: &mut dyn FnMut(String),
) -> Row {
    tick(format!("{} planner-frame {budget}", scene.name));
    if scene.objects.len() >= TREE_FROM {
        let mut tree = hierarchy(scene, settings, budget);
        return fly(scene, settings, budget, &mut tree).row(
            scene,
            "planner-frame",
            budget,
            settings,
        );
    }
    let mut whole = planner(scene, settings, budget, true);
    whole.config.budgets.scope = Scope::Frame;
    fly(scene, settings, budget, &mut whole).row(scene, "planner-frame", budget, settings)
}

/// The planners' representations, in their order: geometry, runtime impostors, image
/// layers, baked octahedral impostors (8 x 8 views of 32 pixels over the upper
/// hemisphere), depth images and LDIs of [`LDI_LAYERS`] layers (each object's captured
/// from the eye and warped to the view), axial billboards (64 pixels, baked from the
/// side) and light fields (six slabs of 8 x 8 cameras of 32 pixels around each object).
///
/// Geometry, then every representation in ibr's catalogue ([`ibr::catalog`]),
/// in its order: a technique added there is swept here with no change to this file.
pub static REPRESENTATIONS: LazyLock<Vec<&'static str>> = LazyLock::new(|| {
    let catalogued = ibr::catalog().iter().filter(|e| e.representation.is_some());
    std::iter::once("geometry")
        .chain(catalogued.map(|e| e.name))
        .collect()
});

/// The representations from this one on ([`REPRESENTATIONS`]) are also run alone, each
/// wherever its predicted error is within the budget and geometry elsewhere (the planner
/// choosing between the two): those before have single-technique runs of their own
/// policies (`impostors`, `layers`).
pub const ALONE: usize = 3;

/// Layers the planners' LDIs peel.
pub const LDI_LAYERS: usize = 3;

/// The planners' predicted milliseconds of rebuilds per frame: what a game might give
/// them, and what keeps bakes of many captures each (a billboard's 57, a light field's
/// 384) from taking whole seconds while the count budget allows them (the impostors' own
/// rebuilds predict about 30 ms at the world's count budget).
pub const REBUILD_MS: f32 = 40.0;

/// The planners' memory budget, bytes: what a game might give images (the other methods
/// hold at most 46 MB in these scenes; an octahedral bake holds 1.3 MB).
pub const MEMORY: usize = 256 << 20;

/// Rebuilds per frame for `scene`.
fn rebuilds(scene: &Scene, settings: &Settings) -> usize {
    settings.rebuilds.max(scene.objects.len() / 16)
}

/// The planner over the scene's objects: geometry, and every other representation of
/// [`REPRESENTATIONS`] when `images`.
fn planner(scene: &Scene, settings: &Settings, budget: f32, images: bool) -> Planner<MeshGroup> {
    let all: Vec<usize> = (1..REPRESENTATIONS.len()).collect();
    planner_of(scene, settings, budget, if images { &all } else { &[] })
}

/// The planner over the scene's objects choosing among geometry and the representations
/// `which` (indices into [`REPRESENTATIONS`], in order).
fn planner_of(
    scene: &Scene,
    settings: &Settings,
    budget: f32,
    which: &[usize],
) -> Planner<MeshGroup> {
    let n = scene.objects.len();
    let mut reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![Box::new(Geometry)];
    for &k in which {
        reps.push(match k {
            1 => Box::new(ImpostorSet::new(image_config(scene, settings, budget), n)),
            2 => Box::new(LayerSet::new(layer_config(scene, settings, 1.0), n)),
            _ => ibr::represent(REPRESENTATIONS[k], n).expect("in ibr's catalogue"),
        });
    }
    let config = plan::Config {
        budgets: Budgets {
            error: budget,
            rebuilds: rebuilds(scene, settings),
            rebuild_ms: Some(REBUILD_MS),
            memory: Some(MEMORY),
            ..Budgets::default()
        },
        spread: settings.spread.unwrap_or(plan::SPREAD),
        ..plan::Config::default()
    };
    Planner::new(config, scene.objects.clone(), reps)
}

/// Objects from which the frame scope plans per node of a hierarchy ([`hierarchy`]): a
/// world's thousands of objects, where planning each would cost more than it saves.
pub const TREE_FROM: usize = 4096;

/// The per-node planner over a hierarchy of the scene's objects, each node drawn as one
/// runtime impostor of all its objects when its predicted error is within `budget`
/// ([`crate::world::tree_planner`]).
fn hierarchy(scene: &Scene, settings: &Settings, budget: f32) -> Hierarchy<MeshGroup> {
    let plan = crate::world::TreePlan {
        budget,
        rebuilds: rebuilds(scene, settings),
        // The warm-up's frames, at the other planners' rebuild budget.
        loading: (settings.warmup as u32, REBUILD_MS),
        height: settings.size.1,
    };
    crate::world::tree_planner(scene.objects.clone(), plan)
}

/// Impostor settings shared by both impostor methods: enough textures for every object.
fn image_config(scene: &Scene, settings: &Settings, levels: f32) -> impostor::Config {
    crate::world::image_config(levels, rebuilds(scene, settings))
}

/// Layer settings: re-rendered past `px` of geometric error.
fn layer_config(scene: &Scene, settings: &Settings, px: f32) -> layers::Config {
    layers::Config {
        tolerance_px: px,
        budget: Budget::count(rebuilds(scene, settings)),
        ..layers::Config::default()
    }
}

/// Runtime impostors everywhere, refreshed past `levels` of predicted staleness.
fn impostored(scene: &Scene, settings: &Settings, levels: f32) -> Impostored<MeshGroup> {
    let cfg = image_config(scene, settings, levels);
    let mut imp = Impostored::new("impostors", cfg, scene.objects.clone());
    imp.near = true;
    imp
}

/// Image layers everywhere, re-rendered past `px` of geometric error.
fn layered(scene: &Scene, settings: &Settings, px: f32) -> Layered<MeshGroup> {
    Layered::new(
        "layers",
        layer_config(scene, settings, px),
        scene.objects.clone(),
    )
}
