//! Cloud impostors through the planner: clouds are subjects like any other, so the
//! runtime impostors' representation stands in for distant ones within the error budget,
//! and a cloud whose particles move never shows its old image.

use crate::core::Subject;
use crate::core::{Geometry, Representation};
use crate::plan::tests::{camera, frame, measured, sight, truth, H};
use crate::plan::{self, Budgets, Planner};
use crate::techniques::clouds::Cloud;
use crate::techniques::impostors::{self as impostor, ImpostorSet};
use engine::Renderer;
use glam::Vec3;

const GEOMETRY: usize = 0;
const IMPOSTORS: usize = 1;

/// Eight cumulus clouds 20 to 48 units down the -z axis, spread across the view.
fn planner(error: f32) -> Planner<Cloud> {
    let clouds: Vec<Cloud> = (0..8)
        .map(|k| {
            let at = Vec3::new(
                (k % 4) as f32 * 6.0 - 9.0,
                (k / 4) as f32 * 4.0,
                -20.0 - 4.0 * k as f32,
            );
            Cloud::cumulus(at, Vec3::new(3.0, 1.5, 2.0), 60, k as u64 + 1)
        })
        .collect();
    let reps: Vec<Box<dyn Representation<Cloud>>> = vec![
        Box::new(Geometry),
        Box::new(ImpostorSet::new(impostor::Config::default(), clouds.len())),
    ];
    let config = plan::Config {
        budgets: Budgets {
            error,
            rebuilds: 8,
            ..Budgets::default()
        },
        ..plan::Config::default()
    };
    Planner::new(config, clouds, reps)
}

/// The ground truth from `cam`: every cloud's particles turned to face it first.
fn clouds_truth(p: &mut Planner<Cloud>, cam: &engine::Camera, r: &mut Renderer) -> engine::Target {
    for c in &mut p.objects {
        c.prepare(cam, H);
    }
    truth(p, cam, r)
}

#[test]
fn distant_clouds_become_impostors_within_the_budget_and_a_moved_cloud_is_never_stale() {
    let mut r = Renderer::new();
    // At 3 levels the nearer, larger clouds are images and the four smallest (16-texel
    // images predicted at 3.6 to 4.3 levels) geometry; at 5 every cloud is an image.
    for (budget, least) in [(3.0, 18), (5.0, 48)] {
        let mut p = planner(budget);
        let (mut images, mut worst) = (0, 0.0f64);
        for k in 0..6 {
            let eye = Vec3::new(0.3 * k as f32, 1.5, 6.0);
            let cam = camera(eye, eye + Vec3::new(0.0, 0.0, -10.0));
            // The fourth frame moves one cloud's particles: its image is out of date.
            if k == 3 {
                for q in p.objects[2].particles_mut() {
                    q.position.y += 0.8;
                }
            }
            let got = frame(&mut p, &cam, &mut r);
            let rep = p.report.clone();
            assert_eq!(rep.culled, 0, "frame {k}: {rep:?}");
            let within = rep.max_error <= budget && rep.over_budget == 0;
            assert!(within, "budget {budget}, frame {k}: {rep:?}");
            let want = clouds_truth(&mut p, &cam, &mut r);
            for (i, c) in p.choices().iter().enumerate() {
                assert!(c.rep.is_some(), "frame {k}: cloud {i} missing");
                if c.rep != Some(IMPOSTORS) {
                    continue;
                }
                images += 1;
                let e = measured(&p.objects[i], &cam, &got, &want);
                worst = worst.max(e);
                assert!(e <= f64::from(budget), "frame {k}, cloud {i}: {e} {c:?}");
                if k == 3 && i == 2 {
                    assert!(
                        c.rebuilt,
                        "a moved cloud drawn as an image is re-captured first"
                    );
                }
            }
            let counts = &p.report.counts;
            assert_eq!(counts[GEOMETRY] + counts[IMPOSTORS], p.objects.len());
        }
        eprintln!("budget {budget}: {images} cloud impostor-frames, worst measured {worst:.2}");
        assert!(images >= least, "budget {budget}: {images} images");
    }
}

/// A cloud's blended particles are all shaded: drawn as geometry it costs several times
/// its disc's pixels, which is what makes its image worth taking.
#[test]
fn a_cloud_costs_its_overdraw_as_geometry() {
    let p = planner(0.0);
    let cam = camera(Vec3::new(0.0, 1.5, 6.0), Vec3::new(0.0, 1.5, -4.0));
    for c in &p.objects {
        let od = c.overdraw();
        assert!((2.0..20.0).contains(&od), "{od}");
        let s = sight(&cam, c);
        let g = Representation::<Cloud>::estimate(&Geometry, 0, c, &s).expect("geometry");
        assert_eq!(g.draw.pixels, (s.pixels * od) as u64);
    }
}

/// A lit torus standing at `at`, about 1 unit across.
fn torus(at: Vec3) -> crate::core::MeshGroup {
    crate::core::MeshGroup::new().with(
        std::sync::Arc::new(engine::procedural::torus(0.4, 0.15, 32, 16)),
        std::sync::Arc::new(engine::Material::lit(engine::Rgba::new(0.8, 0.4, 0.2, 1.0))),
        glam::Mat4::from_translation(at) * glam::Mat4::from_rotation_x(1.0),
    )
}

/// Impostors hold clouds and meshes under one refresh budget (moved here from the
/// impostors' tests, which import no sibling technique).
#[test]
fn one_set_holds_subjects_of_several_kinds_under_one_budget() {
    let mut subjects: Vec<Box<dyn Subject + Send>> = vec![
        Box::new(torus(Vec3::new(-1.5, 0.0, 0.0))),
        Box::new(Cloud::cumulus(
            Vec3::new(1.5, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 1.5),
            40,
            3,
        )),
        Box::new(torus(Vec3::new(0.0, 1.5, 0.0))),
    ];
    let mut config = impostor::Config::default();
    config.budget.refreshes = 2;
    let mut imps = ImpostorSet::new(config, 3);
    let cam = camera(Vec3::new(0.0, 0.5, 8.0), Vec3::ZERO);
    let light = engine::Lighting::white_sun(0.3, Vec3::new(-0.3, -1.0, -0.4));
    let first = imps.update(&mut subjects, &cam, 72, &light);
    assert_eq!(first.refreshes, 2, "one budget across both kinds");
    let second = imps.update(&mut subjects, &cam, 72, &light);
    assert_eq!(second.refreshes, 1);
    assert_eq!(second.images, 3);
    let mut draws = Vec::new();
    imps.draws(&subjects, &mut draws);
    assert_eq!(draws.len(), 3, "one quad each");
}
