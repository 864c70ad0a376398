//! The far field against the cut: every object in view drawn exactly once, by one or the
//! other, the field's objects those beyond its distance, and its per-frame capture budget
//! (counters, not time).

use super::tests::{camera, drawn, hierarchy, plan, Ball, BALL_TRIANGLES};
use super::*;
use crate::core::Frustum;
use glam::Vec3;

/// The tests' far field: beyond 30 units, 4 x 4 tiles, 400 balls' triangles a frame.
fn far() -> FarConfig {
    FarConfig {
        distance: 30.0,
        tiles: 4,
        triangles: 400 * BALL_TRIANGLES,
        loading_triangles: 400 * BALL_TRIANGLES,
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
        if !r.far.shown {
            assert_eq!(r.far_objects, 0);
            continue;
        }
        shown += 1;
        for (i, c) in captured.iter().enumerate() {
            let b = h.objects()[i].bounds();
            if *c {
                // The field's objects lie beyond its distance, as measured here.
                let split = far.split_of(i).expect("a tile's");
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
    let (mut tiles, mut over_one, mut owned) = (0, 0, 0);
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
        owned = far.owned;
    }
    // The captures were spread over frames, several tiles in some, and the tiles shown
    // stand for many objects (the glide leaves each field's frustum before its last
    // slots, so fields are given up rather than completed: their tiles stay shown).
    assert!(
        tiles > 16 && over_one > 0 && owned > 1000,
        "{tiles} {over_one} {owned}"
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

/// Per object in view, how many times the frame draws it: by the cut, or by the shown tile
/// standing for it.
fn times_in_view(h: &Hierarchy<Ball>, cam: &engine::Camera) -> Vec<(usize, usize)> {
    let far = h.far().expect("configured");
    let mut times = drawn(h);
    far.captured().for_each(|i| times[i as usize] += 1);
    let frustum = Frustum::new(cam.clip_from_world());
    (0..times.len())
        .filter(|&i| {
            let b = h.objects()[i].bounds();
            frustum.sees(b.center, b.radius)
        })
        .map(|i| (i, times[i]))
        .collect()
}

#[test]
fn a_recapture_swaps_tiles_in_view_first_and_keeps_every_object_drawn_once() {
    // A field 2.5 times the view in 4 x 4 slots: the view sees the middle four only. The
    // first field is taken at once (loading); then the eye jumps 6 units sideways (36
    // pixels of parallax at 30 units) and the new field comes at 40 balls' triangles a
    // frame.
    let cfg = FarConfig {
        margin: 2.5,
        triangles: 40 * BALL_TRIANGLES,
        loading_triangles: 4_000_000,
        ..far()
    };
    let mut h = hierarchy(
        96,
        TreeConfig {
            rebuilds: 40,
            far: Some(cfg),
            ..TreeConfig::default()
        },
    );
    let (a, b) = (Vec3::new(-3.0, 12.0, 50.0), Vec3::new(3.0, 12.0, 50.0));
    let r = plan(&mut h, &camera(a, 96));
    assert!(r.far.swaps == 1 && r.far.pending == 0, "{r:?}");
    let cam = camera(b, 96);
    let frustum = Frustum::new(cam.clip_from_world());
    let (mut view_served, mut mixed, mut done) = (None, false, None);
    for f in 1..400 {
        let r = plan(&mut h, &cam);
        assert!(
            r.far.triangles <= cfg.triangles || r.far.tiles == 1,
            "frame {f}: {:?}",
            r.far
        );
        for (i, n) in times_in_view(&h, &cam) {
            assert_eq!(n, 1, "object {i} at frame {f}: {r:?}");
        }
        let far = h.far().expect("configured");
        // Which eye each object's tile was taken from: 0 the first, 1 the new, 2 none.
        let eyes: Vec<u8> = (0..h.objects().len())
            .map(|i| match far.split_of(i) {
                Some(s) if s.eye.distance(a) < 1e-3 => 0,
                Some(s) if s.eye.distance(b) < 1e-3 => 1,
                _ => 2,
            })
            .collect();
        mixed |= eyes.contains(&0) && eyes.contains(&1);
        // The objects whose centre the view holds, beyond 30 units of the new eye: all
        // the new field's yet?
        let served = (0..h.objects().len()).all(|i| {
            let c = h.objects()[i].bounds().center;
            !frustum.contains(c) || c.distance(b) <= 30.0 + 0.5 || eyes[i] == 1
        });
        if served && view_served.is_none() {
            view_served = Some((f, r.far.pending));
        }
        if r.far.swaps == 2 {
            done = Some(f);
            break;
        }
    }
    let (f, pending) = view_served.expect("the view's far objects served");
    let done = done.expect("the new field completed");
    // Served before the field was complete, with slots outside the view still to come;
    // old and new tiles were shown together on the way.
    assert!(pending > 0 && f < done, "{f} {pending} {done}");
    assert!(mixed);
}
