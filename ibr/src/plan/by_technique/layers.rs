//! Image layers as a planner representation: predicted against measured error, and the
//! planner's promises with layers among its choices.

use crate::core::screen_rect;
use crate::core::FrameView;
use crate::core::MeshGroup;
use crate::core::Subject;
use crate::core::{Geometry, Representation};
use crate::metrics::{self, Options, Region};
use crate::plan::{self, Budgets, Planner};
use crate::techniques::impostors::{self as impostor, ImpostorSet};
use crate::techniques::layers::*;
use engine::{procedural, Renderer, Rgba, Target, Texture};
use engine::{Camera, Material};
use glam::{Mat3, Vec3};
use glam::{Mat4, Vec2};
use std::sync::Arc;

use crate::plan::tests::{camera, fit_bound, frame, lighting, render, sight, tori, truth, H, W};

/// Tori, boxes and checkered cards, several of each, spread over a few units in depth.
fn scene() -> Vec<MeshGroup> {
    let torus = Arc::new(procedural::torus(0.4, 0.15, 32, 16));
    let cube = Arc::new(procedural::cuboid(Vec3::new(0.7, 0.9, 0.6)));
    let card = Arc::new(procedural::quad(1.0, 1.0));
    let checker = Arc::new(Texture::checker(
        64,
        8,
        Rgba::new(0.9, 0.8, 0.2, 1.0),
        Rgba::new(0.1, 0.2, 0.6, 1.0),
    ));
    (0..12)
        .map(|k| {
            let at = Vec3::new((k % 4) as f32 * 2.0 - 3.0, 0.0, -((k / 4) as f32) * 2.5);
            // Cards (single-sided) face the eye, turned up to about 35 degrees.
            let turn = Mat4::from_rotation_y(0.3 * (k % 4) as f32 - 0.45)
                * Mat4::from_rotation_x(if k % 3 == 2 {
                    -0.3
                } else {
                    0.3 + 0.1 * k as f32
                });
            let place = Mat4::from_translation(at) * turn;
            let tint = Rgba::new(
                0.3 + 0.15 * (k % 4) as f32,
                0.5,
                0.9 - 0.2 * (k / 4) as f32,
                1.0,
            );
            match k % 3 {
                0 => MeshGroup::new().with(torus.clone(), Arc::new(Material::lit(tint)), place),
                1 => MeshGroup::new().with(cube.clone(), Arc::new(Material::lit(tint)), place),
                _ => {
                    let m = Material::unlit(Rgba::WHITE).with_texture(checker.clone());
                    MeshGroup::new().with(card.clone(), Arc::new(m), place)
                }
            }
        })
        .collect()
}

/// The layer's own screen rectangle this frame (its box's, within the view, grown by 2
/// pixels as the impostors' rectangles are).
fn layer_rect(s: &MeshGroup, camera: &Camera) -> Option<metrics::Rect> {
    let (points, _) = project_corners(s.corners(), &Projector::new(camera, W, H))?;
    let (lo, hi) = clip(bounds(&points), (Vec2::ZERO, Vec2::new(W as f32, H as f32)));
    let (x0, y0) = (lo.x.max(0.0) as u32, lo.y.max(0.0) as u32);
    let (x1, y1) = (
        hi.x.ceil().min(W as f32) as u32,
        hi.y.ceil().min(H as f32) as u32,
    );
    (x1 > x0 && y1 > y0).then(|| metrics::Rect::new(x0, y0, x1 - x0, y1 - y0).grow(2, W, H))
}

/// The object's screen rectangle, as the planner measures its error over.
fn object_rect(s: &MeshGroup, camera: &Camera) -> metrics::Rect {
    let b = s.bounds();
    screen_rect(camera, b.center, b.radius, W, H).unwrap_or_default()
}

fn mean_abs(a: &Target, b: &Target, rect: metrics::Rect) -> f64 {
    let opts = Options {
        region: Region::Rect(rect),
        ..Options::default()
    };
    metrics::compare(a, b, &opts).expect("same size").mean_abs
}

