//! Frame cost follows pixels, not triangles, once impostors stand in for the geometry:
//! the work counters of impostor frames that refresh nothing are the same for a city of
//! 1k, 30k and 1M triangles (same silhouettes, same screen coverage) and grow with the
//! pixel count when the resolution doubles, while geometry frames set up triangles in
//! proportion to the scene. Counters only, no wall-clock timing (`bench scaling` times
//! the same frames). The impostor frames run through the one frame loop
//! (`ibr::technique::FrameLoop`, the city behind `Impostored`); the ground truth renders the
//! geometry the technique names as its reference.

use demos::city::{City, Path};
use engine::{Camera, Draw, FrameOptions, FrameStats, Renderer, Rgba, Target};
use ibr::impostor::{Config, Impostored, Mode};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};

const GRID: u32 = 8;
const SIZES: [(u32, u32); 3] = [(160, 90), (320, 180), (640, 360)];
/// Where on the orbit the camera is (as in `bench scaling`).
const T: f32 = 0.125;

fn camera(city: &City, t: f32, turn: f32, (w, h): (u32, u32)) -> Camera {
    let (eye, target) = city.path(Path::Orbit, t);
    let dir = glam::Quat::from_rotation_y(turn.to_radians()) * (target - eye);
    Camera::look_at(eye, eye + dir, glam::Vec3::Y, 50f32.to_radians(), 1.0)
        .with_aspect(w, h)
        .with_depth_range(0.5, city.half_extent * 8.0)
}

fn opts() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..Default::default()
    }
}

/// Counters of the frames of one city at one size.
#[derive(Debug)]
struct Frames {
    triangles: usize,
    size: (u32, u32),
    /// Impostor frames without refreshes: from the capture pose, and with the eye turned
    /// in place by 4 degrees (no parallax: nothing to refresh).
    impostors: [FrameStats; 2],
    geometry: FrameStats,
}

fn frames(renderer: &mut Renderer, city: &mut City, size: (u32, u32)) -> Frames {
    let mut target = Target::new(size.0, size.1);
    // Warm up: everything in view captured for this image height.
    let config = Config {
        budget: ibr::impostor::Budget {
            refreshes: usize::MAX,
            time: None,
        },
        ..Config::default()
    };
    let buildings = std::mem::take(&mut city.buildings);
    let mut imp = Impostored::new("city", config, buildings);
    let mut ground: Vec<Draw> = Vec::new();
    city.ground.draws(&mut ground);
    let mut frame_loop = FrameLoop::new();
    // One frame of the loop: the ground plus the city's impostors.
    let mut frame = |imp: &mut Impostored<MeshGroup>, cam: &Camera, target: &mut Target| {
        let view = FrameView {
            camera: cam,
            width: size.0,
            height: size.1,
            lighting: &city.lighting,
            time: 0.0,
            dt: 0.0,
        };
        let mut list: [&mut dyn Technique; 1] = [imp];
        frame_loop.render(
            renderer,
            ground.iter().copied(),
            &mut list,
            &view,
            target,
            &opts(),
        )
    };
    let cam = camera(city, T, 0.0, size);
    frame(&mut imp, &cam, &mut target);
    let warm = imp.report;
    assert!(warm.refreshes > 0 && warm.stale == 0, "{warm:?}");

    let mut impostors = [FrameStats::default(); 2];
    for (k, turn) in [0.0, 4.0].into_iter().enumerate() {
        let cam = camera(city, T, turn, size);
        let stats = frame(&mut imp, &cam, &mut target);
        let report = imp.report;
        assert_eq!(report.refreshes, 0, "a steady frame: {report:?}");
        assert_eq!((report.geometry, report.stale), (0, 0), "{report:?}");
        assert!(report.images > GRID as usize, "{report:?}");
        assert!(imp
            .set
            .impostors
            .iter()
            .all(|i| matches!(i.mode, Mode::Image | Mode::Culled)));
        assert_eq!(stats.draws as usize, 1 + report.images);
        impostors[k] = stats;
    }

    // The ground truth: the geometry the impostors stand for.
    let mut draws = ground.clone();
    imp.reference(&mut draws);
    let geometry = renderer.render(draws, &cam, &city.lighting, &mut target, &opts());
    drop(ground);
    city.buildings = imp.subjects;
    Frames {
        triangles: city.triangle_count(),
        size,
        impostors,
        geometry,
    }
}

