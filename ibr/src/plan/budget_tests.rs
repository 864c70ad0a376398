//! The planner's budgets and promises, continued: the time budget, measured error within
//! the error budget, thread counts, odd views, the debug tints and the frame budget.

use super::tests::*;
use super::*;
use crate::core::screen_rect;
use crate::core::MeshGroup;
use crate::core::{image_bytes, Geometry, Representation};
use crate::metrics::{self, Options, Region};
use crate::techniques::impostors::{self as impostor, ImpostorSet};
use crate::techniques::layers::{self, LayerSet};
use engine::{Camera, Renderer};
use glam::Vec3;

#[test]
fn a_time_budget_moves_objects_to_images_and_reports_their_error() {
    let mut p = planner(budgets(0.0, 16));
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    // With a generous error budget first, so every object has an image.
    p.config.budgets.error = 1e9;
    for _ in 0..3 {
        frame(&mut p, &cam, &mut r);
    }
    // A zero error budget wants geometry everywhere; a time budget of a third of that
    // frame's predicted time forces images, least error first.
    p.config.budgets.error = 0.0;
    p.config.budgets.rebuilds = 0;
    frame(&mut p, &cam, &mut r);
    let full = p.report.predicted_ms();
    assert_eq!(p.report.counts[IMAGES], 0);
    p.config.budgets.time_ms = Some(full / 3.0);
    frame(&mut p, &cam, &mut r);
    let rep = p.report.clone();
    assert!(rep.predicted_ms() <= full / 3.0, "{rep:?}");
    assert!(
        rep.counts[IMAGES] > 0 && rep.counts[GEOMETRY] > 0,
        "{rep:?}"
    );
    assert_eq!(rep.over_time, rep.counts[IMAGES], "{rep:?}");
    assert_none_missing(&p);
    // Those moved are the ones whose images err least per millisecond saved: each one
    // left as geometry would add at least as much error per millisecond.
    let nr = 2;
    let ratio = |v: usize| {
        let est = estimates(&p.seen, &p.at, nr, v);
        let (g, im) = (est[0].unwrap(), est[1].unwrap());
        let saved = g.ms - im.ms;
        im.error * p.pixels_of(v) / saved
    };
    let (mut moved, mut kept) = (Vec::new(), Vec::new());
    for (v, &i) in p.visible.iter().enumerate() {
        match p.choices()[i].rep {
            Some(IMAGES) => moved.push(ratio(v)),
            _ => kept.push(ratio(v)),
        }
    }
    let most = moved.iter().copied().fold(0.0, f32::max);
    let least = kept.iter().copied().fold(f32::INFINITY, f32::min);
    assert!(most <= least, "moved up to {most}, kept from {least}");
}

#[test]
fn images_it_chooses_err_within_the_budget_when_measured() {
    let budget = 6.0;
    let mut p = planner(budgets(budget, 16));
    let mut r = Renderer::new();
    let (mut images, mut worst) = (0, 0.0f64);
    for k in 0..12 {
        let cam = view_at(0.05 * k as f32);
        let got = frame(&mut p, &cam, &mut r);
        assert!(p.report.max_error <= budget, "{:?}", p.report);
        let want = truth(&p, &cam, &mut r);
        // Each image, over its object's screen rectangle (neighbours' errors included).
        for (i, c) in p.choices().iter().enumerate() {
            if c.rep != Some(IMAGES) {
                continue;
            }
            images += 1;
            let b = p.objects[i].bounds();
            let rect = screen_rect(&cam, b.center, b.radius, W, H).unwrap();
            let opts = Options {
                region: Region::Rect(rect),
                ..Options::default()
            };
            let e = metrics::compare(&want, &got, &opts).unwrap();
            worst = worst.max(e.mean_abs);
            assert!(
                e.mean_abs <= f64::from(budget),
                "frame {k}, object {i}: {e:?} {c:?}"
            );
        }
    }
    assert!(images > 40, "{images} images");
    eprintln!("worst measured {worst:.2} levels against a budget of {budget}");
}

#[test]
fn the_same_frames_give_the_same_pixels_on_one_and_two_threads() {
    let cams: Vec<Camera> = (0..6).map(|k| view_at(0.2 * k as f32)).collect();
    let run = |threads| fly_on_threads(threads, || planner(budgets(2.0, 3)), &cams);
    assert!(run(1) == run(2));
}

#[test]
fn odd_views_neither_panic_nor_choose_nan() {
    let mut p = planner(budgets(2.0, 4));
    let mut r = Renderer::new();
    // Inside an object, at a NaN eye, with an empty target.
    let inside = camera(Vec3::new(-3.0, 0.0, 0.1), Vec3::new(-3.0, 0.0, -5.0));
    frame(&mut p, &inside, &mut r);
    assert_none_missing(&p);
    let nan = camera(Vec3::NAN, Vec3::ZERO);
    frame(&mut p, &nan, &mut r);
    let light = lighting();
    let cam = view_at(0.0);
    p.plan(&FrameView::still(&cam, 0, 0, &light));
    assert!(!p.report.mean_error.is_nan(), "{:?}", p.report);
    // An empty planner.
    let mut empty =
        Planner::<MeshGroup>::new(Config::default(), Vec::new(), vec![Box::new(Geometry)]);
    empty.plan(&FrameView::still(&cam, W, H, &light));
    assert_eq!(empty.report.counts, vec![0]);
}

