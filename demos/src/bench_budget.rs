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
//! sixteenth of the objects, at least [`Plan::rebuilds`]). Each run first holds still for
//! [`Plan::warmup`] frames at its first view (images are taken as a game loading a level
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
mod objects;
mod trace;
mod world;

pub use calibrate::{calibrate, Calibration};
pub use objects::{objects, ObjectRow};
pub use trace::{trace, TraceRow};
pub use world::World;

use crate::bench_impostors::frame_camera;
use crate::city::{City, Path as CityPath};
use crate::showcase::{self, Showcase};
use crate::sweep::{self, CsvRow};
use crate::timing::Summary;
use engine::{Camera, Draw, FrameOptions, Lighting, Material, Mesh, Renderer, Rgba, Target};
use ibr::impostor::{self, Frustum, ImpostorSet, Impostored, Tolerance};
use ibr::layers::{self, LayerSet, Layered};
use ibr::metrics::{self, Options, RectCover};
use ibr::plan::{self, Budgets, Geometry, Planner, Representation, Scope};
use ibr::schedule::Budget;
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::sync::Arc;
use std::time::Duration;

/// What a sweep measures.
#[derive(Clone, Debug)]
pub struct Plan {
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
}

impl Plan {
    /// 640 x 360; the city (16 buildings of 12,000 triangles) and a 150 x 150 world.
    pub fn full() -> Plan {
        Plan {
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
        }
    }

    /// Every point, fewer frames.
    pub fn quick() -> Plan {
        Plan {
            frames: 8,
            ..Plan::full()
        }
    }

