use super::SPRITE_PX;
use crate::showcase::{camera, Showcase, SKY};
use engine::{FrameOptions, Renderer, Target};
use glam::Vec3;
use ibr::flare::{self, FlareSource};

/// Renders `frames` showcase frames a tenth of a second apart from `eye` looking at the sun;
/// returns the flare's depth-only visibility of the last frame (what the depth buffer alone
/// would say), the flare's measured visibility and its quad count.
fn sun_view(show: &mut Showcase, eye: Vec3, frames: u32) -> (f32, f32, usize) {
    let FlareSource::Directional(l) = show.ibr.sun() else {
        panic!("the showcase's sun is directional")
    };
    let (w, h) = (320, 200);
    let cam = camera(eye, eye + l, w, h);
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    };
    for k in 0..frames {
        show.animate(1.0 + 0.1 * k as f32);
        show.render(&mut renderer, &cam, &mut target, &opts);
    }
    let f = show.ibr.flare();
    let light = flare::project(&cam, show.ibr.sun(), w, h).expect("the sun is in view");
    let depth_only = flare::occlusion(&target, &light, f.samples, f.radius_px);
    (depth_only, f.measured(), f.quad_count())
}

#[test]
fn the_sun_behind_the_impostored_skyline_shows_no_flare() {
    let mut show = Showcase::new();
    // Above the clouds the sun is in open sky: the flare shows.
    let (_, measured, quads) = sun_view(&mut show, Vec3::new(0.0, 60.0, 0.0), 4);
    assert!(measured > 0.95 && quads > 0, "{measured} {quads}");
    // In a street of the city district, low down, the sun stands behind buildings drawn as
    // images, which write depth where they are more than half covered: the depth buffer
    // alone sees them, and so does the flare's measure. (The planner is told triangles are
    // dear and error cheap, so it draws every building it can as an image; as it is, it
    // draws these near ones as geometry.)
    let city = &mut show.ibr.impostors.city.config;
    city.budgets.error = 1e6;
    city.cost.ns_per_triangle *= 1e3;
    let (depth_only, measured, quads) = sun_view(&mut show, Vec3::new(-43.4, 3.35, -4.53), 6);
    let city = &show.ibr.impostors.city.report;
    assert!(
        depth_only < 0.02 && city.counts[0] < city.counts.iter().sum::<usize>(),
        "images stand in front of the sun: {depth_only} {city:?}"
    );
    assert!(measured < 0.02, "{measured}");
    assert_eq!(quads, 0, "no flare is drawn");
}

/// The default headless tour (120 frames, as `showcase --headless` renders it, here at
/// 320x180): no frame shows an image over its tolerance (a cloud's) or budget (a
/// building's), the city is drawn as geometry and images, and clouds about to come into
/// view are refreshed ahead.
#[test]
fn the_tour_never_shows_an_impostor_over_its_tolerance() {
    let mut show = Showcase::new();
    let (w, h, n) = (320, 180, 120);
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    };
    for i in 0..n {
        show.animate(i as f32 / 30.0);
        let (eye, look) = show.path(i, n);
        let cam = camera(eye, look, w, h);
        show.render(&mut renderer, &cam, &mut target, &opts);
    }
    let run = show.ibr.impostors.run_stats();
    assert_eq!(run.frames, n);
    assert_eq!(run.frames_over_twice, 0, "{run:?}");
    assert!(
        run.frames_over * 100 <= n,
        "{} of {n} frames over",
        run.frames_over
    );
    assert!(run.max_ratio <= 1.0, "{}", run.max_ratio);
    assert_eq!(run.city_over_budget, 0, "{run:?}");
    let [geometry, impostors, layers] = run.city_frames;
    assert!(geometry > 0 && impostors + layers > 0, "{run:?}");
    assert!(run.city_rebuilds > 0 && run.prewarmed > 0, "{run:?}");
    assert!(run.refreshes > n, "{run:?}");
}

/// A forest tree seen from ever higher: its upright quad is drawn only while it is seen
/// nearly side on (foreshortened to no less than 0.7 of its height, the elevation taken
/// from the eye and the tree here), and the top-down sprite has taken over before then;
/// nowhere is the tree left undrawn.
#[test]
fn forest_trees_hand_over_to_the_top_sprite_before_they_lie_on_their_side() {
    use ibr::billboard::{corners, fade_pair, View};
    let show = Showcase::new();
    let tree = &show.ibr.forest[0].items[0];
    let centre = tree.position + Vec3::Y * 3.0;
    let (w, h) = (1280, 720);
    let (mut upright, mut top) = (0, 0);
    for step in 0..=80 {
        let elevation = (step as f32).to_radians();
        let eye = centre + 20.0 * Vec3::new(elevation.cos(), elevation.sin(), 0.0);
        let cam = camera(eye, centre, w, h);
        let view = View::new(&cam, h);
        let seen = (centre - eye).normalize();
        let squash = (1.0 - seen.y * seen.y).sqrt();
        if corners(tree, &view).is_some() {
            upright += 1;
            assert!(
                squash >= 0.7,
                "{step} degrees: upright drawn at {squash:.2} of its height"
            );
        }
        let basis = ibr::billboard::orient(tree.facing, &view, tree.position);
        let (side, flat) = fade_pair(basis.fade, true);
        assert!(side >= 1.0 || flat >= 1.0, "{step} degrees: {side} {flat}");
        if flat > 0.0 {
            top += 1;
        }
    }
    assert!(upright > 20 && top > 20, "{upright} {top}");
}

/// Over the tour at 1280 x 720, forest trees in view drawn with less than a texel per
/// screen pixel (taller on screen than their sprite's texels: the height in pixels from
/// the camera's own field of view and the tree's depth) are a small fraction of those the
/// old 96-texel sprites magnified. (Those left are the trees the path brushes past, which
/// would need their meshes.)
#[test]
fn over_the_tour_few_forest_sprites_are_magnified() {
    use ibr::billboard::Size;
    let show = Showcase::new();
    let (w, h, n) = (1280, 720, 120);
    let (mut over, mut over_old, mut seen) = (0, 0, 0);
    for i in 0..n {
        let (eye, look) = show.path(i, n);
        let cam = camera(eye, look, w, h);
        let engine::Projection::Perspective { fov_y, .. } = cam.projection else {
            panic!("the tour's camera is a perspective one");
        };
        let px_per_unit_at_1 = h as f32 * 0.5 / (fov_y * 0.5).tan();
        let forward = (look - eye).normalize();
        for b in show.ibr.forest.iter().flat_map(|f| &f.items) {
            let Size::World(size) = b.size else {
                panic!("forest trees are world-sized")
            };
            let mid = b.position + Vec3::Y * size.y * 0.5;
            let depth = (mid - eye).dot(forward);
            if depth <= 0.1 {
                continue;
            }
            let px = size.y * px_per_unit_at_1 / depth;
            // Only trees whose centre is on screen.
            let off = mid - eye - forward * depth;
            let across = off.length() * px_per_unit_at_1 / depth;
            if across > w as f32 * 0.5 {
                continue;
            }
            seen += 1;
            over += usize::from(px > SPRITE_PX as f32);
            over_old += usize::from(px > 96.0);
        }
    }
    eprintln!("tree sightings {seen}: magnified {over} at {SPRITE_PX} texels, {over_old} at 96");
    assert!(seen > 1000 && over_old > 0, "{seen} {over_old}");
    assert!(over * 10 <= over_old, "{over} of {over_old}");
}
