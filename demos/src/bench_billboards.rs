//! The `bench billboards` sweep: what billboards cost and how far billboard trees are from
//! the meshes they replace.
//!
//! Six series in four groups, one CSV row per point ([`Row::HEADER`]):
//! - `count`: screen-facing, alpha-blended glow particles ([`sprites::glow`] 64 px, 0.15
//!   world units wide) scattered in a box 10 to 30 units in front of the camera, at
//!   [`Plan::count_size`], for each of [`Plan::counts`].
//! - `resolution`: the same particles, [`Plan::resolution_count`] of them, at each of
//!   [`Plan::resolutions`].
//! - `accuracy_fade` and `accuracy_top`: a pine and a broadleaf tree drawn as meshes (the
//!   ground truth: lit, vertex-coloured) and as axial billboards showing sprites baked once
//!   from the meshes ([`sprites::bake_upright`], seen from +Z, same lighting,
//!   [`Plan::bake_px`] tall), each alone over a transparent background in a square image
//!   of [`Plan::accuracy_size`], seen from 11 units away from the tree's mid-height point
//!   (the trees are 5 tall; 40 degree field of view) at each view elevation of
//!   [`Plan::elevations`] (measured at that point) and each azimuth of [`Plan::azimuths`]
//!   (0 = the baked side; the billboard turns to face every azimuth but keeps showing the
//!   baked side, as in a game). The billboard fades by the elevation seen from its base
//!   (its pivot), a few degrees more than the nominal one. Billboards are alpha-tested
//!   (`AlphaMode::Mask { cutoff: 0.5 }`, opaque pass).
//!   `accuracy_fade` uses [`Facing::UPRIGHT`] (fades out between 55 and 75 degrees);
//!   `accuracy_top` adds the baked top-down sprite ([`AxialFallback::top`]). The error is
//!   [`ibr::metrics`] over the union of both images' covered rectangles (grown by 2
//!   pixels), pooled over trees and azimuths ([`ImageError::pooled`]).
//! - `trees_mesh` and `trees_billboard`: a forest of [`Plan::tree_counts`] trees (pines and
//!   broadleaves, 3 to 7 units tall, at random on a 200 x 200 square of a flat ground
//!   plane) seen from one camera 12 units up at [`Plan::tree_size`]: as meshes (statically
//!   batched: one merged mesh per kind, so the renderer sees three draws with the ground)
//!   or as alpha-tested [`Facing::UPRIGHT`] billboards of sprites baked 128 px tall (one
//!   batch per kind).
//!
//! Timing: every frame is timed as two parts, `build` (computing the billboard [`View`] and
//! [`BillboardBatch::build`]: quad generation, and for blended batches the back-to-front
//! sort; zero for meshes) and `render` (`Renderer::render` alone, clear included). Columns
//! `build_ms` and `render_ms` are their medians; `median_ms`, `min_ms` and `p90_ms` are of
//! their sum. Accuracy rows are not timed (empty time columns); timing rows have no error
//! columns.

use crate::bench::count_name;
use crate::chart::{Chart, Line, Lines};
use crate::sweep::{ticker, timed_frames, CsvRow};
use crate::timing::Summary;
use engine::procedural::{self, TreeKind, XorShift};
use engine::{
    AlphaMode, BlendMode, Camera, Draw, FrameOptions, FrameStats, Lighting, Material, Mesh,
    Renderer, Rgba, Target,
};
use glam::{Mat4, Vec2, Vec3};
use ibr::metrics::{self, Coverage, ImageError, Options, Region};
use ibr::sprites::{self, BakedSprite};
use ibr::{AxialFallback, Billboard, BillboardBatch, Facing, Size, View};
use plotters::prelude::SeriesLabelPosition;
use std::sync::Arc;
use std::time::{Duration, Instant};

pub use crate::sweep::MIN_FRAMES;

