//! How the planner spends its work: a representation that could never be chosen is not
//! asked for estimates, and under a budget of rebuild milliseconds many short rebuilds go
//! before one long bake worth less per millisecond. Driven by a scripted representation
//! whose predictions are set by the test.

use super::tests::{dear_geometry, frame, tori, view_at};
use super::*;
use crate::core::MeshGroup;
use crate::core::{CostModel, Estimate, Geometry, Representation, Sight, Work};
use engine::Renderer;
use glam::Vec3;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// Predictions set by the test: `error` once built (infinite before), `rebuilt` after a
/// rebuild, drawing and rebuilding at the given work; draws the subject's geometry.
struct Scripted {
    name: &'static str,
    rebuilt: f32,
    draw: Work,
    rebuild: Work,
    least: Work,
    payback: Option<f32>,
    built: Vec<bool>,
    /// Estimates asked for, shared with the test.
    asked: Arc<AtomicUsize>,
}

impl Scripted {
    fn new(name: &'static str, n: usize, draw: Work, rebuild: Work) -> Scripted {
        Scripted {
            name,
            rebuilt: 0.5,
            draw,
            rebuild,
            least: Work::default(),
            payback: None,
            built: vec![false; n],
            asked: Arc::default(),
        }
    }
}

impl Representation<MeshGroup> for Scripted {
    fn name(&self) -> &str {
        self.name
    }
    fn estimate(&self, i: usize, _s: &MeshGroup, _sight: &Sight<'_>) -> Option<Estimate> {
        self.asked.fetch_add(1, Ordering::Relaxed);
        let built = *self.built.get(i)?;
        Some(Estimate {
            error: if built { self.rebuilt } else { f32::INFINITY },
            rebuilt: self.rebuilt,
            draw: self.draw,
            rebuild: self.rebuild,
            memory: 0,
        })
    }
    fn rebuild(&mut self, objects: &[usize], _: &mut [MeshGroup], _: &FrameView<'_>) -> Work {
        for &i in objects {
            self.built[i] = true;
        }
        Work {
            captures: self.rebuild.captures * objects.len() as u64,
            ..Work::default()
        }
    }
    fn draw<'a>(&'a self, _i: usize, s: &'a MeshGroup, _eye: Vec3, out: &mut Vec<Draw<'a>>) {
        s.draws(out);
    }
    fn least_draw(&self) -> Work {
        self.least
    }
    fn payback_frames(&self) -> Option<f32> {
        self.payback
    }
    fn release(&mut self, i: usize) {
        self.built[i] = false;
    }
}

fn captures(n: u64) -> Work {
    Work {
        captures: n,
        ..Work::default()
    }
}

fn image_pixels(n: u64) -> Work {
    Work {
        image_pixels: n,
        ..Work::default()
    }
}

fn planner(budgets: Budgets, cost: CostModel, reps: Vec<Scripted>) -> Planner<MeshGroup> {
    let config = Config {
        budgets,
        cost,
        ..Config::default()
    };
    let mut all: Vec<Box<dyn Representation<MeshGroup>>> = vec![Box::new(Geometry)];
    all.extend(
        reps.into_iter()
            .map(|r| Box::new(r) as Box<dyn Representation<MeshGroup>>),
    );
    Planner::new(config, tori(), all)
}

/// A planner of geometry and `pass` (budget 2 levels, 16 rebuilds), and `pass`'s count of
/// estimates asked.
fn beside_geometry(pass: Scripted) -> (Planner<MeshGroup>, Arc<AtomicUsize>) {
    let asked = pass.asked.clone();
    let budgets = Budgets {
        error: 2.0,
        rebuilds: 16,
        ..Budgets::default()
    };
    (planner(budgets, CostModel::default(), vec![pass]), asked)
}

#[test]
fn a_pass_that_costs_more_than_the_exact_geometry_is_not_asked_unless_in_use() {
    // Each torus's geometry costs about 35 us at the default costs, less than one image
    // pass's setup (52 us): the pass could never be chosen, so it is not asked.
    let least = Work {
        passes: 1,
        ..Work::default()
    };
    let mut pass = Scripted::new("pass", 16, least, captures(1));
    pass.least = least;
    let (mut p, asked) = beside_geometry(pass);
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    frame(&mut p, &cam, &mut r);
    let visible = p.objects.len() - p.report.culled;
    assert!(visible > 0);
    assert_eq!(asked.load(Ordering::Relaxed), 0);
    assert!(p.choices().iter().all(|c| c.rep != Some(1)));

    // Geometry made dear: the pass is asked for every visible object, rebuilt and used.
    p.config.cost = dear_geometry();
    frame(&mut p, &cam, &mut r);
    assert_eq!(asked.load(Ordering::Relaxed), visible);
    let using = p.choices().iter().filter(|c| c.rep == Some(1)).count();
    assert_eq!(using, visible, "{:?}", p.report);

    // Geometry cheap again: the objects using the pass are still asked (so the
    // hysteresis weighs them), and the pass goes only where it loses.
    p.config.cost = CostModel::default();
    asked.store(0, Ordering::Relaxed);
    frame(&mut p, &cam, &mut r);
    assert_eq!(asked.load(Ordering::Relaxed), visible);
    frame(&mut p, &cam, &mut r);
    assert!(p.choices().iter().all(|c| c.rep != Some(1)));
}

