use super::{near, SPRITE_ELEVATIONS, SPRITE_PX};
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

/// A forest tree seen from ever higher, from 10 degrees below the horizon (the trees on the
/// hills seen from the plaza) to 85 degrees: its quad always
/// faces the eye (never foreshortened, so it never lies on its side) and shows the view
/// baked from the elevation nearest the eye's (within half the bakes' spacing).
#[test]
fn forest_trees_show_the_view_baked_nearest_the_eye_from_any_elevation() {
    use ibr::billboard::{corners, View};
    let show = Showcase::new();
    let tree = show.ibr.forest_billboards()[0][0];
    let views = &show.ibr.forest[0].atlas;
    let spacing = SPRITE_ELEVATIONS[1] - SPRITE_ELEVATIONS[0];
    let (w, h) = (1280, 720);
    for step in -10..=85 {
        let elevation = (step as f32).to_radians();
        let eye = tree.position + 40.0 * Vec3::new(elevation.cos(), elevation.sin(), 0.3);
        assert!(!near(&tree, eye), "{step} degrees: drawn as a mesh");
        let view = View::new(&camera(eye, tree.position, w, h), h);
        let (q, _) = corners(&tree, &view).expect("a world-facing quad is always drawn");
        let normal = (q[1] - q[0]).cross(q[3] - q[0]).normalize();
        let facing = normal.dot((eye - tree.position).normalize()).abs();
        assert!(
            facing > 0.999,
            "{step} degrees: the quad turns {facing} to the eye"
        );
        let seen = (eye - tree.position).normalize().y.asin().to_degrees();
        let (_, row) = views.cell(eye - tree.position);
        let baked = SPRITE_ELEVATIONS[row];
        assert!(
            (baked - seen).abs() <= spacing * 0.5 + 1e-3,
            "{step} degrees: seen from {seen}, shows the view from {baked}"
        );
    }
}

/// Over the tour at 1280 x 720, no forest tree drawn as a sprite is magnified (taller on
/// screen than its view's texels: the height in pixels from the camera's own field of
/// view and the tree's depth): those near enough to be are drawn as their meshes
/// ([`near`]), and the path does come that near some.
#[test]
fn over_the_tour_no_forest_sprite_is_magnified() {
    use ibr::billboard::Size;
    let show = Showcase::new();
    let (w, h, n) = (1280, 720, 120);
    let (mut meshes, mut seen) = (0, 0);
    for i in 0..n {
        let (eye, look) = show.path(i, n);
        let cam = camera(eye, look, w, h);
        let engine::Projection::Perspective { fov_y, .. } = cam.projection else {
            panic!("the tour's camera is a perspective one");
        };
        let px_per_unit_at_1 = h as f32 * 0.5 / (fov_y * 0.5).tan();
        let forward = (look - eye).normalize();
        for b in show.ibr.forest_billboards().iter().flatten() {
            let Size::World(size) = b.size else {
                panic!("forest trees are world-sized")
            };
            let depth = (b.position - eye).dot(forward);
            // Only trees whose centre is on screen.
            let off = b.position - eye - forward * depth;
            if depth <= 0.1 || off.length() * px_per_unit_at_1 / depth > w as f32 * 0.5 {
                continue;
            }
            if near(b, eye) {
                meshes += 1;
                continue;
            }
            seen += 1;
            let px = size.y * px_per_unit_at_1 / depth;
            assert!(px <= SPRITE_PX as f32, "frame {i}: a sprite {px} px tall");
        }
    }
    eprintln!("tree sightings {seen} as sprites, {meshes} as meshes");
    assert!(seen > 1000 && meshes > 0, "{seen} {meshes}");
}

/// The tree views are baked under the light the forest receives: the sun and the ambient,
/// no point light (the bake stands the tree at the origin, where the showcase's lamp
/// orbits), and no point light of the scene reaches any tree where it stands, so the
/// meshes there are lit by the sun and the ambient alone, as their views were baked.
#[test]
fn no_point_light_reaches_the_forest() {
    use engine::Light;
    let show = Showcase::new();
    let lighting = &show.scene.lighting;
    let baked = super::bake_lighting(lighting);
    assert_eq!(baked.ambient, lighting.ambient);
    let suns = |l: &engine::Lighting| {
        l.lights
            .iter()
            .filter(|l| matches!(l, Light::Directional { .. }))
            .count()
    };
    assert_eq!(suns(&baked), suns(lighting));
    assert!(suns(&baked) >= 1 && baked.lights.len() == suns(&baked));
    let mut points = 0;
    for light in &lighting.lights {
        if let Light::Point {
            position, range, ..
        } = light
        {
            points += 1;
            for (kind, at) in &show.ibr.trees.trees {
                let b = show.ibr.trees.bounds[*kind];
                let scale = at.x_axis.truncate().length();
                let centre = at.transform_point3(b.center);
                let gap = centre.distance(*position) - b.radius * scale;
                assert!(
                    gap > *range,
                    "a point light reaches a tree: {gap} < {range}"
                );
            }
        }
    }
    assert!(points > 0, "the showcase has its lamp");
}

/// The forest's bands split both tree kinds at the same distances from the eye: each
/// sprite in one band, every sprite of band `b` of either kind no farther than every
/// sprite of band `b + 1` of either, the bands about equal shares of all the sprites.
#[test]
fn the_forests_bands_split_both_kinds_at_the_same_distances() {
    use super::bands::split;
    use engine::procedural::XorShift;
    use glam::Vec2;
    use ibr::billboard::ViewAtlas;
    use ibr::{Billboard, Facing};
    let eye = Vec3::new(1.0, 2.0, 3.0);
    let mut rng = XorShift::new(7);
    let kinds: Vec<Vec<Billboard>> = [300, 200]
        .map(|n| {
            let mut items: Vec<Billboard> = (0..n)
                .map(|_| {
                    let at = Vec3::new(rng.range(-50.0, 50.0), 0.0, rng.range(-50.0, 50.0));
                    Billboard::new(at, Facing::World { up: Vec3::Y }, Vec2::ONE)
                })
                .collect();
            ViewAtlas::order(&mut items, eye);
            items
        })
        .into();
    let d = |b: &Billboard| b.position.distance_squared(eye);
    let mut all: Vec<f32> = kinds.iter().flatten().map(d).collect();
    all.sort_unstable_by(f32::total_cmp);
    let n = 8;
    let ends: Vec<Vec<usize>> = kinds
        .iter()
        .map(|k| {
            let mut e = vec![99];
            split(k, eye, &all, n, &mut e);
            e
        })
        .collect();
    for (k, e) in kinds.iter().zip(&ends) {
        assert_eq!(e.len(), n);
        assert!(e.windows(2).all(|w| w[0] <= w[1]), "{e:?}");
        assert_eq!(e[n - 1], k.len());
    }
    let band = |k: usize, b: usize| {
        let start = if b == 0 { 0 } else { ends[k][b - 1] };
        &kinds[k][start..ends[k][b]]
    };
    for b in 0..n {
        let sprites = band(0, b).len() + band(1, b).len();
        assert!(sprites.abs_diff(500 / n) <= 1, "band {b}: {sprites}");
        if b + 1 < n {
            let far = (0..2).flat_map(|k| band(k, b)).map(d).fold(0.0, f32::max);
            let near = (0..2).flat_map(|k| band(k, b + 1)).map(d);
            assert!(near.fold(f32::MAX, f32::min) >= far, "band {b}");
        }
    }
}
