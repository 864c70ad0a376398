//! Light fields as a planner representation: predicted against measured error (the
//! calibration run), a fresh bake near its own sampling, invalidation, the planner's
//! promises with light fields among its choices, release, a memory budget
//! and odd inputs.

use crate::core::screen_rect;
use crate::core::FrameView;
use crate::core::{MeshGroup, Subject};
use crate::core::{Representation, Sight};
use crate::plan::tests::{
    assert_changes_invalidate, beside_geometry, camera, camera_at, dear_geometry, drawn_alone,
    fit_bound, frame, lighting, measured, release_one_and_ignore_out_of_range, render, sight,
    subjects, tori, truth, view_at, Sample, FOV, H, W,
};
use crate::plan::Planner;
use crate::techniques::lightfields::plan::{
    bake_bytes, lightfield_error, taps, view_terms, LightFieldSet,
};
use crate::techniques::lightfields::*;
use engine::procedural::XorShift;
use engine::Camera;
use engine::Renderer;
use glam::Vec3;

type Rep = dyn Representation<MeshGroup>;

/// Bakes every subject into a set of `grid` x `grid` cameras of `st` samples per slab.
fn baked(subjects: &mut [MeshGroup], grid: u32, st: u32) -> LightFieldSet {
    let n = subjects.len();
    let mut set = LightFieldSet::new(n, grid, st);
    let light = lighting();
    let cam = camera(Vec3::new(0.0, 2.0, 10.0), Vec3::ZERO);
    let all: Vec<usize> = (0..n).collect();
    let work = Rep::rebuild(
        &mut set,
        &all,
        subjects,
        &FrameView::still(&cam, W, H, &light),
    );
    assert_eq!(work.captures, 6 * u64::from(grid * grid) * n as u64);
    set
}

/// Object `i` of `set` (baked) seen alone from `camera`: its estimate, and its light field
/// composited on an empty frame against its geometry. `None` where the set does not draw
/// it.
fn sample(
    set: &mut LightFieldSet,
    subjects: &[MeshGroup],
    i: usize,
    camera: &Camera,
    r: &mut Renderer,
) -> Option<Sample> {
    let (e, got, want) = drawn_alone(set, subjects, i, camera, r)?;
    let s = &subjects[i];
    let seen = sight(camera, s);
    let fields = set.fields(i)?;
    let k = object::choose_slab(fields.iter().map(|f| &f.slab), s.bounds(), camera.eye())?;
    let (texels_per_px, shift) = view_terms(&fields[k].slab, &seen);
    let g = set.gradients(i)?[k];
    assert_eq!(e.error, lightfield_error(g, texels_per_px, shift));
    Some(Sample {
        gradient: g.gradient,
        depth_gradient: g.depth_gradient,
        texels_per_px,
        shift,
        predicted: e.error,
        measured: measured(s, camera, &got, &want),
    })
}

#[test]
fn predicted_error_bounds_the_measured_on_the_calibration_run() {
    // The run the constants come from (plan.rs, GHOST): each subject baked with four
    // settings (ghosting from 2.5 to 15 texels a radius), then seen alone along eight
    // random directions, each from five distances (3 to 24 radii: about 0.2 to 1.8 texels
    // per pixel; the nearest mostly in the failure region).
    let mut subjects = subjects();
    let mut r = Renderer::new();
    let settings = [(4, 48), (8, 32), (12, 24), (12, 64)];
    let (mut all, mut none) = (Vec::new(), 0);
    for (c, &(grid, st)) in settings.iter().enumerate() {
        let mut set = baked(&mut subjects, grid, st);
        let mut rng = XorShift::new(11 + c as u64);
        for i in 0..subjects.len() {
            for _ in 0..8 {
                let az = rng.range(0.0, std::f32::consts::TAU);
                let el = rng.range(-1.2, 1.2);
                let d = Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin());
                for distance in [3.0, 5.0, 9.0, 14.0, 24.0] {
                    let cam = camera_at(&subjects[i], d, distance, FOV);
                    match sample(&mut set, &subjects, i, &cam, &mut r) {
                        Some(s) => all.push(s),
                        None => none += 1,
                    }
                }
            }
        }
    }
    let within = all
        .iter()
        .filter(|s| s.measured <= f64::from(s.predicted))
        .count();
    let fraction = within as f64 / all.len() as f64;
    let terms: Vec<(f32, f32, f32)> = all
        .iter()
        .map(|s| (s.terms().0, s.terms().1, s.measured as f32))
        .collect();
    let (texel, ghost) = fit_bound(&terms, 0.95, 150);
    let mean = |f: fn(&Sample) -> f64| all.iter().map(f).sum::<f64>() / all.len() as f64;
    let most = |f: fn(&Sample) -> f32| all.iter().map(f).fold(0.0, f32::max);
    let least = |f: fn(&Sample) -> f32| all.iter().map(f).fold(f32::INFINITY, f32::min);
    eprintln!(
        "{} views drawn ({none} in the failure region), {:.2} to {:.2} texels per pixel, \
         ghosting {:.1} to {:.1} texels: measured within predicted on {within} of {} \
         ({:.1}%; mean measured {:.2}, predicted {:.2} levels); the 95% fit: texel \
         {texel:.2}, ghost {ghost:.2}",
        all.len(),
        least(|s| s.texels_per_px),
        most(|s| s.texels_per_px),
        least(|s| s.shift),
        most(|s| s.shift),
        all.len(),
        fraction * 100.0,
        mean(|s| s.measured),
        mean(|s| f64::from(s.predicted)),
    );
    assert_eq!(all.len() + none, 4 * 4 * 8 * 5, "every view tried");
    assert!(none > 0 && all.len() > 400, "{none} in the failure region");
    assert!(least(|s| s.texels_per_px) < 0.5 && most(|s| s.texels_per_px) > 1.5);
    assert!(least(|s| s.shift) < 3.0 && most(|s| s.shift) > 10.0);
    assert!(fraction >= 0.95, "{fraction}");
}