#[test]
fn under_a_rebuild_time_budget_short_rebuilds_go_before_a_long_bake_worth_less_per_ms() {
    // A bake: drawn for almost nothing, rebuilt in 2,000 captures (15 ms at the default
    // costs), lasting 3,600 frames. A quick image: drawn for 10,000 image pixels (64 us),
    // rebuilt in 40 captures (0.3 ms), lasting 30 frames. Each saves nearly the whole of a dear geometry, the
    // bake a little more; per millisecond of rebuild the quick image is worth 50 times as
    // much. With 10 ms of rebuilds a frame, the quick images are taken first.
    let tiny = image_pixels(10);
    let mut bake = Scripted::new("bake", 16, tiny, captures(2000));
    bake.payback = Some(3600.0);
    let quick_draw = image_pixels(10_000);
    let quick = Scripted::new("quick", 16, quick_draw, captures(40));
    let budgets = Budgets {
        error: 2.0,
        rebuilds: 16,
        rebuild_ms: Some(10.0),
        ..Budgets::default()
    };
    let cost = dear_geometry();
    let mut p = planner(budgets, cost, vec![bake, quick]);
    let mut r = Renderer::new();
    frame(&mut p, &view_at(0.0), &mut r);
    let quick_ms = cost.ms(captures(40));
    let visible = p.objects.len() - p.report.culled;
    let fit = ((10.0 / quick_ms) as usize).min(visible);
    assert!(fit >= 8, "{fit}");
    assert_eq!(p.report.rebuilds, fit, "{:?}", p.report);
    assert!(p.report.rebuild_ms <= 10.0, "{:?}", p.report);
    let quick_ones = p.choices().iter().filter(|c| c.rep == Some(2)).count();
    assert_eq!(quick_ones, fit);

    // Without the time budget the count alone limits rebuilds, ranked by what each saves:
    // the bakes (saving a little more) are taken, for objects expected to stay.
    let mut bake = Scripted::new("bake", 16, tiny, captures(2000));
    bake.payback = Some(3600.0);
    let quick = Scripted::new("quick", 16, quick_draw, captures(40));
    let budgets = Budgets {
        rebuild_ms: None,
        rebuilds: 4,
        ..budgets
    };
    let mut p = planner(budgets, cost, vec![bake, quick]);
    p.config.horizon = f32::INFINITY;
    frame(&mut p, &view_at(0.0), &mut r);
    let bakes = p.choices().iter().filter(|c| c.rep == Some(1)).count();
    assert_eq!(bakes, 4, "{:?}", p.report);
}

#[test]
fn a_bake_meant_to_last_a_minute_waits_until_its_object_has_been_in_view_long_enough() {
    // A bake drawn for almost nothing, rebuilt in 400 captures (2.9 ms at the default
    // costs), lasting 3,600 frames, beside geometry of some 35 us a torus: it pays back
    // over some 80 frames. An object just come into view is expected to stay 30 frames
    // (the horizon), then as long again as it has been in view: each object is baked once
    // its horizon reaches what its bake needs, not before, and within the frames between
    // which every representation is asked (an option off an object's front waits for
    // them: `Config::reask`).
    let (tiny, slow) = (image_pixels(10), captures(400));
    let mut bake = Scripted::new("bake", 16, tiny, slow);
    bake.payback = Some(3600.0);
    let budgets = Budgets {
        error: 2.0,
        rebuilds: 16,
        ..Budgets::default()
    };
    let cost = CostModel::default();
    let mut p = planner(budgets, cost, vec![bake]);
    let horizon = p.config.horizon;
    assert_eq!(horizon, 30.0);
    let (rebuild_ms, draw_ms) = (cost.rebuild_ms(slow), cost.ms(tiny));
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    let n = p.objects.len();
    let (mut baked, mut needs) = (vec![None; n], vec![f32::NAN; n]);
    for k in 0..200 {
        frame(&mut p, &cam, &mut r);
        for (i, c) in p.choices().iter().enumerate() {
            match c.rep {
                // Frames the bake needs to pay for itself against the geometry.
                Some(0) => needs[i] = rebuild_ms / (c.ms - draw_ms),
                Some(1) if baked[i].is_none() => baked[i] = Some(k),
                _ => {}
            }
        }
    }
    let visible = n - p.report.culled;
    assert!(visible > 1);
    for i in (0..n).filter(|&i| p.choices()[i].rep.is_some()) {
        let (k, needs) = (baked[i].expect("baked") as f32, needs[i]);
        assert!(needs > horizon, "object {i}: {needs}");
        let slack = 1e-3 * needs;
        assert!(
            horizon + k >= needs - slack,
            "object {i} early: {k} {needs}"
        );
        let reask = p.config.reask as f32;
        assert!(
            horizon + k - reask < needs + slack,
            "object {i} late: {k} {needs}"
        );
    }
    // Objects expected to stay are baked at first sight.
    let mut bake = Scripted::new("bake", 16, tiny, slow);
    bake.payback = Some(3600.0);
    let mut p = planner(budgets, cost, vec![bake]);
    p.config.horizon = f32::INFINITY;
    frame(&mut p, &cam, &mut r);
    assert_eq!(p.report.rebuilds, visible, "{:?}", p.report);
}

