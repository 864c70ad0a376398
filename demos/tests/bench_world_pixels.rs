//! The world of `bench budget --scene world` at two target sizes and with its ground cut in
//! pieces (issue 41): the per-node planner's pixel settings scale with the target's height,
//! so 1280x720 cuts the hierarchy as 640x360 does instead of opening it deeper; and the
//! cut ground draws the same pixels as one plate while shading fewer fragments, the
//! objects standing on it hiding it before it is shaded; the node images drawn as cutouts
//! shade fewer fragments than blended ones, none blended, at the same error against all
//! the geometry. Counters from the planner's cut and the renderer, against the unscaled
//! planner, the single plate and the blended images.

use demos::city::ground;
use demos::world::{
    tiled_ground, tree_planner, tree_planner_drawing, tree_side, TreePlan, World, GROUND_TILES,
    TREE_CUTOUT, TREE_SIDE,
};
use engine::{FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::metrics::{self, Options};
use ibr::plan::tree::TreeReport;
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};

/// The planner made for a `planned`-pixel-high target, its cut of the world seen by a
/// `size` target after 5 frames (the loading frames, which take the images), the eye a
/// tenth into the fly-over.
fn cut(world: &World, size: (u32, u32), planned: u32) -> TreeReport {
    let plan = TreePlan::for_tests(world, planned);
    let mut planner = tree_planner(world.objects.clone(), plan);
    let camera = world.camera(0.1, size);
    for _ in 0..5 {
        planner.plan(&FrameView::still(&camera, size.0, size.1, &world.lighting));
    }
    planner.report
}

/// At 1280x720 the planner made for it draws about as many objects as geometry, and as
/// many images, as at 640x360 (the same nodes, each image twice the texels a side); the
/// planner made for 640x360 opens the hierarchy deeper there (every node twice as wide on
/// screen against the same texel cap) and draws more objects as geometry.
#[test]
fn a_taller_target_cuts_the_world_as_640x360() {
    assert_eq!(tree_side(96), TREE_SIDE, "never below the cap as given");
    assert_eq!(tree_side(720), 2 * TREE_SIDE);
    let world = World::new(32, 11);
    let small = cut(&world, (640, 360), 360);
    let large = cut(&world, (1280, 720), 720);
    let unscaled = cut(&world, (1280, 720), 360);
    assert!(small.images > 0 && small.geometry > 0, "{small:?}");
    let near = |a: usize, b: usize| a.abs_diff(b) as f32 <= 0.1 * b as f32 + 4.0;
    assert!(near(large.geometry, small.geometry), "{large:?}\n{small:?}");
    assert!(near(large.images, small.images), "{large:?}\n{small:?}");
    assert!(
        unscaled.geometry as f32 > 1.3 * large.geometry as f32,
        "unscaled {unscaled:?}\nscaled {large:?}"
    );
}

/// The world's objects on `ground`, rendered at 320 x 180 from the fly-over a tenth in.
fn render(world: &World, ground: &MeshGroup) -> (Target, FrameStats) {
    let (w, h) = (320, 180);
    world.render_geometry(ground, &world.camera(0.1, (w, h)), (w, h))
}

/// The world's ground, [`GROUND_TILES`] x [`GROUND_TILES`] pieces of two triangles, draws
/// the pixels of the single plate of the same side and colour: no crack between pieces
/// (the sky's pixels are the same), the frames within a fraction of a level; and shades
/// at least a tenth fewer fragments, what stands on the ground hiding it first.
#[test]
fn the_cut_ground_draws_the_plate_and_shades_less() {
    let world = World::new(16, 11);
    assert_eq!(
        world.ground.parts.len(),
        (GROUND_TILES * GROUND_TILES) as usize
    );
    assert!(world
        .ground
        .parts
        .iter()
        .all(|p| p.mesh.triangle_count() == 2));
    let side = world.half_extent * 2.2;
    let plate = ground(side, Rgba::from_srgb8(92, 104, 84));
    let (one, one_stats) = render(&world, &plate);
    let (cut, cut_stats) = render(&world, &world.ground);
    let sky = |t: &Target| {
        let rgba = t.to_rgba8();
        let first = one.to_rgba8()[..4].to_vec();
        rgba.chunks_exact(4).filter(|p| *p == &first[..]).count()
    };
    assert_eq!(sky(&cut), sky(&one), "the pieces leave no crack");
    let e = metrics::compare(&one, &cut, &Options::default()).expect("same size");
    assert!(e.mean_abs < 0.05, "{e:?}");
    let again = tiled_ground(side, Rgba::from_srgb8(92, 104, 84), GROUND_TILES);
    assert_eq!(render(&world, &again).1, cut_stats, "deterministic");
    let (a, b) = (one_stats.fragments_shaded, cut_stats.fragments_shaded);
    assert!(b * 10 < a * 9, "plate {a}, pieces {b}");
}

/// The world seen by the planner drawing its node images as cutouts at `cutout` (or
/// blended) at 320 x 180 after its 4 loading frames and one more, and the frame's mean
/// absolute difference from all the geometry, levels.
fn planned_frame(world: &World, cutout: Option<f32>) -> (FrameStats, f64) {
    let (w, h) = (320, 180);
    let plan = TreePlan::for_tests(world, h);
    let mut planner = tree_planner_drawing(world.objects.clone(), plan, cutout);
    let camera = world.camera(0.1, (w, h));
    let view = FrameView::still(&camera, w, h, &world.lighting);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..FrameOptions::default()
    };
    let mut ground = Vec::new();
    world.ground.draws(&mut ground);
    let (mut renderer, mut frames) = (Renderer::new(), FrameLoop::new());
    let (mut target, mut stats) = (Target::new(w, h), FrameStats::default());
    for _ in 0..5 {
        let techniques: &mut [&mut dyn Technique] = &mut [&mut planner];
        let (g, r) = (ground.iter().copied(), &mut renderer);
        stats = frames.render(r, g, techniques, &view, &mut target, &opts);
    }
    let (truth, _) = render(world, &world.ground);
    let e = metrics::compare(&truth, &target, &Options::default()).expect("same size");
    (stats, e.mean_abs)
}

/// The node images as cutouts ([`TREE_CUTOUT`]): none of the frame's fragments is
/// blended, fewer are shaded than with the images blended (the ground and farther images
/// behind an opaque image are rejected first), and the frame is as near all the geometry
/// as the blended one (within a tenth of a level).
#[test]
fn cutout_node_images_shade_fewer_fragments_at_the_same_error() {
    let world = World::new(32, 11);
    let (cut, cut_error) = planned_frame(&world, Some(TREE_CUTOUT));
    let (blended, blended_error) = planned_frame(&world, None);
    assert!(blended.fragments_shaded_blended > 0, "{blended:?}");
    assert_eq!(cut.fragments_shaded_blended, 0, "{cut:?}");
    let (a, b) = (blended.fragments_shaded, cut.fragments_shaded);
    assert!(b < a, "blended {a}, cutouts {b}");
    assert!(
        cut_error <= blended_error + 0.1,
        "{cut_error} {blended_error}"
    );
}
