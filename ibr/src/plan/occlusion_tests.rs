//! The frame scope with what the last frame hid: objects behind a wall weigh nothing in the
//! frame's error, so they take the cheapest representation whatever its error, objects
//! behind others weigh what shows of them, and the frame's measured error stays within
//! its budget.

use super::tests::{budgets, lighting, planner, view_at, H, IMAGES, W};
use super::*;
use crate::core::screen_rect;
use crate::core::MeshGroup;
use crate::core::{FrameLoop, Technique};
use crate::metrics::{self, Options, Region};
use engine::Rgba;
use engine::{procedural, FrameOptions, Mesh, Renderer};
use glam::{Mat4, Vec3};

/// A wall covering the tori left of x = 0 from [`view_at`]`(0)`: 6 x 6, its right edge
/// at x = 0, at z = 1.5 (in front of the grid's nearest row, at z = 0).
fn wall() -> (Mesh, Material) {
    let mesh = procedural::cuboid(Vec3::new(6.0, 6.0, 0.1));
    (mesh, Material::lit(Rgba::new(0.8, 0.7, 0.6, 1.0)))
}

/// The wall's draw.
fn wall_draw(wall: &(Mesh, Material)) -> Draw<'_> {
    Draw {
        mesh: &wall.0,
        material: &wall.1,
        transform: Mat4::from_translation(Vec3::new(-3.0, 0.0, 1.5)),
    }
}

/// One frame of the planner with the wall; returns the target.
fn frame_behind(p: &mut Planner<MeshGroup>, wall: &(Mesh, Material), r: &mut Renderer) -> Target {
    let (cam, light) = (view_at(0.0), lighting());
    let view = FrameView::still(&cam, W, H, &light);
    let mut target = Target::new(W, H);
    let scene = [wall_draw(wall)];
    let mut techniques: [&mut dyn Technique; 1] = [p];
    let opts = FrameOptions::default();
    FrameLoop::new().render(r, scene, &mut techniques, &view, &mut target, &opts);
    target
}

#[test]
fn objects_behind_a_wall_weigh_nothing_and_take_the_cheapest_representation() {
    let wall = wall();
    let mut p = planner(Budgets {
        scope: Scope::Frame,
        ..budgets(0.5, 16)
    });
    let mut r = Renderer::new();
    for _ in 0..4 {
        frame_behind(&mut p, &wall, &mut r);
    }
    let left: Vec<usize> = (0..16).filter(|k| k % 4 < 2).collect();
    let (visible, weights) = p.weights();
    for (&i, &w) in visible.iter().zip(weights) {
        let b = p.objects[i].bounds();
        if left.contains(&i) {
            assert_eq!(w, 0.0, "object {i} behind the wall");
            assert_eq!(p.choices()[i].rep, Some(IMAGES), "object {i}");
        } else {
            assert!(w > 0.0, "object {i} at {:?}", b.center);
        }
    }
    // In the right half, the rows behind show between the ones in front: the last row
    // weighs under half of its rectangle, the first all of it.
    let share = |i: usize| {
        let b = p.objects[i].bounds();
        let r = screen_rect(&view_at(0.0), b.center, b.radius, W, H).unwrap();
        let k = visible.iter().position(|&v| v == i).unwrap();
        weights[k] / (r.width * r.height) as f32
    };
    assert!(
        share(2) == 1.0 && share(3) == 1.0,
        "{} {}",
        share(2),
        share(3)
    );
    assert!(
        share(14) < 0.5 && share(15) < 0.5,
        "{} {}",
        share(14),
        share(15)
    );
    // The right half, in view, keeps the frame within its budget: most stay geometry.
    let shown: Vec<usize> = (0..16).filter(|k| k % 4 >= 2).collect();
    let images = shown
        .iter()
        .filter(|&&i| p.choices()[i].rep == Some(IMAGES))
        .count();
    assert!(images < shown.len(), "{images}");
    assert!(p.report.bound <= 0.5 + 1e-4, "{:?}", p.report);
    // Measured: the frame with the wall against all the geometry with the wall, over the
    // whole frame, is within the budget.
    let got = frame_behind(&mut p, &wall, &mut r);
    let mut all = vec![wall_draw(&wall)];
    p.reference(&mut all);
    let mut want = Target::new(W, H);
    r.render(
        all,
        &view_at(0.0),
        &lighting(),
        &mut want,
        &FrameOptions::default(),
    );
    let opts = Options {
        region: Region::All,
        ..Options::default()
    };
    let e = metrics::compare(&want, &got, &opts).unwrap();
    assert!(e.mean_abs <= 0.5, "{e:?}");
}