/// One layer's predicted and measured error from one view.
#[derive(Clone, Copy, Debug)]
struct Sample {
    /// The image's gradient per screen pixel, and the warp's geometric error.
    gradient: f32,
    pixels: f32,
    predicted: f32,
    /// Mean absolute error over the object's screen rectangle, and over the layer's own.
    object: f64,
    own: f64,
}

/// Object `i`'s layer, rebuilt from `views[0]`, then drawn alone (prepared, not rebuilt)
/// from each later view: its estimate against the error measured over its rectangles.
fn samples(
    set: &mut LayerSet,
    subjects: &mut [MeshGroup],
    i: usize,
    views: &[Camera],
    r: &mut Renderer,
) -> Vec<Sample> {
    type Rep = dyn Representation<MeshGroup>;
    let light = lighting();
    Rep::rebuild(
        set,
        &[i],
        subjects,
        &FrameView::still(&views[0], W, H, &light),
    );
    let mut out = Vec::new();
    for cam in &views[1..] {
        let s = &subjects[i];
        let (Some(e), Some(rect)) = (Rep::estimate(set, i, s, &sight(cam, s)), layer_rect(s, cam))
        else {
            continue;
        };
        if !e.error.is_finite() {
            continue;
        }
        Rep::prepare(set, &[i], subjects, &FrameView::still(cam, W, H, &light));
        let mut draws = Vec::new();
        Rep::draw(set, i, s, cam.eye(), &mut draws);
        let got = render(draws, cam, r);
        let mut draws = Vec::new();
        s.draws(&mut draws);
        let want = render(draws, cam, r);
        let (layer, image) = (&set.layers[i], set.layers[i].image.expect("an image"));
        out.push(Sample {
            gradient: image.gradient / image.scale,
            pixels: layer.predicted.pixels,
            predicted: e.error,
            object: mean_abs(&want, &got, object_rect(s, cam)),
            own: mean_abs(&want, &got, rect),
        });
    }
    out
}

#[test]
fn predicted_error_bounds_the_measured_on_the_calibration_run() {
    // The run the constants come from (plan.rs, DISPLACEMENT): every layer of the mixed
    // scene, alone, from eleven views along each of five paths away from where it was
    // rendered.
    let mut subjects = scene();
    let n = subjects.len();
    let mut r = Renderer::new();
    let base = Vec3::new(0.0, 2.0, 7.0);
    let target = Vec3::new(0.0, 0.0, -2.5);
    let to = (target - base).normalize();
    let step = |k: usize| k as f32;
    let paths: [Vec<Camera>; 5] = [
        // Slide, rise, orbit, dolly in, turn.
        (0..12)
            .map(|k| {
                camera(
                    base + Vec3::X * 0.03 * step(k),
                    target + Vec3::X * 0.03 * step(k),
                )
            })
            .collect(),
        (0..12)
            .map(|k| camera(base + Vec3::Y * 0.03 * step(k), target))
            .collect(),
        (0..12)
            .map(|k| {
                camera(
                    target + Mat3::from_rotation_y(0.01 * step(k)) * (base - target),
                    target,
                )
            })
            .collect(),
        (0..12)
            .map(|k| camera(base + to * 0.15 * step(k), target))
            .collect(),
        (0..12)
            .map(|k| camera(base, target + Vec3::X * 0.06 * step(k)))
            .collect(),
    ];
    let mut all = Vec::new();
    for views in &paths {
        let mut set = LayerSet::new(Config::default(), n);
        for i in 0..n {
            all.extend(samples(&mut set, &mut subjects, i, views, &mut r));
        }
    }
    let within = |m: fn(&Sample) -> f64| {
        let ok = all
            .iter()
            .filter(|s| m(s) <= f64::from(s.predicted))
            .count();
        ok as f64 / all.len() as f64
    };
    let (object, own, both) = (
        within(|s| s.object),
        within(|s| s.own),
        within(|s| s.object.max(s.own)),
    );
    // In units of each image's gradient: a floor and a slope per pixel of geometric error.
    let terms: Vec<(f32, f32, f32)> = all
        .iter()
        .map(|s| (1.0, s.pixels, s.object.max(s.own) as f32 / s.gradient))
        .collect();
    let (floor, k) = fit_bound(&terms, 0.95, 50);
    let most = all.iter().map(|s| s.pixels).fold(0.0, f32::max);
    eprintln!(
        "{} images, up to {most:.1} px: measured within predicted on {:.1}% over the object's \
         rectangle, {:.1}% over the layer's, {:.1}% both; the 95% fit: resampling {floor:.2}, \
         displacement {k:.2}",
        all.len(),
        object * 100.0,
        own * 100.0,
        both * 100.0
    );
    assert!(all.len() >= 600, "{} images", all.len());
    assert!(most > 3.0, "the paths reach {most} px");
    assert!(both >= 0.95, "{both}");
}