/// How much the sweep measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Particle counts of the `count` series, at `count_size`.
    pub counts: Vec<usize>,
    pub count_size: (u32, u32),
    /// Target sizes of the `resolution` series, with `resolution_count` particles.
    pub resolutions: Vec<(u32, u32)>,
    pub resolution_count: usize,
    /// View elevations (degrees) of the accuracy series.
    pub elevations: Vec<f32>,
    /// View azimuths (degrees from the baked side) pooled at each elevation.
    pub azimuths: Vec<f32>,
    /// Side of the square accuracy images, and height of the baked sprites, in pixels.
    pub accuracy_size: u32,
    pub bake_px: u32,
    /// Tree counts of the `trees_*` series, at `tree_size`.
    pub tree_counts: Vec<usize>,
    pub tree_size: (u32, u32),
    pub warmup: usize,
    /// Most timed frames per measurement.
    pub frames: usize,
    /// Time budget per measurement; measuring stops after it (at least [`MIN_FRAMES`]).
    pub budget: Duration,
}

impl Plan {
    /// The full sweep.
    pub fn full() -> Plan {
        Plan {
            counts: vec![1_000, 10_000, 100_000, 1_000_000],
            count_size: (1280, 720),
            resolutions: vec![
                (320, 240),
                (640, 480),
                (1280, 720),
                (1920, 1080),
                (2560, 1440),
                (3840, 2160),
            ],
            resolution_count: 10_000,
            elevations: (0..=9).map(|i| i as f32 * 10.0).collect(),
            azimuths: vec![0.0, 90.0, 180.0, 270.0],
            accuracy_size: 256,
            bake_px: 256,
            tree_counts: vec![100, 1_000, 10_000, 50_000],
            tree_size: (1280, 720),
            warmup: 2,
            frames: 21,
            budget: Duration::from_secs(2),
        }
    }

    /// Every point of the full sweep with few frames: about a minute at most.
    pub fn quick() -> Plan {
        Plan {
            warmup: 1,
            frames: 5,
            budget: Duration::from_millis(600),
            ..Plan::full()
        }
    }

    /// A seconds-long smoke run (tests): small counts and sizes, four elevations.
    pub fn tiny() -> Plan {
        Plan {
            counts: vec![100, 1_000],
            count_size: (320, 240),
            resolutions: vec![(160, 120), (320, 240)],
            resolution_count: 1_000,
            elevations: vec![0.0, 30.0, 60.0, 90.0],
            azimuths: vec![0.0, 180.0],
            accuracy_size: 96,
            bake_px: 96,
            tree_counts: vec![50, 200],
            tree_size: (320, 240),
            warmup: 0,
            frames: 2,
            budget: Duration::from_millis(100),
        }
    }

    /// Measurements the sweep makes (progress steps).
    pub fn steps(&self) -> usize {
        self.counts.len()
            + self.resolutions.len()
            + 2 * self.elevations.len()
            + 2 * self.tree_counts.len()
    }
}

/// Frame times of a measurement: the build part, the render part, and their sum.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Times {
    pub build: Summary,
    pub render: Summary,
    pub total: Summary,
}

/// One measurement: a CSV row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `count`, `resolution`, `accuracy_fade`, `accuracy_top`, `trees_mesh` or
    /// `trees_billboard`.
    pub series: &'static str,
    /// What the series sweeps: `billboards`, `pixels`, `elevation_deg` or `trees`.
    pub param: &'static str,
    pub value: f64,
    pub width: u32,
    pub height: u32,
    /// Billboards (particles) or trees in the frame.
    pub items: u64,
    /// Triangles submitted to the renderer (accuracy rows: the pine billboard's image at
    /// azimuth 0).
    pub triangles: u64,
    pub threads: usize,
    /// `None` for accuracy rows.
    pub times: Option<Times>,
    /// Counters of the last timed frame (accuracy rows: the pine billboard's image at
    /// azimuth 0).
    pub stats: FrameStats,
    /// `None` for timing rows.
    pub error: Option<ImageError>,
}