    /// A seconds-long smoke run (tests).
    pub fn tiny() -> Plan {
        Plan {
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
    /// would have made it hold on 99% of frames ([`spread_fit`]).
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
    pub planning_ms: f64,
}

impl CsvRow for Row {
    const HEADER: &'static str = "scene,method,budget,objects,triangles,width,height,frames,median_ms,mean_ms,measured_mean,measured_p99,within,objects_over,psnr_db,predicted_mean,predicted_max,predicted_bound,spread_fit,geometry_per_frame,images_per_frame,mix,switches_per_frame,rebuilds_per_frame,memory_mb,planning_ms";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{:.3},{:.3},{:.4},{:.4},{:.4},{:.5},{:.3},{:.4},{:.4},{:.4},{:.4},{:.1},{:.1},{},{:.2},{:.2},{:.2},{:.3}",
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

fn scenes(plan: &Plan) -> Vec<Scene> {
    let city = City::new(plan.city.0, plan.city.1, 7);
    let mut out = Vec::new();
    if plan.showcase {
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
    if plan.world > 0 {
        let world = World::new(plan.world, 11);
        let (objects, ground, lighting) = (
            world.objects.clone(),
            world.ground.clone(),
            world.lighting.clone(),
        );
        out.push(Scene {
            name: "world",
            objects,
            ground,
            lighting,
            camera: Box::new(move |f, n, size| {
                world.camera(f as f32 / n.max(2) as f32 * 0.25, size)
            }),
        });
    }
    out.retain(|s| plan.only.as_deref().is_none_or(|o| o == s.name));
    out
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
pub fn run(plan: &Plan, progress: &mut dyn FnMut(usize, usize, &str)) -> Vec<Row> {
    let scenes = scenes(plan);
    let wanted = |m: &str| plan.methods.is_empty() || plan.methods.iter().any(|w| w == m);
    let alone = REPRESENTATIONS[ALONE..]
        .iter()
        .filter(|&&m| wanted(m))
        .count();
    let each = |m: &str| usize::from(wanted(m));
    let per_budget = each("impostors") + each("planner") + each("planner-frame") + alone;
    let runs = scenes.len()
        * (each("geometry")
            + per_budget * plan.budgets.len()
            + each("planner-frame") * plan.frame_budgets.len()
            + each("layers") * plan.layer_px.len());
    let mut tick = sweep::ticker(runs, progress);
    let mut rows = Vec::new();
    for scene in &scenes {
        if wanted("geometry") {
            tick(format!("{} geometry", scene.name));
            let mut geometry = planner(scene, plan, 0.0, false);
            rows.push(fly(scene, plan, 0.0, &mut geometry).row(scene, "geometry", 0.0, plan));
        }
        for &b in &plan.budgets {
            if wanted("impostors") {
                tick(format!("{} impostors {b}", scene.name));
                let flown = fly(scene, plan, b, &mut impostored(scene, plan, b));
                rows.push(flown.row(scene, "impostors", b, plan));
            }
            if wanted("planner") {
                tick(format!("{} planner {b}", scene.name));
                let flown = fly(scene, plan, b, &mut planner(scene, plan, b, true));
                rows.push(flown.row(scene, "planner", b, plan));
            }
            if wanted("planner-frame") {
                rows.push(frame_scope(scene, plan, b, &mut tick));
            }
            for (k, &name) in REPRESENTATIONS.iter().enumerate().skip(ALONE) {
                if !wanted(name) {
                    continue;
                }
                tick(format!("{} {name} {b}", scene.name));
                let flown = fly(scene, plan, b, &mut planner_of(scene, plan, b, &[k]));
                rows.push(flown.row(scene, name, b, plan));
            }
        }
        for &b in plan
            .frame_budgets
            .iter()
            .filter(|_| wanted("planner-frame"))
        {
            rows.push(frame_scope(scene, plan, b, &mut tick));
        }
        for &px in plan.layer_px.iter().filter(|_| wanted("layers")) {
            tick(format!("{} layers {px} px", scene.name));
            let flown = fly(scene, plan, f32::INFINITY, &mut layered(scene, plan, px));
            rows.push(flown.row(scene, "layers", px, plan));
        }
    }
    rows
}

/// The frame-scope planner's run at `budget`.
fn frame_scope(scene: &Scene, plan: &Plan, budget: f32, tick: &mut dyn FnMut(String)) -> Row {
    tick(format!("{} planner-frame {budget}", scene.name));
    let mut whole = planner(scene, plan, budget, true);
    whole.config.budgets.scope = Scope::Frame;
    fly(scene, plan, budget, &mut whole).row(scene, "planner-frame", budget, plan)
}

/// The planners' representations, in their order: geometry, runtime impostors, image
/// layers, baked octahedral impostors (8 x 8 views of 32 pixels over the upper
/// hemisphere), depth images and LDIs of [`LDI_LAYERS`] layers (each object's captured
/// from the eye and warped to the view), axial billboards (64 pixels, baked from the
/// side) and light fields (six slabs of 8 x 8 cameras of 32 pixels around each object).
pub const REPRESENTATIONS: [&str; 8] = [
    "geometry",
    "impostors",
    "layers",
    "octahedral",
    "depth images",
    "LDIs",
    "billboards",
    "light fields",
];

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
fn rebuilds(scene: &Scene, plan: &Plan) -> usize {
    plan.rebuilds.max(scene.objects.len() / 16)
}

/// The planner over the scene's objects: geometry, and every other representation of
/// [`REPRESENTATIONS`] when `images`.
fn planner(scene: &Scene, plan: &Plan, budget: f32, images: bool) -> Planner<MeshGroup> {
    let all: Vec<usize> = (1..REPRESENTATIONS.len()).collect();
    planner_of(scene, plan, budget, if images { &all } else { &[] })
}

/// The planner over the scene's objects choosing among geometry and the representations
/// `which` (indices into [`REPRESENTATIONS`], in order).
fn planner_of(scene: &Scene, plan: &Plan, budget: f32, which: &[usize]) -> Planner<MeshGroup> {
    let n = scene.objects.len();
    let mut reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![Box::new(Geometry)];
    for &k in which {
        reps.push(match k {
            1 => Box::new(ImpostorSet::new(image_config(scene, plan, budget), n)),
            2 => Box::new(LayerSet::new(layer_config(scene, plan, 1.0), n)),
            _ => ibr::represent(REPRESENTATIONS[k], n).expect("in ibr's catalogue"),
        });
    }
    let config = plan::Config {
        budgets: Budgets {
            error: budget,
            rebuilds: rebuilds(scene, plan),
            rebuild_ms: Some(REBUILD_MS),
            memory: Some(MEMORY),
            ..Budgets::default()
        },
        spread: plan.spread.unwrap_or(plan::SPREAD),
        ..plan::Config::default()
    };
    Planner::new(config, scene.objects.clone(), reps)
}

/// Impostor settings shared by both impostor methods: enough textures for every object.
fn image_config(scene: &Scene, plan: &Plan, levels: f32) -> impostor::Config {
    impostor::Config {
        tolerance: Tolerance {
            levels: Some(levels),
            ..Tolerance::default()
        },
        budget: Budget::count(rebuilds(scene, plan)),
        pool_slots: 1 << 16,
        prewarm: 0.0,
        ..impostor::Config::default()
    }
}

/// Layer settings: re-rendered past `px` of geometric error.
fn layer_config(scene: &Scene, plan: &Plan, px: f32) -> layers::Config {
    layers::Config {
        tolerance_px: px,
        budget: Budget::count(rebuilds(scene, plan)),
        ..layers::Config::default()
    }
}

/// Runtime impostors everywhere, refreshed past `levels` of predicted staleness.
fn impostored(scene: &Scene, plan: &Plan, levels: f32) -> Impostored<MeshGroup> {
    let cfg = image_config(scene, plan, levels);
    let mut imp = Impostored::new("impostors", cfg, scene.objects.clone());
    imp.near = true;
    imp
}

/// Image layers everywhere, re-rendered past `px` of geometric error.
fn layered(scene: &Scene, plan: &Plan, px: f32) -> Layered<MeshGroup> {
    Layered::new(
        "layers",
        layer_config(scene, plan, px),
        scene.objects.clone(),
    )
}

/// What a run reads from its technique after each frame.
trait Probe: Technique {
    fn probe(&self) -> Sample;
}

/// One frame's counters.
#[derive(Clone, Copy, Debug, Default)]
struct Sample {
    /// Objects drawn as geometry and as images, and by each of the planner's
    /// representations ([`REPRESENTATIONS`]).
    geometry: usize,
    images: usize,
    mix: [usize; REPRESENTATIONS.len()],
    switches: usize,
    rebuilds: usize,
    /// Bytes images hold.
    memory: usize,
    /// Predicted error of the drawn objects (mean, largest), levels (0 where not predicted).
    predicted_mean: f32,
    predicted_max: f32,
    /// The planner's bound on the frame's error, and its scatter ([`plan::Report`]).
    bound: f32,
    scatter: f32,
    /// The planner's own time (predicting and choosing), milliseconds.
    planning_ms: f32,
}

impl Probe for Planner<MeshGroup> {
    fn probe(&self) -> Sample {
        let r = &self.report;
        let c = self.counters();
        let mut mix = [0; REPRESENTATIONS.len()];
        mix.iter_mut().zip(&r.counts).for_each(|(m, &n)| *m = n);
        Sample {
            mix,
            geometry: c.geometry as usize,
            images: c.images as usize,
            switches: r.switches,
            rebuilds: r.rebuilds,
            memory: r.memory,
            predicted_mean: r.mean_error,
            predicted_max: r.max_error,
            bound: r.bound,
            scatter: r.scatter,
            planning_ms: r.planning_ms,
        }
    }
}

impl Probe for Impostored<MeshGroup> {
    fn probe(&self) -> Sample {
        let r = &self.report;
        let shown = self
            .set
            .impostors
            .iter()
            .filter(|i| i.mode == impostor::Mode::Image);
        let (mut sum, mut max, mut n) = (0.0, 0.0f32, 0);
        for i in shown {
            sum += i.predicted.levels;
            max = max.max(i.predicted.levels);
            n += 1;
        }
        let memory = self
            .set
            .impostors
            .iter()
            .filter(|i| i.has_texture())
            .filter_map(|i| i.capture())
            .map(|c| (c.side as usize).pow(2) * 16 / 3)
            .sum();
        Sample {
            geometry: r.geometry,
            images: r.images,
            rebuilds: r.refreshes,
            memory,
            predicted_mean: sum / n.max(1) as f32,
            predicted_max: max,
            ..Sample::default()
        }
    }
}

impl Probe for Layered<MeshGroup> {
    fn probe(&self) -> Sample {
        let r = &self.report;
        let memory = self.set.layers.iter().filter_map(|l| l.image_size());
        let memory = memory.map(|(w, h)| (w * h) as usize * 16 / 3).sum();
        Sample {
            geometry: r.geometry,
            images: r.images,
            rebuilds: r.refreshes,
            memory,
            ..Sample::default()
        }
    }
}

/// A visible object's index, its measured error over its screen rectangle, the rectangle.
type ObjectError = (usize, f64, metrics::Rect);

/// One run's frames, and what it measured.
#[derive(Default)]
struct Flight {
    times: Vec<Duration>,
    frame_errors: Vec<f64>,
    objects_over: Vec<f64>,
    psnr: Vec<f64>,
    probes: Vec<Sample>,
    scratch: Scratch,
    /// The last frame's visible objects: index, measured error over its screen rectangle,
    /// and the rectangle.
    seen: Vec<ObjectError>,
}

fn fly<T: Probe>(scene: &Scene, plan: &Plan, budget: f32, t: &mut T) -> Flight {
    fly_with(scene, plan, budget, t, &mut |_, _| {})
}

/// [`fly`], calling `each` after every measured frame with the technique and the visible
/// objects' measured errors ([`Flight::seen`]).
fn fly_with<T: Probe>(
    scene: &Scene,
    plan: &Plan,
    budget: f32,
    t: &mut T,
    each: &mut dyn FnMut(&T, &[ObjectError]),
) -> Flight {
    let (w, h) = plan.size;
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..FrameOptions::default()
    };
    let mut ground = Vec::new();
    scene.ground.draws(&mut ground);
    let (mut renderer, mut frame_loop) = (Renderer::new(), FrameLoop::new());
    let (mut target, mut truth) = (Target::new(w, h), Target::new(w, h));
    let mut out = Flight::default();
    let frames = plan.frames.max(1);
    for f in 0..plan.warmup + frames {
        let k = f.saturating_sub(plan.warmup);
        let camera = (scene.camera)(k, frames, plan.size);
        let view = FrameView::still(&camera, w, h, &scene.lighting);
        let techniques: &mut [&mut dyn Technique] = &mut [t];
        frame_loop.render(
            &mut renderer,
            ground.iter().copied(),
            techniques,
            &view,
            &mut target,
            &opts,
        );
        if f < plan.warmup {
            continue;
        }
        out.times.push(frame_loop.times.total);
        out.probes.push(t.probe());
        let mut all: Vec<Draw<'_>> = ground.clone();
        scene.objects.iter().for_each(|o| o.draws(&mut all));
        renderer.render(all, &camera, &scene.lighting, &mut truth, &opts);
        let (frame, over) = measure(
            &truth,
            &target,
            &scene.objects,
            &camera,
            budget,
            (&mut out.scratch, &mut out.seen),
        );
        each(t, &out.seen);
        out.frame_errors.push(frame);
        out.objects_over.push(over);
        if let Ok(e) = metrics::compare(&truth, &target, &Options::default()) {
            out.psnr.push(e.psnr_capped(99.0));
        }
    }
    out
}

/// The frame's error: the mean absolute error over the pixels the visible objects' screen
/// rectangles cover (each pixel once, however many rectangles cover it: the planner's
/// frame scope, [`plan::Scope::Frame`]), and the fraction of visible objects whose own
/// rectangle's mean error is over `budget`. Visible is what the planner counts: a sphere in
/// the view frustum.
fn measure(
    truth: &Target,
    got: &Target,
    objects: &[MeshGroup],
    camera: &Camera,
    budget: f32,
    (scratch, seen): (&mut Scratch, &mut Vec<ObjectError>),
) -> (f64, f64) {
    let (w, h) = (truth.width() as usize, truth.height() as usize);
    let (a, b) = (truth.to_rgba8(), got.to_rgba8());
    // Per-pixel mean absolute RGB difference, and its summed-area table.
    let (diff, table) = (&mut scratch.diff, &mut scratch.table);
    diff.clear();
    diff.extend(a.chunks_exact(4).zip(b.chunks_exact(4)).map(|(p, q)| {
        let d: u32 = (0..3).map(|c| u32::from(p[c].abs_diff(q[c]))).sum();
        f64::from(d) / 3.0
    }));
    table.clear();
    table.resize((w + 1) * (h + 1), 0.0);
    for y in 0..h {
        let mut row = 0.0;
        for x in 0..w {
            row += diff[y * w + x];
            table[(y + 1) * (w + 1) + x + 1] = table[y * (w + 1) + x + 1] + row;
        }
    }
    seen.clear();
    let frustum = Frustum::new(camera.clip_from_world());
    let mut over = 0usize;
    for (i, o) in objects.iter().enumerate() {
        let s = o.bounds();
        if !frustum.sees(s.center, s.radius) {
            continue;
        }
        let Some(r) = impostor::screen_rect(camera, s.center, s.radius, w as u32, h as u32) else {
            continue;
        };
        let (x0, y0, x1, y1) = (
            r.x as usize,
            r.y as usize,
            (r.x + r.width) as usize,
            (r.y + r.height) as usize,
        );
        let px = ((x1 - x0) * (y1 - y0)) as f64;
        if px == 0.0 {
            continue;
        }
        let at = |x: usize, y: usize| table[y * (w + 1) + x];
        let total = at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
        seen.push((i, total / px, r));
        over += usize::from(total / px > f64::from(budget));
    }
    let cover = &mut scratch.cover;
    cover.count(w as u32, h as u32, seen.iter().map(|s| s.2));
    let covered = cover.counts().iter().zip(diff.iter());
    let sum: f64 = covered.filter(|(&c, _)| c > 0).map(|(_, &d)| d).sum();
    let area = cover.area() as f64;
    (sum / area.max(1.0), over as f64 / seen.len().max(1) as f64)
}

/// [`measure`]'s memory, reused frame to frame.
#[derive(Default)]
struct Scratch {
    diff: Vec<f64>,
    table: Vec<f64>,
    cover: RectCover,
}

impl Flight {
    fn row(self, scene: &Scene, method: &'static str, budget: f32, plan: &Plan) -> Row {
        let n = self.frame_errors.len().max(1) as f64;
        let mut sorted = self.frame_errors.clone();
        sorted.sort_by(f64::total_cmp);
        let p99 = sorted
            .get(((sorted.len() as f64 * 0.99).ceil() as usize).saturating_sub(1))
            .copied()
            .unwrap_or(0.0);
        let within = self
            .frame_errors
            .iter()
            .filter(|&&e| e <= f64::from(budget))
            .count();
        let mean = |f: &dyn Fn(&Sample) -> f64| {
            self.probes.iter().map(f).sum::<f64>() / self.probes.len().max(1) as f64
        };
        Row {
            scene: scene.name,
            method,
            budget,
            objects: scene.objects.len(),
            triangles: scene.objects.iter().map(|o| o.triangle_count()).sum(),
            width: plan.size.0,
            height: plan.size.1,
            time: Summary::of(&self.times),
            measured_mean: self.frame_errors.iter().sum::<f64>() / n,
            measured_p99: p99,
            within: within as f64 / n,
            objects_over: self.objects_over.iter().sum::<f64>() / n,
            psnr_db: self.psnr.iter().sum::<f64>() / self.psnr.len().max(1) as f64,
            predicted_mean: mean(&|p| f64::from(p.predicted_mean)),
            predicted_max: self
                .probes
                .iter()
                .map(|p| f64::from(p.predicted_max))
                .fold(0.0, f64::max),
            predicted_bound: mean(&|p| f64::from(p.bound)),
            spread_fit: spread_fit(&self.probes, &self.frame_errors),
            geometry_per_frame: mean(&|p| p.geometry as f64),
            images_per_frame: mean(&|p| p.images as f64),
            mix: if method.starts_with("planner") {
                let per = |k: usize| mean(&|p| p.mix[k] as f64);
                let names = REPRESENTATIONS.iter().enumerate();
                let parts: Vec<String> = names.map(|(k, n)| format!("{n} {:.1}", per(k))).collect();
                parts.join(" ")
            } else {
                String::new()
            },
            switches_per_frame: mean(&|p| p.switches as f64),
            rebuilds_per_frame: mean(&|p| p.rebuilds as f64),
            memory_mb: mean(&|p| p.memory as f64) / (1 << 20) as f64,
            planning_ms: mean(&|p| f64::from(p.planning_ms)),
        }
    }
}

/// The least [`plan::Config::spread`] whose bound would have held on 99% of the frames:
/// the 99th percentile over frames of the measured error's excess over the predicted mean,
/// in units of the frame's scatter, over [`plan::Z99`] (0 when the planner predicted
/// nothing, or never erred beyond its mean).
fn spread_fit(probes: &[Sample], measured: &[f64]) -> f64 {
    let mut z: Vec<f64> = probes
        .iter()
        .zip(measured)
        .filter(|(p, _)| p.scatter > 0.0)
        .map(|(p, &m)| (m - f64::from(p.predicted_mean)) / f64::from(p.scatter))
        .collect();
    if z.is_empty() {
        return 0.0;
    }
    z.sort_by(f64::total_cmp);
    let p99 = z[((z.len() as f64 * 0.99).ceil() as usize).saturating_sub(1)];
    (p99 / plan::Z99).max(0.0)
}

/// `(file, chart)` for every chart of the sweep: per scene, frame time against measured
/// error, one line per method over the budgets.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, crate::chart::Chart)> {
    use crate::chart::{Chart, Line, Lines};
    let mut out = Vec::new();
    for (scene, file) in [
        ("showcase", "budget_time_error_showcase.png"),
        ("city", "budget_time_error_city.png"),
        ("world", "budget_time_error_world.png"),
    ] {
        if !rows.iter().any(|r| r.scene == scene) {
            continue;
        }
        // Each point labelled with its error budget.
        let series = |method: &str| {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.scene == scene && r.method == method)
                .collect();
            let pts = of.iter().map(|r| (r.time.median_ms, r.measured_mean));
            let labels = of.iter().map(|r| format!("b{}", r.budget)).collect();
            Line::new(format!("{method} ({scene})"), pts.collect()).labelled(labels)
        };
        out.push((
            file,
            Chart::Lines(Lines::new(
                "Measured error against frame time (labels: error budget bN)",
                "median frame time (ms)",
                "mean abs error over objects (8-bit levels)",
                ["geometry", "impostors", "layers"]
                    .into_iter()
                    .chain(REPRESENTATIONS[ALONE..].iter().copied())
                    .chain(["planner", "planner-frame"])
                    .map(series)
                    .collect(),
            )),
        ));
    }
    // The planner's predicted against measured error, and the budget itself.
    let planner = |scene: &str, f: &dyn Fn(&Row) -> f64| {
        let pts = rows
            .iter()
            .filter(|r| r.scene == scene && r.method == "planner")
            .map(|r| (f64::from(r.budget), f(r)))
            .collect();
        pts
    };
    let mut lines = Vec::new();
    for scene in ["showcase", "city", "world"] {
        if rows.iter().any(|r| r.scene == scene) {
            let predicted = planner(scene, &|r| r.predicted_mean);
            let measured = planner(scene, &|r| r.measured_mean);
            let p99 = planner(scene, &|r| r.measured_p99);
            lines.push(Line::new(format!("predicted ({scene})"), predicted));
            lines.push(Line::new(format!("measured ({scene})"), measured));
            lines.push(Line::new(format!("measured, p99 frame ({scene})"), p99));
        }
    }
    let budgets: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.method == "planner" && r.scene == "city")
        .map(|r| (f64::from(r.budget), f64::from(r.budget)))
        .collect();
    lines.push(Line::reference("the budget", budgets));
    out.push((
        "budget_predicted_measured.png",
        Chart::Lines(Lines::new(
            "The planner's error against its budget",
            "error budget (8-bit levels)",
            "error over objects (8-bit levels)",
            lines,
        )),
    ));
    out
}
