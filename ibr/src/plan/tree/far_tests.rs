//! The far field against the cut: every object in view drawn exactly once, by one or the
//! other, the field's objects those beyond its distance, and its per-frame capture budget
//! (counters, not time).

use super::tests::{camera, drawn, hierarchy, plan};
use super::*;
use crate::core::Frustum;
use glam::Vec3;

/// The tests' far field: beyond 30 units, 4 x 4 tiles, 200,000 triangles (400 balls) a frame.
fn far() -> FarConfig {
    FarConfig {
        distance: 30.0,
        tiles: 4,
        triangles: 200_000,
        loading_triangles: 200_000,
        parallax: 24.0,
        ..FarConfig::default()
    }
}

fn config() -> TreeConfig {
    TreeConfig {
        rebuilds: 40,
        far: Some(far()),
        ..TreeConfig::default()
    }
}

/// The eye of frame `f`: gliding sideways over the near edge of a 96-wide field.
fn eye(f: usize) -> Vec3 {
    Vec3::new(f as f32 * 0.5 - 12.0, 12.0, 50.0)
}

#[test]
fn the_far_field_and_the_cut_draw_every_object_in_view_exactly_once() {
    let mut h = hierarchy(96, config());
    let (mut shown, mut far_total) = (0, 0);
    for f in 0..80 {
        let cam = camera(eye(f), 96);
        let r = plan(&mut h, &cam);
        let far = h.far().expect("configured");
        let mut times = drawn(&h);
        let mut captured = vec![false; h.objects().len()];
        far.captured().for_each(|i| captured[i as usize] = true);
        let frustum = Frustum::new(cam.clip_from_world());
        let Some(split) = far.split() else {
            assert_eq!(r.far_objects, 0);
            continue;
        };
        shown += 1;
        for (i, c) in captured.iter().enumerate() {
            let b = h.objects()[i].bounds();
            if *c {
                // The field's objects lie beyond its distance, as measured here.
                assert!(b.center.distance(split.eye) > split.distance - 1e-3, "{i}");
                if frustum.sees(b.center, b.radius) {
                    times[i] += 1;
                    far_total += 1;
                }
            }
            if frustum.sees(b.center, b.radius) {
                assert_eq!(times[i], 1, "object {i} at frame {f}: {r:?}");
            } else {
                assert!(times[i] <= 1, "object {i} at frame {f}");
            }
        }
        assert!(r.far_objects > 0 && r.far.shown, "{r:?}");
    }
    // A field was shown for most frames, and its objects were many.
    assert!(shown > 40 && far_total > 1000, "{shown} {far_total}");
}

#[test]
fn the_far_capture_budget_holds_every_frame() {
    let mut h = hierarchy(96, config());
    let budget = far().triangles;
    let (mut tiles, mut over_one, mut swaps) = (0, 0, 0);
    for f in 0..80 {
        let r = plan(&mut h, &camera(eye(f), 96));
        let far = r.far;
        // Within the budget, or one tile alone (split to a pixel and still over).
        assert!(
            far.triangles <= budget || far.tiles == 1,
            "frame {f}: {far:?}"
        );
        tiles += far.tiles;
        over_one += usize::from(far.tiles > 1);
        swaps = far.swaps;
    }
    // The captures were spread over frames, several tiles in some, and fields completed.
    assert!(
        tiles > 16 && over_one > 0 && swaps >= 2,
        "{tiles} {over_one} {swaps}"
    );
}

#[test]
fn the_split_sides_agree_with_their_objects() {
    let cam = camera(Vec3::new(0.0, 12.0, 50.0), 96);
    let split = Split {
        eye: cam.eye(),
        distance: 30.0,
        frustum: Frustum::new(cam.clip_from_world()),
    };
    let unit = |c: Vec3| (c - Vec3::splat(0.5), c + Vec3::splat(0.5));
    // Near the eye: nobody's; far and in view: the field's; across the distance: some.
    let near = unit(Vec3::new(0.0, 0.5, 40.0));
    let far = unit(Vec3::new(0.0, 0.5, -10.0));
    assert_eq!(split.side(near.0, near.1), Side::Near);
    assert!(!split.is_far(near));
    assert_eq!(split.side(far.0, far.1), Side::Far);
    assert!(split.is_far(far));
    let across = (Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 40.0));
    assert_eq!(split.side(across.0, across.1), Side::Across);
    // Behind the eye, however far: not the field's (outside its frustum).
    let behind = unit(Vec3::new(0.0, 0.5, 200.0));
    assert_eq!(split.side(behind.0, behind.1), Side::Near);
    assert!(!split.is_far(behind));
}