impl Row {
    /// A timing row (no error columns) of `items` billboards or trees in `triangles`, at
    /// `value` of `param`.
    fn timed(
        series: &'static str,
        param: &'static str,
        value: f64,
        (width, height): (u32, u32),
        items: u64,
        triangles: u64,
        (times, stats): (Times, FrameStats),
    ) -> Row {
        Row {
            series,
            param,
            value,
            width,
            height,
            items,
            triangles,
            threads: rayon::current_num_threads(),
            times: Some(times),
            stats,
            error: None,
        }
    }
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,param,value,width,height,items,triangles,threads,frames,build_ms,render_ms,median_ms,min_ms,p90_ms,triangles_set_up,fragments_shaded,psnr_db,mae,max_abs,frac_over,coverage_mismatch";

    fn csv(&self) -> String {
        let times = match &self.times {
            Some(t) => format!(
                "{},{:.4},{:.4},{:.4},{:.4},{:.4}",
                t.total.frames,
                t.build.median_ms,
                t.render.median_ms,
                t.total.median_ms,
                t.total.min_ms,
                t.total.p90_ms
            ),
            None => ",,,,,".to_string(),
        };
        let error = match &self.error {
            Some(e) => format!(
                "{:.3},{:.4},{},{:.5},{:.5}",
                e.psnr_db, e.mean_abs, e.max_abs, e.frac_over, e.coverage_mismatch
            ),
            None => ",,,,".to_string(),
        };
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{}",
            self.series,
            self.param,
            self.value,
            self.width,
            self.height,
            self.items,
            self.triangles,
            self.threads,
            times,
            self.stats.triangles_set_up,
            self.stats.fragments_shaded,
            error
        )
    }
}

/// Times frames of `fixed` draws plus `batches` rebuilt every frame for `camera`.
fn measure(
    renderer: &mut Renderer,
    target: &mut Target,
    camera: &Camera,
    lighting: &Lighting,
    fixed: &[Draw],
    batches: &mut [BillboardBatch],
    plan: &Plan,
) -> (Times, FrameStats) {
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.05, 0.06, 0.09, 1.0)),
        ..Default::default()
    };
    let frames = timed_frames(plan.warmup, plan.frames, plan.budget, || {
        let t0 = Instant::now();
        let view = View::new(camera, target.height());
        for b in batches.iter_mut() {
            b.build(&view);
        }
        let t1 = Instant::now();
        let draws = fixed
            .iter()
            .copied()
            .chain(batches.iter().map(|b| b.draw()));
        let stats = renderer.render(draws, camera, lighting, target, &opts);
        (t1 - t0, t1.elapsed(), stats)
    });
    let summary = |part: fn(&(Duration, Duration, FrameStats)) -> Duration| {
        Summary::of(&frames.iter().map(part).collect::<Vec<_>>())
    };
    let times = Times {
        build: summary(|f| f.0),
        render: summary(|f| f.1),
        total: summary(|f| f.0 + f.1),
    };
    (
        times,
        frames.last().map_or_else(FrameStats::default, |f| f.2),
    )
}

/// The particle camera: at the origin looking down -Z, 60 degrees, 0.5 - 100.
pub fn particle_camera(width: u32, height: u32) -> Camera {
    Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.5, 100.0)
}

/// `n` glow particles (screen-facing, alpha-blended, warm random tints) in the box
/// x in [-12, 12], y in [-7, 7], z in [-30, -10].
pub fn particles(n: usize, seed: u64) -> BillboardBatch {
    let material = Material::unlit(Rgba::WHITE)
        .with_texture(Arc::new(sprites::glow(64)))
        .blended(BlendMode::Alpha);
    let mut batch = BillboardBatch::new(material);
    let mut rng = XorShift::new(seed);
    batch.items.reserve(n);
    for _ in 0..n {
        let p = Vec3::new(
            rng.range(-12.0, 12.0),
            rng.range(-7.0, 7.0),
            rng.range(-30.0, -10.0),
        );
        let mut b = Billboard::new(p, Facing::Screen, Vec2::splat(0.15));
        b.rotation = rng.range(0.0, std::f32::consts::TAU);
        b.tint = Rgba::new(1.0, rng.range(0.4, 0.9), rng.range(0.1, 0.4), 0.8);
        batch.push(b);
    }
    batch
}