/// `a` and `b` within `rel` of each other.
fn close(a: u64, b: u64, rel: f64) -> bool {
    (a as f64 - b as f64).abs() <= rel * a.max(b) as f64
}

#[test]
fn impostor_frames_cost_pixels_not_triangles() {
    let mut renderer = Renderer::new();
    // cities[c][s]: city c (about 1k, 30k, 1M triangles) at size s.
    let cities: Vec<Vec<Frames>> = [1_000, 30_000, 1_000_000]
        .into_iter()
        .map(|n| {
            let mut city = City::with_triangles(GRID, n, 7);
            SIZES
                .iter()
                .map(|&size| frames(&mut renderer, &mut city, size))
                .collect()
        })
        .collect();
    let (small, large) = (&cities[0], &cities[2]);
    assert!(small[0].triangles < 1_500 && large[0].triangles > 900_000);

    for s in 0..SIZES.len() {
        let first = &cities[0][s];
        for f in &cities[1..] {
            let f = &f[s];
            for (a, b) in first.impostors.iter().zip(&f.impostors) {
                let what = format!(
                    "{} vs {} triangles at {:?}: {a:?} {b:?}",
                    first.triangles, f.triangles, f.size
                );
                // Same quads, whatever the buildings' triangles: equal set-up, and the
                // same fragments up to the images' silhouette pixels.
                assert_eq!(a.triangles_in, b.triangles_in, "{what}");
                assert_eq!(a.triangles_set_up, b.triangles_set_up, "{what}");
                assert!(
                    close(a.fragments_shaded, b.fragments_shaded, 0.002),
                    "{what}"
                );
                assert!(
                    close(a.fragments_written, b.fragments_written, 0.002),
                    "{what}"
                );
            }
        }
        // Geometry submits every triangle and sets up more the finer the city, over the
        // same screen coverage.
        for f in &cities {
            let g = f[s].geometry;
            assert_eq!(g.triangles_in, f[s].triangles as u64);
            // A few triangles a building (its image's mesh over its covered cells: a band
            // or a few) and the ground's, whatever the buildings' triangles.
            let imp = &f[s].impostors[0];
            assert!(imp.triangles_in < 8 * 64 + 4, "{imp:?}");
            assert!(
                close(g.fragments_shaded, small[s].geometry.fragments_shaded, 0.01),
                "{g:?} {:?}",
                small[s].geometry
            );
        }
        assert!(
            cities[1][s].geometry.triangles_set_up > 10 * small[s].geometry.triangles_set_up,
            "{:?} {:?}",
            small[s].geometry,
            cities[1][s].geometry
        );
    }
    // At the largest size, 1M against 1k triangles: over 100 times the set-up work.
    let last = SIZES.len() - 1;
    assert!(
        large[last].geometry.triangles_set_up > 100 * small[last].geometry.triangles_set_up,
        "{:?} {:?}",
        small[last].geometry,
        large[last].geometry
    );

    // Doubling the resolution in each axis: 4x the fragments, about the same triangles.
    for city in &cities {
        for pair in city.windows(2) {
            for k in 0..2 {
                let (a, b) = (pair[0].impostors[k], pair[1].impostors[k]);
                let what = format!(
                    "{} triangles, {:?} -> {:?}: {a:?} {b:?}",
                    pair[0].triangles, pair[0].size, pair[1].size
                );
                // About the same triangles: each image's mesh over its covered cells of a
                // coarse grid, which a finer image may trace a cell or two apart.
                let tris = b.triangles_set_up as f64 / a.triangles_set_up.max(1) as f64;
                assert!((0.8..=1.25).contains(&tris), "{tris}: {what}");
                for (x, y) in [
                    (a.fragments_shaded, b.fragments_shaded),
                    (a.fragments_written, b.fragments_written),
                ] {
                    let ratio = y as f64 / x.max(1) as f64;
                    assert!((3.2..=4.8).contains(&ratio), "{ratio}: {what}");
                }
            }
        }
    }
}
