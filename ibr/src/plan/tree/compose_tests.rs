//! Node images composed of their children's images (Shade et al. 96's hierarchical image
//! cache, [`TreeConfig::compose`]): the capture draws the children's quads instead of
//! their objects, is priced so, and the image inherits the children's error (counters, not
//! time).

use super::tests::{camera, drawn, hierarchy, plan, Ball};
use super::*;
use glam::Vec3;

const SIDE: usize = 32;

/// A budget of 40 levels, children's images taken within all of it, and no rebuild or
/// payback limit (what is tested is what a rebuild draws and costs, not how many).
fn config(compose: f32) -> TreeConfig {
    TreeConfig {
        budget: 40.0,
        compose,
        rebuilds: 100_000,
        rebuild_ms: 1e9,
        payback: 1e9,
        ..TreeConfig::default()
    }
}

/// The field seen from `near`, then twice as far from what it looks at (every disc on
/// screen halves, so the cut closes: the parents of the nodes imaged first are rebuilt),
/// then from there again (the eye still).
fn back_off(compose: f32) -> (Hierarchy<Ball>, [TreeReport; 3]) {
    let mut h = hierarchy(SIDE, config(compose));
    let at = Vec3::new(0.0, 0.0, -(SIDE as f32) * 0.25);
    let near = Vec3::new(0.0, 5.0, 8.0);
    let far = at + (near - at) * 2.0;
    let first = plan(&mut h, &camera(near, SIDE));
    let second = plan(&mut h, &camera(far, SIDE));
    let third = plan(&mut h, &camera(far, SIDE));
    (h, [first, second, third])
}

#[test]
fn a_node_rebuilt_over_its_childrens_images_draws_their_quads_not_their_objects() {
    let (h, [first, second, _]) = back_off(1.0);
    let (_, [_, plain, _]) = back_off(0.0);
    assert!(first.images > 0 && first.composed == 0, "{first:?}");
    // The balls draw no triangles: whatever a capture drew is the children's quads, two
    // triangles each, one or two children a composed rebuild.
    assert!(second.composed > 0, "{second:?}");
    let quads = second.captured_triangles / 2;
    assert!(second.captured_triangles % 2 == 0, "{second:?}");
    assert!(
        quads >= second.composed && quads <= 2 * second.composed,
        "{second:?}"
    );
    // Each quad's texture is 1 x 1.
    assert_eq!(second.composed_texels, quads as u64, "{second:?}");
    // Without composing the same rebuilds draw the objects (nothing, here) and are priced
    // at their 500 triangles an object; composed, at two a child image.
    assert_eq!(
        (plain.composed, plain.captured_triangles),
        (0, 0),
        "{plain:?}"
    );
    assert!(plain.rebuilds > 0, "{plain:?}");
    let each = |r: &TreeReport| r.rebuild_ms / r.rebuilds as f32;
    assert!(each(&second) < each(&plain), "{second:?} {plain:?}");
    // The cut still draws every object once at most.
    assert!(drawn(&h).iter().all(|&n| n <= 1));
}

#[test]
fn a_composed_image_keeps_the_error_of_the_images_it_drew() {
    // The eye still from the second frame to the third: an image taken from there errs by
    // nothing of its own, a composed one by what its children's images erred by when it
    // was composed.
    let (_, [_, second, third]) = back_off(1.0);
    let (_, [_, _, plain]) = back_off(0.0);
    assert!(second.composed > 0, "{second:?}");
    assert!(third.mean_error > plain.mean_error, "{third:?} {plain:?}");
    assert!(third.max_error <= 40.0, "{third:?}");
}

#[test]
fn a_node_whose_childrens_images_will_do_is_opened_not_rebuilt() {
    // Backing off closes the cut: without composing, each node of the closer cut was
    // rebuilt from its objects (32 images, 32 rebuilds, before this rule). Where both of a
    // node's children still show within the budget as they are, the cut now draws them and
    // spends no rebuild on the node.
    let (h, [first, second, third]) = back_off(0.0);
    assert!(
        first.images > 0 && first.rebuilds == first.images,
        "{first:?}"
    );
    assert!(second.rebuilds > 0, "{second:?}");
    assert!(second.images > second.rebuilds, "{second:?}");
    assert!(second.max_error <= 40.0 && second.over == 0, "{second:?}");
    assert_eq!(third.rebuilds, 0, "{third:?}");
    assert!(drawn(&h).iter().all(|&n| n <= 1));
}