/// The trees of the sweep, standing on the origin and 5 units tall: a pine and a broadleaf.
fn tree_meshes() -> [Mesh; 2] {
    [
        procedural::tree(TreeKind::Pine, 5.0, 11),
        procedural::tree(TreeKind::Broadleaf, 5.0, 12),
    ]
}

/// The trees' material: lit, vertex-coloured.
fn tree_material() -> Material {
    Material::lit(Rgba::WHITE)
}

/// The alpha-tested material of billboard trees showing `sprite`.
fn sprite_material(sprite: &BakedSprite) -> Material {
    Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..Material::unlit(Rgba::WHITE).with_texture(sprite.texture.clone())
    }
}

/// An upright billboard standing on `position` showing `sprite`'s side view at `scale`.
fn tree_billboard(sprite: &BakedSprite, position: Vec3, scale: f32, facing: Facing) -> Billboard {
    Billboard {
        position,
        facing,
        size: Size::World(sprite.size * scale),
        pivot: sprite.pivot,
        rotation: 0.0,
        tint: Rgba::WHITE,
        region: sprite.side,
    }
}

/// A camera `dist` from `center` at `azimuth` (degrees about +Y from +Z) and `elevation`
/// (degrees above the horizon), upright, well defined straight above too.
pub fn orbit_camera(center: Vec3, dist: f32, azimuth: f32, elevation: f32, fov: f32) -> Camera {
    let (sa, ca) = azimuth.to_radians().sin_cos();
    let (se, ce) = elevation.to_radians().sin_cos();
    let dir = Vec3::new(sa * ce, se, ca * ce);
    let up = Vec3::new(-sa * se, ce, -ca * se);
    Camera::look_at(center + dir * dist, center, up, fov, 1.0)
        .with_depth_range(dist * 0.05, dist * 4.0)
}

/// The billboard-tree error at each elevation: one `accuracy_fade` and one `accuracy_top`
/// row per elevation.
fn accuracy(
    plan: &Plan,
    renderer: &mut Renderer,
    threads: usize,
    progress: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let lighting = Lighting::default();
    let material = tree_material();
    let trees: Vec<(Mesh, BakedSprite)> = tree_meshes()
        .into_iter()
        .map(|mesh| {
            let sprite = sprites::bake_upright(&mesh, &material, &lighting, Vec3::Z, plan.bake_px);
            (mesh, sprite)
        })
        .collect();
    let size = plan.accuracy_size;
    let clear = FrameOptions {
        clear: Some(Rgba::new(0.0, 0.0, 0.0, 0.0)),
        ..Default::default()
    };
    let mut truth = Target::new(size, size);
    let mut image = Target::new(size, size);
    for (series, with_top) in [("accuracy_fade", false), ("accuracy_top", true)] {
        for &elevation in &plan.elevations {
            progress(format!("{series} {elevation} deg"));
            let mut errors = Vec::new();
            let mut first: Option<(u64, FrameStats)> = None;
            for (mesh, sprite) in &trees {
                let facing = Facing::Axial {
                    axis: Vec3::Y,
                    fallback: AxialFallback {
                        top: with_top.then_some(sprite.top),
                        ..AxialFallback::default()
                    },
                };
                let mut batch = BillboardBatch::new(sprite_material(sprite));
                batch.push(tree_billboard(sprite, Vec3::ZERO, 1.0, facing));
                let center = Vec3::new(0.0, 2.5, 0.0);
                for &azimuth in &plan.azimuths {
                    let cam = orbit_camera(center, 11.0, azimuth, elevation, 40f32.to_radians());
                    let draw = Draw {
                        mesh,
                        material: &material,
                        transform: Mat4::IDENTITY,
                    };
                    renderer.render([draw], &cam, &lighting, &mut truth, &clear);
                    batch.build(&View::new(&cam, size));
                    let stats =
                        renderer.render([batch.draw()], &cam, &lighting, &mut image, &clear);
                    first.get_or_insert((batch.mesh().triangle_count() as u64, stats));
                    let rect = match (
                        metrics::covered_rect(&truth, Coverage::Alpha),
                        metrics::covered_rect(&image, Coverage::Alpha),
                    ) {
                        (None, None) => metrics::Rect::new(0, 0, size, size),
                        (a, b) => a.unwrap_or_default().union(b.unwrap_or_default()),
                    };
                    let opts = Options {
                        region: Region::Rect(rect.grow(2, size, size)),
                        ..Options::default()
                    };
                    errors.push(metrics::compare(&image, &truth, &opts).expect("same size"));
                }
            }
            let (triangles, stats) = first.unwrap_or_default();
            rows.push(Row {
                series,
                param: "elevation_deg",
                value: elevation as f64,
                width: size,
                height: size,
                items: trees.len() as u64,
                triangles,
                threads,
                times: None,
                stats,
                error: ImageError::pooled(&errors),
            });
        }
    }
}