#[test]
fn tints_colour_each_representation_and_off_restore_the_frame_exactly() {
    let objects = tori();
    let n = objects.len();
    let reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
        Box::new(Geometry),
        // Impostors of 64 texels a side, room for four of them: the other objects are
        // layers (smaller images) or geometry.
        Box::new(ImpostorSet::new(
            impostor::Config {
                min_side: 64,
                max_side: 64,
                ..impostor::Config::default()
            },
            n,
        )),
        Box::new(LayerSet::new(layers::Config::default(), n)),
    ];
    let config = Config {
        budgets: Budgets {
            memory: Some(4 * image_bytes(64, 64)),
            ..budgets(8.0, 6)
        },
        ..Config::default()
    };
    let mut p = Planner::new(config, objects, reps);
    let mut r = Renderer::new();
    let cam = view_at(0.0);
    // Three frames of six rebuilds make a mix of all three; then no more rebuilds, so the
    // choices stay.
    for _ in 0..3 {
        frame(&mut p, &cam, &mut r);
    }
    p.config.budgets.rebuilds = 0;
    frame(&mut p, &cam, &mut r);
    let plain = frame(&mut p, &cam, &mut r).to_rgba8();
    let counts = p.report.counts.clone();
    assert!(counts.iter().all(|&k| k > 0), "{counts:?}");
    assert!(!p.tints());
    p.set_tints(true);
    assert!(p.tints());
    let tinted = frame(&mut p, &cam, &mut r).to_rgba8();
    assert_eq!(p.report.counts, counts);
    // Each object's draws: geometry with the flat material of the first colour, images
    // multiplied by their representation's.
    let mut draws = Vec::new();
    p.draws(&mut draws);
    for (i, c) in p.choices().iter().enumerate() {
        let Some(k) = c.rep else { continue };
        let mut own = Vec::new();
        p.representation(k)
            .unwrap()
            .draw(i, &p.objects[i], p.eye, &mut own);
        for d in &own {
            let m = draws
                .iter()
                .find(|e| std::ptr::eq(e.mesh, d.mesh))
                .unwrap()
                .material;
            if k == GEOMETRY {
                assert_eq!(m.base_color, tint(0).1);
                assert!(m.base_texture.is_none() && !m.vertex_colors);
                assert_eq!(m.shading, engine::Shading::Unlit);
            } else {
                assert_eq!(m.base_color, tint(k).1, "object {i} by {k}");
            }
        }
    }
    // Geometry shows flat white; nothing was white before.
    let white = |t: &[u8]| t.chunks_exact(4).filter(|p| p[..3] == [255; 3]).count();
    assert_eq!(white(&plain), 0);
    assert!(white(&tinted) > 100, "{}", white(&tinted));
    // Images tinted: an impostor's pixels keep their green and lose red and blue, a
    // layer's keep their blue and lose red and green.
    let turned = |keep: usize, lose: usize| {
        let f = |(p, q): (&[u8], &[u8])| {
            q[keep].abs_diff(p[keep]) <= 3 && q[0] + 20 < p[0] && q[lose] + 10 < p[lose]
        };
        plain
            .chunks_exact(4)
            .zip(tinted.chunks_exact(4))
            .filter(|&pq| f(pq))
            .count()
    };
    let (green, blue) = (turned(1, 2), turned(2, 1));
    assert!(
        green > 50 && blue > 50,
        "{green} pixels turned green, {blue} blue"
    );
    p.set_tints(false);
    let again = frame(&mut p, &cam, &mut r).to_rgba8();
    assert!(again == plain, "turning the tints off restores the frame");
}

#[test]
fn a_frame_budget_bounds_the_weighted_mean_and_costs_no_more_than_per_object() {
    let overlap = std::cell::Cell::new(1.0f32);
    let run = |scope: Scope, error: f32, spread: f32| {
        let mut p = planner(Budgets {
            scope,
            ..budgets(error, 16)
        });
        p.config.spread = spread;
        let mut r = Renderer::new();
        for k in 0..8 {
            frame(&mut p, &view_at(0.1 * k as f32), &mut r);
            assert_none_missing(&p);
        }
        let weight: f32 = p.weights().1.iter().sum();
        overlap.set(weight / p.report.covered.max(1) as f32);
        p.report.clone()
    };
    for spread in [0.0, SPREAD] {
        // Every object within `error / (1 + 2.3 spread) / k` keeps the bound within
        // `error`, `k` the objects' weights over the pixels they cover (the spread term is
        // at most the mean's; `k` is over 1 where rectangles overlap), so the frame scope,
        // choosing the cheapest plan whose bound fits, costs no more.
        let strict = 1.0 + 2.326 * spread;
        for error in [0.0, 2.0, 4.0, 8.0] {
            let whole = run(Scope::Frame, error, spread);
            let k = 1.0f32.max(overlap.get());
            let object = run(Scope::Object, error / strict / k, spread);
            // The frame's bound is within the budget, the mean within the bound, and it
            // is reported over nothing.
            assert!(whole.bound <= error + 1e-4, "{error}: {whole:?}");
            assert!(whole.mean_error <= whole.bound + 1e-4, "{error}: {whole:?}");
            assert_eq!(whole.over_budget, 0, "{error}: {whole:?}");
            // (Within 1%: an image's draw is priced by its own quad, trimmed to what its
            // capture covered, so the same choices taken at other frames differ a little.)
            assert!(
                whole.draw_ms <= object.draw_ms * 1.01 + 1e-6,
                "{error}: {whole:?} {object:?}"
            );
            if error == 0.0 {
                assert_eq!(whole.counts[IMAGES], 0);
            }
        }
    }
}