/// A fresh bake seen from its own cameras (where every ray is one a camera took) errs
/// within its prediction, and less than from halfway between them; the render reads
/// about the samples predicted.
#[test]
fn a_fresh_bake_seen_from_its_cameras_errs_within_prediction_and_reads_the_samples_predicted() {
    let mut subjects = subjects();
    let (grid, st) = (8, 48);
    let mut set = baked(&mut subjects, grid, st);
    let mut r = Renderer::new();
    let light = lighting();
    let (mut at, mut between, mut read) = (Vec::new(), Vec::new(), 0.0);
    for i in 0..subjects.len() {
        let c = subjects[i].bounds().center;
        // The slabs looking along +Z, -X and -Z (the cameras' up is +Y).
        for k in [4, 1, 5] {
            let slab = set.fields(i).expect("baked")[k].slab;
            let cameras = [(4, 4), (3, 4), (4, 3)].map(|(u, v)| (true, slab.uv_point(u, v)));
            let halfway = [(4, 4), (3, 4), (4, 3)]
                .map(|(u, v)| (false, slab.uv_point(u, v) + slab.uv.edge_a / 16.0));
            for (camera_at_sample, eye) in cameras.into_iter().chain(halfway) {
                let cam = camera(eye, c);
                let fields = set.fields(i).unwrap();
                let chosen =
                    object::choose_slab(fields.iter().map(|f| &f.slab), subjects[i].bounds(), eye);
                assert_eq!(chosen, Some(k), "object {i} from {eye}");
                let s = sample(&mut set, &subjects, i, &cam, &mut r).expect("a slab sees it");
                if camera_at_sample {
                    assert!(
                        s.measured <= f64::from(s.predicted),
                        "object {i}, slab {k} from {eye}: {s:?}"
                    );
                    at.push(s.measured);
                } else {
                    between.push(s.measured);
                }
                // Every pixel of the rectangle casts its ray (those at its corners may
                // miss the slab's rectangles); the samples read are at most
                // its pixels times the taps per pixel (a ray that meets only empty samples
                // reads fewer: the prediction is a bound).
                let e = Rep::estimate(&set, i, &subjects[i], &sight(&cam, &subjects[i])).unwrap();
                Rep::prepare(
                    &mut set,
                    &[i],
                    &subjects,
                    &FrameView::still(&cam, W, H, &light),
                );
                let (frame, rect) = set.shown(i).expect("drawn");
                let area = u64::from(rect.x1 - rect.x0) * u64::from(rect.y1 - rect.y0);
                assert_eq!(e.draw.samples, area * taps(set.lookup), "object {i}");
                assert!(
                    frame.rays <= area && frame.rays * 10 >= area * 9,
                    "object {i}: {} rays of {area}",
                    frame.rays
                );
                assert!(
                    frame.taps <= e.draw.samples,
                    "object {i}: read {} of {} predicted",
                    frame.taps,
                    e.draw.samples
                );
                read += frame.taps as f64 / e.draw.samples as f64;
            }
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let worst = at.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "from the cameras: mean {:.2}, worst {worst:.2} levels; halfway between: mean {:.2}; \
         samples read {:.0}% of predicted",
        mean(&at),
        mean(&between),
        read * 100.0 / (at.len() + between.len()) as f64
    );
    assert!(mean(&at) < mean(&between), "{at:?} {between:?}");
}

#[test]
fn a_changed_or_moved_subject_and_an_unbaked_object_have_infinite_error() {
    let mut subjects = subjects();
    let n = subjects.len();
    let (grid, st) = (4, 16);
    let cam = camera_at(
        &subjects[0],
        Vec3::new(0.3, 0.5, 0.8).normalize(),
        12.0,
        FOV,
    );
    // Never baked: nothing to draw now; a bake would err as the prior says, cost six
    // slabs of grid^2 captures and hold what the bake turns out to hold.
    let mut set = LightFieldSet::new(n, grid, st);
    let e = Rep::estimate(&set, 0, &subjects[0], &sight(&cam, &subjects[0])).expect("seen");
    assert!(e.error.is_infinite(), "{e:?}");
    assert!(e.rebuilt.is_finite() && e.rebuilt > 0.0, "{e:?}");
    assert_eq!(e.rebuild.captures, 6 * u64::from(grid * grid));
    assert_eq!(e.rebuild.pixels, 6 * u64::from(grid * grid * st * st));
    let light = lighting();
    let view = FrameView::still(&cam, W, H, &light);
    Rep::rebuild(&mut set, &[0], &mut subjects, &view);
    assert_eq!(e.memory, Rep::memory(&set));
    let seen = sight(&cam, &subjects[0]);
    let fresh = Rep::estimate(&set, 0, &subjects[0], &seen).expect("seen");
    assert!(
        fresh.error.is_finite() && fresh.error == fresh.rebuilt,
        "{fresh:?}"
    );
    assert_changes_invalidate(&mut set, &mut subjects, 0, &cam, fresh);
}

const LIGHT_FIELD: usize = 1;

/// Geometry and light fields (6 x 6 cameras of 24 samples a slab) of the planner tests'
/// sixteen tori.
fn planner(error: f32) -> Planner<MeshGroup> {
    let objects = tori();
    let set = Box::new(LightFieldSet::new(objects.len(), 6, 24));
    beside_geometry(objects, set, error, 8, dear_geometry())
}

/// Every object the frustum keeps is drawn: geometry draws something, and every object
/// drawn as a light field covers pixels of its rectangle when the light fields' passes
/// run alone on an empty frame, wherever its geometry alone would (a sphere's rectangle
/// may reach into the frame when the object does not).
fn assert_light_fields_drawn(p: &Planner<MeshGroup>, cam: &Camera, r: &mut Renderer) -> usize {
    let visible = p.choices().iter().filter(|c| c.rep.is_some()).count();
    assert_eq!(visible + p.report.culled, p.objects.len());
    let light = lighting();
    let set = p.representation(LIGHT_FIELD).expect("light fields");
    let mut alone = render(Vec::new(), cam, r);
    set.passes(&FrameView::still(cam, W, H, &light), &mut alone);
    let rgba = alone.to_rgba8();
    let mut shown = 0;
    for (i, c) in p.choices().iter().enumerate() {
        match c.rep {
            Some(LIGHT_FIELD) => {
                let b = p.objects[i].bounds();
                let rect = screen_rect(cam, b.center, b.radius, W, H).expect("on screen");
                let covered = |rgba: &[u8]| {
                    (rect.y..rect.y + rect.height)
                        .flat_map(|y| (rect.x..rect.x + rect.width).map(move |x| (x, y)))
                        .filter(|&(x, y)| rgba[((y * W + x) * 4 + 3) as usize] > 0)
                        .count()
                };
                let mut draws = Vec::new();
                p.objects[i].draws(&mut draws);
                let geometry = covered(&render(draws, cam, r).to_rgba8());
                let field = covered(&rgba);
                assert!(
                    field > 0 || geometry == 0,
                    "object {i} drawn as a light field covers nothing ({geometry} as geometry)"
                );
                shown += usize::from(field > 0);
            }
            Some(k) => {
                let mut out = Vec::new();
                let rep = p.representation(k).unwrap();
                rep.draw(i, &p.objects[i], cam.eye(), &mut out);
                assert!(!out.is_empty(), "object {i} chose {k} but draws nothing");
            }
            None => {}
        }
    }
    shown
}

#[test]
fn in_a_planner_light_fields_err_within_the_budget_and_none_go_missing() {
    let budget = 20.0;
    let mut p = planner(budget);
    let mut r = Renderer::new();
    let (mut fields, mut worst) = (0, 0.0f64);
    for k in 0..5 {
        let cam = view_at(0.1 * k as f32);
        let got = frame(&mut p, &cam, &mut r);
        assert_light_fields_drawn(&p, &cam, &mut r);
        let rep = p.report.clone();
        assert!(
            rep.max_error <= budget && rep.over_budget == 0,
            "frame {k}: {rep:?}"
        );
        let want = truth(&p, &cam, &mut r);
        for (i, c) in p.choices().iter().enumerate() {
            if c.rep != Some(LIGHT_FIELD) {
                continue;
            }
            fields += 1;
            let e = measured(&p.objects[i], &cam, &got, &want);
            worst = worst.max(e);
            assert!(e <= f64::from(budget), "frame {k}, object {i}: {e} {c:?}");
        }
    }
    eprintln!("{fields} light-field object-frames, worst measured {worst:.2} levels");
    assert!(fields >= 16, "{fields}");
    // The debug view multiplies the light fields by their colour (green): their pixels
    // keep their green and lose red; off restores the frame exactly.
    let cam = view_at(0.4);
    p.config.budgets.rebuilds = 0;
    let plain = frame(&mut p, &cam, &mut r).to_rgba8();
    p.set_tints(true);
    let tinted = frame(&mut p, &cam, &mut r).to_rgba8();
    let turned = plain
        .chunks_exact(4)
        .zip(tinted.chunks_exact(4))
        .filter(|(a, b)| b[1].abs_diff(a[1]) <= 3 && b[0] + 20 < a[0])
        .count();
    assert!(turned > 50, "{turned} pixels turned green");
    p.set_tints(false);
    assert!(frame(&mut p, &cam, &mut r).to_rgba8() == plain);
}

#[test]
fn a_memory_budget_caps_what_the_light_fields_hold() {
    // Memory for four and a half bakes: bakes stop at four, the rest stay geometry (the
    // wanted bakes counted as deferred); nothing is missing.
    let per_bake = bake_bytes([6, 6, 24, 24]);
    let cap = per_bake * 4 + per_bake / 2;
    let mut p = planner(1e9);
    p.config.budgets.memory = Some(cap);
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    for _ in 0..3 {
        frame(&mut p, &cam, &mut r);
        assert_light_fields_drawn(&p, &cam, &mut r);
        assert!(p.report.memory <= cap, "{:?}", p.report);
    }
    assert_eq!(p.report.counts[LIGHT_FIELD], 4, "{:?}", p.report);
    assert_eq!(p.report.memory, 4 * per_bake);
    assert!(p.report.deferred > 0, "{:?}", p.report);
}

#[test]
fn release_frees_a_bake_and_odd_views_neither_panic_nor_estimate() {
    let mut r = Renderer::new();
    // Releasing one bake frees exactly its bytes; indices out of range are
    // ignored by every call.
    let mut subjects = subjects();
    let mut set = baked(&mut subjects, 2, 8);
    let both = Rep::memory(&set);
    let one = bake_bytes([2, 2, 8, 8]);
    let light = lighting();
    let cam = view_at(0.0);
    let view = FrameView::still(&cam, W, H, &light);
    release_one_and_ignore_out_of_range(&mut set, &mut subjects, &view);
    assert_eq!(Rep::memory(&set), both - one);
    assert!(set.fields(1).is_none() && set.fields(0).is_some());
    // A NaN eye, an eye inside the object, one near it off the cube's axes and an empty
    // target: no estimate, and preparing and compositing at those views draws nothing.
    let s = &subjects[0];
    let b = s.bounds();
    let nan = camera(Vec3::NAN, Vec3::ZERO);
    let inside = camera(b.center, b.center + Vec3::Z);
    let near = camera(b.center + Vec3::ONE * b.radius * 1.5, b.center);
    for odd in [&nan, &inside, &near] {
        assert!(
            Rep::estimate(&set, 0, s, &sight(odd, s)).is_none(),
            "{odd:?}"
        );
        let view = FrameView::still(odd, W, H, &light);
        Rep::prepare(&mut set, &[0], &subjects, &view);
        let mut t = render(Vec::new(), &cam, &mut r);
        assert_eq!(Rep::passes(&set, &view, &mut t).fragments_written, 0);
    }
    let empty = Sight {
        width: 0,
        height: 0,
        ..sight(&cam, s)
    };
    assert!(Rep::estimate(&set, 0, s, &empty).is_none());
    let view = FrameView::still(&cam, 0, 0, &light);
    Rep::prepare(&mut set, &[0], &subjects, &view);
    let mut t = engine::Target::new(0, 0);
    Rep::passes(&set, &view, &mut t);
    // Whole frames at those views.
    let mut p = planner(20.0);
    frame(&mut p, &nan, &mut r);
    p.plan(&FrameView::still(&cam, 0, 0, &light));
    assert!(!p.report.mean_error.is_nan(), "{:?}", p.report);
    let in_torus = camera(Vec3::new(-3.0, 0.0, 0.1), Vec3::new(-3.0, 0.0, -5.0));
    frame(&mut p, &in_torus, &mut r);
    assert_light_fields_drawn(&p, &in_torus, &mut r);
}