/// A forest of `n` trees (pines and broadleaves, 0.6 to 1.4 times 5 units tall) on the
/// square x in [-100, 100], z in [-190, 10]: positions, kinds (0 pine, 1 broadleaf) and
/// scales.
fn forest(n: usize, seed: u64) -> Vec<(Vec3, usize, f32)> {
    let mut rng = XorShift::new(seed);
    (0..n)
        .map(|_| {
            let p = Vec3::new(rng.range(-100.0, 100.0), 0.0, rng.range(-190.0, 10.0));
            let kind = (rng.next_u64() % 2) as usize;
            (p, kind, rng.range(0.6, 1.4))
        })
        .collect()
}

/// The forest camera: 12 units up at z = 20, looking down 15 degrees along -Z.
pub fn forest_camera(width: u32, height: u32) -> Camera {
    let eye = Vec3::new(0.0, 12.0, 20.0);
    let target = eye + Vec3::new(0.0, -(15f32.to_radians().tan()), -1.0);
    Camera::look_at(eye, target, Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.5, 400.0)
}

/// Appends `mesh` moved by `m` (normals rotated) to `out`.
fn append_transformed(out: &mut Mesh, mesh: &Mesh, m: Mat4) {
    let mut copy = mesh.clone();
    for p in &mut copy.positions {
        *p = m.transform_point3(*p);
    }
    let n = Mat4::from_mat3(glam::Mat3::from_mat4(m).inverse().transpose());
    for v in &mut copy.normals {
        *v = n.transform_vector3(*v).normalize_or(Vec3::Y);
    }
    out.append(&copy);
}