#[test]
fn an_option_off_the_front_is_asked_again_every_reask_frames_or_once_the_eye_moves() {
    // A pass that draws for more than each torus's geometry (about 35 us) and errs: off
    // every object's front. No bound on its least draw, so only the front skips it.
    let pass = Scripted::new("pass", 16, image_pixels(100_000), captures(1));
    let (mut p, asked) = beside_geometry(pass);
    assert_eq!(p.config.reask, 8);
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    // The first frame asks for every visible object.
    frame(&mut p, &cam, &mut r);
    let visible = p.objects.len() - p.report.culled;
    assert!(visible > 1);
    assert_eq!(asked.swap(0, Ordering::Relaxed), visible);
    let full = p.report.estimates;
    assert_eq!(full, 2 * visible);
    // With the eye still, each object once in the next eight frames, at its own frame.
    let mut fewest = usize::MAX;
    for _ in 0..8 {
        frame(&mut p, &cam, &mut r);
        fewest = fewest.min(p.report.estimates);
        assert!(p.choices().iter().all(|c| c.rep != Some(1)));
    }
    assert_eq!(asked.swap(0, Ordering::Relaxed), visible);
    assert!(fewest < full, "{fewest} {full}");
    // The eye moves by more than REASK_MOVE of every object's distance: all asked again.
    frame(&mut p, &view_at(1.5), &mut r);
    let now = p.objects.len() - p.report.culled;
    assert_eq!(asked.swap(0, Ordering::Relaxed), now);
    // Every frame with a reask of 1.
    p.config.reask = 1;
    for _ in 0..3 {
        frame(&mut p, &view_at(1.5), &mut r);
    }
    assert_eq!(asked.load(Ordering::Relaxed), 3 * now);
}

#[test]
fn geometry_is_priced_by_its_box_where_that_is_smaller_than_its_disc() {
    use super::tests::{camera, H, W};
    use engine::{procedural, FrameOptions, Lighting, Material, Rgba, Target};
    use glam::Mat4;
    // A tall thin post seen from the front: its box's screen rectangle is a sliver of its
    // sphere's disc, and about what the renderer shades.
    let post = Arc::new(procedural::cuboid(Vec3::new(0.2, 2.0, 0.2)));
    let white = Arc::new(Material::unlit(Rgba::WHITE));
    let g = MeshGroup::new().with(post, white, Mat4::IDENTITY);
    let cam = camera(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO);
    let sight = Sight::new(&cam, W, H, g.bounds());
    let e = Representation::<MeshGroup>::estimate(&Geometry, 0, &g, &sight).expect("seen");
    let mut draws = Vec::new();
    g.draws(&mut draws);
    let opts = FrameOptions::default();
    let mut target = Target::new(W, H);
    let stats = Renderer::new().render(draws, &cam, &Lighting::default(), &mut target, &opts);
    let (priced, shaded) = (e.draw.pixels as f32, stats.fragments_shaded as f32);
    let disc = sight.pixels;
    assert!(
        priced < 0.3 * disc,
        "{priced} priced against a disc of {disc}"
    );
    assert!(
        priced >= 0.9 * shaded && priced <= 1.5 * shaded,
        "{priced} priced, {shaded} shaded"
    );
    // Seen from inside its box (no rectangle in front of the eye): the disc.
    let inside = camera(Vec3::new(0.0, 0.5, 0.0), Vec3::new(0.0, 0.5, -1.0));
    let sight = Sight::new(&inside, W, H, g.bounds());
    let e = Representation::<MeshGroup>::estimate(&Geometry, 0, &g, &sight).expect("seen");
    assert_eq!(e.draw.pixels, sight.pixels as u64);
}
