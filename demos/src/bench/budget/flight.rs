//! One run of the `budget` sweep: a technique flown along a scene's frames ([`fly`]), each
//! frame timed and measured against the geometry ([`measure`]), and what the run's frames
//! add up to ([`Flight`]).

use super::{Row, Scene, Settings, PLANNING_MS, REPRESENTATIONS};
use crate::timing::Summary;
use engine::{Camera, Draw, FrameOptions, Renderer, Rgba, Target};
use ibr::impostor::{self, Frustum, Impostored};
use ibr::layers::Layered;
use ibr::metrics::{self, Options, RectCover};
use ibr::plan::tree::Hierarchy;
use ibr::plan::{self, Planner};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::time::Duration;

/// What a run reads from its technique after each frame.
pub(super) trait Probe: Technique {
    fn probe(&self) -> Sample;
}

/// Room for the planner's representations in a frame's counters: geometry and every
/// representation in ibr's catalogue ([`REPRESENTATIONS`]; a test checks they fit).
pub(super) const MIX: usize = 16;

/// One frame's counters.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Sample {
    /// Objects drawn as geometry and as images, and by each of the planner's
    /// representations ([`REPRESENTATIONS`]).
    geometry: usize,
    images: usize,
    mix: [usize; MIX],
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
    /// The per-node planner's captures: measured milliseconds (node images and the far
    /// field), and the node images' triangles ([`ibr::plan::tree::TreeReport::captured_triangles`]).
    capture_ms: f32,
    captured: usize,
    captured_draws: usize,
    /// Of `capture_ms`, the far field's; its tiles captured; the node images' rebuilds'
    /// predicted milliseconds ([`ibr::plan::tree::TreeReport::rebuild_ms`]).
    far_ms: f32,
    far_tiles: usize,
    rebuild_ms: f32,
    /// Node-image rebuilds composed of their children's images, and the texels of the
    /// images they drew ([`ibr::plan::tree::TreeReport::composed`]).
    composed: usize,
    composed_texels: u64,
}

impl Probe for Planner<MeshGroup> {
    fn probe(&self) -> Sample {
        let r = &self.report;
        let c = self.counters();
        let mut mix = [0; MIX];
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
            ..Sample::default()
        }
    }
}