/// The `trees_mesh` and `trees_billboard` rows for each tree count.
fn trees(
    plan: &Plan,
    renderer: &mut Renderer,
    progress: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let lighting = Lighting::default();
    let material = tree_material();
    let kinds = tree_meshes();
    let sprites: Vec<BakedSprite> = kinds
        .iter()
        .map(|mesh| sprites::bake_upright(mesh, &material, &lighting, Vec3::Z, 128))
        .collect();
    let ground = procedural::plane(240.0, 240.0, 1, 1);
    let ground_material = Material::lit(Rgba::from_srgb8(90, 120, 60));
    let ground_at = Mat4::from_translation(Vec3::new(0.0, 0.0, -90.0));
    let (w, h) = plan.tree_size;
    let camera = forest_camera(w, h);
    let mut target = Target::new(w, h);
    let time = |renderer: &mut Renderer,
                target: &mut Target,
                fixed: &[Draw],
                batches: &mut [BillboardBatch]| {
        measure(renderer, target, &camera, &lighting, fixed, batches, plan)
    };
    for &n in &plan.tree_counts {
        let trees = forest(n, 5);
        // Meshes: one merged mesh per kind (static batching).
        progress(format!("trees_mesh {}", count_name(n as u64)));
        let mut merged = [Mesh::default(), Mesh::default()];
        let mut rng = XorShift::new(9);
        for &(p, kind, scale) in &trees {
            let m = Mat4::from_translation(p)
                * Mat4::from_rotation_y(rng.range(0.0, std::f32::consts::TAU))
                * Mat4::from_scale(Vec3::splat(scale));
            append_transformed(&mut merged[kind], &kinds[kind], m);
        }
        let mut fixed = vec![Draw {
            mesh: &ground,
            material: &ground_material,
            transform: ground_at,
        }];
        fixed.extend(merged.iter().map(|mesh| Draw {
            mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        }));
        let triangles = fixed.iter().map(|d| d.mesh.triangle_count() as u64).sum();
        let measured = time(renderer, &mut target, &fixed, &mut []);
        let row = |series, triangles, measured| {
            Row::timed(
                series,
                "trees",
                n as f64,
                (w, h),
                n as u64,
                triangles,
                measured,
            )
        };
        rows.push(row("trees_mesh", triangles, measured));
        drop(fixed);
        drop(merged);

        // Billboards: one alpha-tested batch per kind.
        progress(format!("trees_billboard {}", count_name(n as u64)));
        let mut batches: Vec<BillboardBatch> = sprites
            .iter()
            .map(|s| BillboardBatch::new(sprite_material(s)))
            .collect();
        for &(p, kind, scale) in &trees {
            batches[kind].push(tree_billboard(&sprites[kind], p, scale, Facing::UPRIGHT));
        }
        let fixed = [Draw {
            mesh: &ground,
            material: &ground_material,
            transform: ground_at,
        }];
        let measured = time(renderer, &mut target, &fixed, &mut batches);
        let triangles = ground.triangle_count() as u64
            + batches
                .iter()
                .map(|b| b.mesh().triangle_count() as u64)
                .sum::<u64>();
        rows.push(row("trees_billboard", triangles, measured));
    }
}

/// Runs the whole sweep; `progress` is called before each measurement with its 0-based
/// index, the total, and what it is.
pub fn run(plan: &Plan, mut progress: impl FnMut(usize, usize, &str)) -> Vec<Row> {
    let mut rows = Vec::with_capacity(plan.steps());
    let mut tick = ticker(plan.steps(), &mut progress);
    let mut renderer = Renderer::new();
    let threads = rayon::current_num_threads();
    let lighting = Lighting::default();
    // Times a batch of particles into `target`: the batch's triangles and the measurement.
    let mut particles_in = |target: &mut Target, batch: &mut [BillboardBatch; 1]| {
        let camera = particle_camera(target.width(), target.height());
        let measured = measure(&mut renderer, target, &camera, &lighting, &[], batch, plan);
        (batch[0].mesh().triangle_count() as u64, measured)
    };

    let size = plan.count_size;
    let mut target = Target::new(size.0, size.1);
    for &n in &plan.counts {
        tick(format!("count {}", count_name(n as u64)));
        let (triangles, measured) = particles_in(&mut target, &mut [particles(n, 1)]);
        let value = n as f64;
        rows.push(Row::timed(
            "count",
            "billboards",
            value,
            size,
            n as u64,
            triangles,
            measured,
        ));
    }
    drop(target);

    let mut batch = [particles(plan.resolution_count, 1)];
    for &(w, h) in &plan.resolutions {
        tick(format!("resolution {w}x{h}"));
        let (triangles, measured) = particles_in(&mut Target::new(w, h), &mut batch);
        let n = plan.resolution_count as u64;
        let value = w as f64 * h as f64;
        rows.push(Row::timed(
            "resolution",
            "pixels",
            value,
            (w, h),
            n,
            triangles,
            measured,
        ));
    }
    drop(batch);

    accuracy(plan, &mut renderer, threads, &mut tick, &mut rows);
    trees(plan, &mut renderer, &mut tick, &mut rows);
    rows
}

/// Highest PSNR drawn in charts (identical images have an infinite PSNR).
pub const PSNR_CAP_DB: f64 = 99.0;