/// The grid from in front and above, slid `x` across.
fn slid(x: f32) -> Camera {
    camera(Vec3::new(x, 2.0, 7.0), Vec3::new(x, 0.0, -3.0))
}

const LAYERS: usize = 1;

fn planner(
    reps: Vec<Box<dyn Representation<MeshGroup>>>,
    error: f32,
    rebuilds: usize,
) -> Planner<MeshGroup> {
    let config = plan::Config {
        budgets: Budgets {
            error,
            rebuilds,
            ..Budgets::default()
        },
        ..plan::Config::default()
    };
    Planner::new(config, tori(), reps)
}

fn geometry_and_layers(error: f32, rebuilds: usize) -> Planner<MeshGroup> {
    let reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
        Box::new(Geometry),
        Box::new(LayerSet::new(Config::default(), 16)),
    ];
    planner(reps, error, rebuilds)
}

/// Every object the frustum keeps is drawn by its representation.
fn assert_none_missing(p: &Planner<MeshGroup>, cam: &Camera) {
    let drawn = p.choices().iter().filter(|c| c.rep.is_some()).count();
    assert_eq!(drawn + p.report.culled, p.objects.len(), "{:?}", p.report);
    for (i, c) in p.choices().iter().enumerate() {
        if let Some(r) = c.rep {
            let mut out = Vec::new();
            let rep = p.representation(r).expect("a representation");
            rep.draw(i, &p.objects[i], cam.eye(), &mut out);
            assert!(!out.is_empty(), "object {i} chose {r} but draws nothing");
        }
    }
}

/// Each object drawn by representation `rep`: its predicted error and the error measured
/// over its screen rectangle in the frame (neighbours' errors included).
fn errors(
    p: &Planner<MeshGroup>,
    rep: usize,
    cam: &Camera,
    got: &Target,
    want: &Target,
) -> Vec<(usize, f32, f64)> {
    let chosen = p.choices().iter().enumerate();
    let by = chosen.filter(|(_, c)| c.rep == Some(rep));
    by.map(|(i, c)| {
        (
            i,
            c.error,
            mean_abs(want, got, object_rect(&p.objects[i], cam)),
        )
    })
    .collect()
}

#[test]
fn an_enormous_budget_makes_visible_objects_layers_that_match_their_geometry() {
    let mut p = geometry_and_layers(1e9, 16);
    let mut r = Renderer::new();
    let cam = slid(0.0);
    for k in 0..2 {
        let got = frame(&mut p, &cam, &mut r);
        let visible = p.objects.len() - p.report.culled;
        assert!(visible >= 12, "{:?}", p.report);
        assert_eq!(p.report.counts[LAYERS], visible, "{:?}", p.report);
        // Rebuilt in the first frame, all at once; kept in the second.
        assert_eq!(p.report.rebuilds, if k == 0 { visible } else { 0 });
        assert_none_missing(&p, &cam);
        let want = truth(&p, &cam, &mut r);
        for (i, predicted, measured) in errors(&p, LAYERS, &cam, &got, &want) {
            assert!(
                predicted.is_finite() && predicted > 0.0,
                "object {i}: {predicted}"
            );
            // Rendered on the pixel grid: the warp copies texels.
            assert!(measured < 1.0, "object {i}: {measured} levels");
            assert!(
                measured <= f64::from(predicted),
                "object {i}: {measured} > {predicted}"
            );
        }
        let whole = metrics::compare(&want, &got, &Options::default()).expect("same size");
        assert!(whole.mean_abs < 0.5, "{whole:?}");
    }
    assert!(p.report.memory > 0);
}