/// The per-node planner: its images in the impostors' column of the mix (its one image
/// representation), the objects it draws as geometry in the geometry's.
impl Probe for Hierarchy<MeshGroup> {
    fn probe(&self) -> Sample {
        let r = &self.report;
        let mut mix = [0; MIX];
        (mix[0], mix[1]) = (r.geometry, r.images);
        Sample {
            mix,
            geometry: r.geometry,
            images: r.images,
            rebuilds: r.rebuilds,
            memory: r.memory,
            predicted_mean: r.mean_error,
            predicted_max: r.max_error,
            planning_ms: r.planning_ms,
            capture_ms: r.capture_ms,
            captured: r.captured_triangles,
            captured_draws: r.captured_draws,
            far_ms: r.far_ms,
            far_tiles: r.far.tiles,
            rebuild_ms: r.rebuild_ms,
            composed: r.composed,
            composed_texels: r.composed_texels,
            ..Sample::default()
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
pub(super) struct Flight {
    times: Vec<Duration>,
    frame_errors: Vec<f64>,
    objects_over: Vec<f64>,
    psnr: Vec<f64>,
    probes: Vec<Sample>,
    /// Per frame, the fractions of the reference's pixels the visible objects' rectangles
    /// cover and nothing covers (sky).
    covered: Vec<f64>,
    sky: Vec<f64>,
    scratch: Scratch,
    /// The last frame's visible objects: index, measured error over its screen rectangle,
    /// and the rectangle.
    seen: Vec<ObjectError>,
}

pub(super) fn fly<T: Probe>(scene: &Scene, settings: &Settings, budget: f32, t: &mut T) -> Flight {
    fly_with(scene, settings, budget, t, &mut |_, _| {})
}

/// [`fly`], calling `each` after every measured frame with the technique and the visible
/// objects' measured errors ([`Flight::seen`]).
pub(super) fn fly_with<T: Probe>(
    scene: &Scene,
    settings: &Settings,
    budget: f32,
    t: &mut T,
    each: &mut dyn FnMut(&T, &[ObjectError]),
) -> Flight {
    let (w, h) = settings.size;
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..FrameOptions::default()
    };
    let mut ground = Vec::new();
    scene.ground.draws(&mut ground);
    let (mut renderer, mut frame_loop) = (Renderer::new(), FrameLoop::new());
    let (mut target, mut truth) = (Target::new(w, h), Target::new(w, h));
    let mut out = Flight::default();
    let frames = settings.frames.max(1);
    for f in 0..settings.warmup + frames {
        let k = f.saturating_sub(settings.warmup);
        let camera = (scene.camera)(k, frames, settings.size);
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
        if f < settings.warmup {
            continue;
        }
        out.times.push(frame_loop.times.total);
        out.probes.push(t.probe());
        if settings.stages {
            let (ft, st, fs) = (frame_loop.times, renderer.stage_times(), renderer.stats());
            let ms = |d: Duration| d.as_secs_f64() * 1e3;
            let p = out.probes.last().copied().unwrap_or_default();
            eprintln!("stages {w}x{h} f{k} total {:.2} prepare {:.2} render {:.2} passes {:.2} vertex {:.2} front {:.2} tiles {:.2} draws {} tri_in {} setup {} frag_tested {} frag_shaded {} blended {} rebuilds {} capture_ms {:.2} captured {} captured_draws {} far_ms {:.2} far_tiles {} predicted_rebuild_ms {:.3} composed {} composed_texels {}",
                ms(ft.total), ms(ft.prepare), ms(ft.render), ms(ft.passes), ms(st.vertex), ms(st.front), ms(st.tiles), fs.draws, fs.triangles_in, fs.triangles_set_up, fs.fragments_tested, fs.fragments_shaded, fs.fragments_shaded_blended, p.rebuilds, p.capture_ms, p.captured, p.captured_draws, p.far_ms, p.far_tiles, p.rebuild_ms, p.composed, p.composed_texels);
        }
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
        let pixels = f64::from(w * h).max(1.0);
        out.covered.push(out.scratch.cover.area() as f64 / pixels);
        out.sky.push(sky_pixels(&truth) as f64 / pixels);
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

/// Pixels of `target` nothing was drawn on (its depth the far plane's).
fn sky_pixels(target: &Target) -> usize {
    let (w, h) = (target.width(), target.height());
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| target.depth_reversed(x, y) == Some(0.0))
        .count()
}

/// [`measure`]'s memory, reused frame to frame.
#[derive(Default)]
struct Scratch {
    diff: Vec<f64>,
    table: Vec<f64>,
    cover: RectCover,
}

impl Flight {
    pub(super) fn row(
        self,
        scene: &Scene,
        method: &'static str,
        budget: f32,
        settings: &Settings,
    ) -> Row {
        let n = self.frame_errors.len().max(1) as f64;
        let p99 = percentile(&self.frame_errors, 0.99);
        let planning: Vec<f64> = self
            .probes
            .iter()
            .map(|p| f64::from(p.planning_ms))
            .collect();
        let planned_within = planning.iter().filter(|&&t| t <= PLANNING_MS).count();
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
            width: settings.size.0,
            height: settings.size.1,
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
            planning_p99_ms: percentile(&planning, 0.99),
            planning_max_ms: planning.iter().copied().fold(0.0, f64::max),
            planning_within: planned_within as f64 / planning.len().max(1) as f64,
            covered: self.covered.iter().sum::<f64>() / n,
            sky: self.sky.iter().sum::<f64>() / n,
        }
    }
}

/// The `q` quantile of `values` (the nearest rank at or above it; 0 when empty).
pub(super) fn percentile(values: &[f64], q: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = (sorted.len() as f64 * q).ceil() as usize;
    sorted.get(rank.saturating_sub(1)).copied().unwrap_or(0.0)
}

/// The least [`plan::Config::spread`] whose bound would have held on 99% of the frames:
/// the 99th percentile over frames of the measured error's excess over the predicted mean,
/// in units of the frame's scatter, over [`plan::Z99`] (0 when the planner predicted
/// nothing, or never erred beyond its mean).
pub(super) fn spread_fit(probes: &[Sample], measured: &[f64]) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::{percentile, MIX, REPRESENTATIONS};

    /// The nearest rank at or above the quantile: of 1..=100, the 99th percentile is 99
    /// and the median 50; one value is every percentile; none is 0.
    #[test]
    fn percentiles_are_nearest_ranks() {
        let hundred: Vec<f64> = (1..=100).rev().map(f64::from).collect();
        assert_eq!(percentile(&hundred, 0.99), 99.0);
        assert_eq!(percentile(&hundred, 0.5), 50.0);
        assert_eq!(percentile(&hundred, 1.0), 100.0);
        assert_eq!(percentile(&[2.5], 0.99), 2.5);
        assert_eq!(percentile(&[], 0.99), 0.0);
    }

    #[test]
    fn the_sweep_takes_every_catalogued_representation_and_they_fit_the_counters() {
        let catalogued: Vec<&str> = ibr::catalog()
            .iter()
            .filter(|e| e.representation.is_some())
            .map(|e| e.name)
            .collect();
        assert_eq!(REPRESENTATIONS[0], "geometry");
        assert_eq!(REPRESENTATIONS[1..], catalogued[..]);
        assert!(REPRESENTATIONS.len() <= MIX, "{:?}", *REPRESENTATIONS);
        // The budget sweep's CSV has always named these, in this order.
        for name in ["impostors", "layers", "octahedral", "depth images", "LDIs"] {
            assert!(REPRESENTATIONS.contains(&name), "{name}");
        }
    }
}
