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