#[test]
fn sliding_away_from_the_rebuild_predicted_error_grows_and_bounds_the_measured() {
    let mut p = geometry_and_layers(1e9, 16);
    let mut r = Renderer::new();
    frame(&mut p, &slid(0.0), &mut r);
    // No more rebuilds: every layer is warped further and further from its image.
    p.config.budgets.rebuilds = 0;
    let mut first = vec![f32::NAN; p.objects.len()];
    let mut last = first.clone();
    let (mut within, mut total) = (0, 0);
    for k in 1..=10 {
        let cam = slid(0.08 * k as f32);
        let got = frame(&mut p, &cam, &mut r);
        let want = truth(&p, &cam, &mut r);
        assert_none_missing(&p, &cam);
        for (i, predicted, measured) in errors(&p, LAYERS, &cam, &got, &want) {
            if first[i].is_nan() {
                first[i] = predicted;
            }
            last[i] = predicted;
            total += 1;
            within += usize::from(measured <= f64::from(predicted));
        }
    }
    let grew = first.iter().zip(&last).filter(|(a, b)| b > a).count();
    let layers = first.iter().filter(|a| !a.is_nan()).count();
    let fraction = within as f64 / total.max(1) as f64;
    let most = last
        .iter()
        .copied()
        .filter(|a| !a.is_nan())
        .fold(0.0, f32::max);
    eprintln!(
        "{layers} layers, {grew} with growing predictions (up to {most:.1} levels); measured \
         within predicted on {within} of {total} ({:.1}%)",
        fraction * 100.0
    );
    assert!(layers >= 12 && grew == layers, "{first:?} {last:?}");
    assert!(total >= 100, "{total}");
    assert!(fraction >= 0.9, "{within} of {total}");
}

#[test]
fn with_impostors_and_layers_none_is_missing_and_the_budget_holds() {
    let budget = 8.0;
    let reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
        Box::new(Geometry),
        Box::new(ImpostorSet::new(impostor::Config::default(), 16)),
        Box::new(LayerSet::new(Config::default(), 16)),
    ];
    let mut p = planner(reps, budget, 4);
    let mut r = Renderer::new();
    let mut used = [0usize; 3];
    for k in 0..24 {
        // Across, then around the grid's centre, then nearer.
        let t = k as f32;
        let cam = match k / 8 {
            0 => slid(0.05 * t),
            1 => camera(
                Vec3::new(0.4, 2.0, -3.0)
                    + Mat3::from_rotation_y(0.03 * (t - 8.0)) * Vec3::new(0.0, 0.0, 10.0),
                Vec3::new(0.4, 0.0, -3.0),
            ),
            _ => camera(
                Vec3::new(0.4, 2.0, 7.0 - 0.3 * (t - 16.0)),
                Vec3::new(0.4, 0.0, -3.0),
            ),
        };
        frame(&mut p, &cam, &mut r);
        assert_none_missing(&p, &cam);
        let rep = &p.report;
        assert!(rep.max_error <= budget, "frame {k}: {rep:?}");
        assert_eq!(rep.over_budget, 0, "frame {k}: {rep:?}");
        for (u, n) in used.iter_mut().zip(&rep.counts) {
            *u += n;
        }
    }
    eprintln!("object-frames by geometry, impostors, layers: {used:?}");
    assert!(used.iter().all(|&n| n > 0), "{used:?}");
}

#[test]
fn release_frees_a_layers_memory() {
    // Releasing one layer frees exactly its image.
    let mut set = LayerSet::new(Config::default(), 16);
    let mut objects = tori();
    let light = lighting();
    let cam = slid(0.0);
    let view = FrameView::still(&cam, W, H, &light);
    type Rep = dyn Representation<MeshGroup>;
    Rep::rebuild(&mut set, &[3, 5], &mut objects, &view);
    let both = Rep::memory(&set);
    let (w, h) = set.layers[5].image_size().expect("an image");
    Rep::release(&mut set, 5);
    assert_eq!(Rep::memory(&set), both - (w * h * 4 * 4 / 3) as usize);
    assert!(set.layers[5].image_size().is_none() && set.layers[3].image_size().is_some());
}