/// The sweep's charts: file name and chart.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let of = |series: &'static str| rows.iter().filter(move |r| r.series == series);
    let times = |series: &'static str, x: fn(&Row) -> f64, pick: fn(&Times) -> f64, name: &str| {
        let points = of(series).filter_map(|r| Some((x(r), pick(r.times.as_ref()?))));
        Line::new(name, points.collect())
    };
    let parts = |series: &'static str, x: fn(&Row) -> f64| {
        vec![
            times(series, x, |t| t.total.median_ms, "build + render"),
            times(series, x, |t| t.render.median_ms, "render"),
            times(series, x, |t| t.build.median_ms, "build (quads + sort)"),
        ]
    };
    let size_of = |series: &'static str| {
        of(series)
            .next()
            .map_or(String::new(), |r| format!(" at {}x{}", r.width, r.height))
    };
    let mut res = parts("resolution", |r| r.value / 1e6);
    res[0].labels = of("resolution")
        .map(|r| format!("{}x{}", r.width, r.height))
        .collect();
    let n = of("resolution").next().map_or(0, |r| r.items);
    let accuracy = |name: &str, y_desc: &str, pick: fn(&ImageError) -> f64| {
        let line = |series: &'static str, label: &str| {
            let points = of(series).filter_map(|r| Some((r.value, pick(r.error.as_ref()?))));
            Line::new(label, points.collect())
        };
        Lines::new(
            format!("Billboard trees against meshes: {name} vs view elevation"),
            "view elevation (degrees)",
            y_desc,
            vec![
                line("accuracy_fade", "fade out (Facing::UPRIGHT)"),
                line("accuracy_top", "fade to top-down sprite"),
            ],
        )
    };
    let total = |t: &Times| t.total.median_ms;
    let value = |r: &Row| r.value;
    vec![
        (
            "billboards_count.png",
            Lines::new(
                format!("Blended particles: frame time vs count{}", size_of("count")),
                "billboards",
                "median time (ms)",
                parts("count", value),
            )
            .log(true, true),
        ),
        (
            "billboards_resolution.png",
            Lines::new(
                format!(
                    "Blended particles: frame time vs resolution ({})",
                    count_name(n)
                ),
                "megapixels",
                "median time (ms)",
                res,
            ),
        ),
        (
            "billboards_accuracy_psnr.png",
            accuracy("PSNR", "PSNR (dB)", |e| e.psnr_capped(PSNR_CAP_DB))
                .legend(SeriesLabelPosition::LowerLeft),
        ),
        (
            "billboards_accuracy_mae.png",
            accuracy("mean error", "mean absolute error (8-bit levels)", |e| {
                e.mean_abs
            }),
        ),
        (
            "billboards_trees.png",
            Lines::new(
                format!("Forest: frame time vs trees{}", size_of("trees_mesh")),
                "trees",
                "median frame time (ms)",
                vec![
                    times("trees_mesh", value, total, "mesh trees"),
                    times(
                        "trees_billboard",
                        value,
                        total,
                        "billboard trees (build + render)",
                    ),
                ],
            )
            .log(true, true),
        ),
    ]
    .into_iter()
    .map(|(name, lines)| (name, Chart::Lines(lines)))
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_match_the_header_with_and_without_times() {
        let timed = Row {
            series: "count",
            param: "billboards",
            value: 1000.0,
            width: 320,
            height: 240,
            items: 1000,
            triangles: 2000,
            threads: 2,
            times: Some(Times::default()),
            stats: FrameStats::default(),
            error: None,
        };
        let n = Row::HEADER.split(',').count();
        assert_eq!(timed.csv().split(',').count(), n);
        let accuracy = Row {
            times: None,
            error: ImageError::pooled([]),
            ..timed
        };
        assert_eq!(accuracy.csv().split(',').count(), n);
    }

    #[test]
    fn the_orbit_camera_looks_at_its_centre_from_every_elevation() {
        let c = Vec3::new(0.0, 2.5, 0.0);
        for el in [0.0, 45.0, 90.0] {
            for az in [0.0, 90.0, 200.0] {
                let cam = orbit_camera(c, 11.0, az, el, 0.7);
                assert!((cam.eye().distance(c) - 11.0).abs() < 1e-3);
                assert!((cam.forward() - (c - cam.eye()).normalize()).length() < 1e-3);
                assert!(cam.view.is_finite());
            }
        }
    }
}
