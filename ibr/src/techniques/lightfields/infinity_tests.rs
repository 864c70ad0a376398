//! Slabs with a plane at infinity (as Stanford's `.lid` allows): parallel-projection
//! cameras (`uv` at infinity) and environment cameras (`st` at infinity), against the
//! geometry.

use super::tests::{camera, compare, slab, truth, Card, H, W};
use super::*;
use crate::warp::Warped;
use engine::{procedural, Material, Rgba};
use glam::Vec2;

#[test]
fn uv_at_infinity_cameras_are_parallel_projections_of_the_st_rectangle() {
    let s = slab(3, 8).with_uv_at_infinity().expect("a valid slab");
    assert_eq!(s.infinite, [true, false]);
    for (i, j) in [(0, 0), (2, 1), (1, 2)] {
        let cam = s.camera(i, j);
        let m = cam.clip_from_world();
        // The direction this camera looks along: from its old uv sample to the centre.
        let d = s.uv.at((i as f32 + 0.5) / 3.0, (j as f32 + 0.5) / 3.0);
        for (ps, pt) in [(0u32, 0u32), (7, 0), (3, 5), (7, 7)] {
            let p = s.st.at((ps as f32 + 0.5) / 8.0, (pt as f32 + 0.5) / 8.0);
            // The sample, and points before and behind it along the direction, all land
            // on the sample's pixel centre.
            for along in [-1.5, 0.0, 0.7] {
                let c = m * (p + d * along).extend(1.0);
                let px = Vec2::new((c.x / c.w + 1.0) * 4.0, (1.0 - c.y / c.w) * 4.0);
                assert!(
                    px.distance(Vec2::new(ps as f32 + 0.5, pt as f32 + 0.5)) < 1e-3,
                    "camera ({i}, {j}), sample ({ps}, {pt}), {along} along: at {px}"
                );
                assert!(
                    (-1.0..=1.0).contains(&(c.z / c.w)),
                    "within the depth range"
                );
            }
        }
    }
}

#[test]
fn a_card_in_the_focal_plane_of_a_uv_at_infinity_slab_looks_as_the_geometry_does() {
    let card = Card::new(0.0, 2.0);
    let draws = [card.draw()];
    let s = slab(5, 48).with_uv_at_infinity().expect("a valid slab");
    let lf = LightField::capture(&draws, &Lighting::default(), s);
    assert!(
        !lf.has_depth(),
        "a slab with a plane at infinity keeps no depth"
    );
    let mut out = Warped::new(0, 0, camera(Vec3::Z));
    for eye in [Vec3::new(0.13, -0.21, 4.0), Vec3::new(-0.3, 0.25, 3.0)] {
        let cam = camera(eye);
        let want = truth(&draws, &cam);
        let frame = render(&lf, &cam, W, H, Lookup::default(), &mut out);
        let (mean, n) = compare(&out, &want);
        assert!(n > 500, "{eye}: the card covers {n} pixels");
        assert!(frame.pixels as u32 >= n, "{frame:?}");
        assert!(mean < 2.0, "{eye}: mean error {mean}");
    }
}

#[test]
fn an_st_at_infinity_slab_shows_a_distant_backdrop_from_anywhere_in_its_camera_plane() {
    // A backdrop 500 units off, 1200 wide: from a camera plane 2 units wide it lies at
    // infinity (its parallax is under a tenth of a sample).
    let (mesh, material) = backdrop();
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -500.0)),
    }];
    let finite = slab(4, 48);
    let far = Slab::new(finite.uv, finite.st, finite.counts(), 0.5, 2000.0).expect("valid");
    let s = far.with_st_at_infinity().expect("a valid slab");
    assert_eq!(s.infinite, [false, true]);
    let lf = LightField::capture(&draws, &Lighting::default(), s);
    let mut out = Warped::new(0, 0, camera(Vec3::Z));
    for eye in [Vec3::new(0.3, -0.2, 4.0), Vec3::new(-0.6, 0.5, 4.5)] {
        let cam = Camera::look_at(eye, eye - Vec3::Z, Vec3::Y, 0.4, W as f32 / H as f32)
            .with_depth_range(0.1, 3000.0);
        let want = truth(&draws, &cam);
        let frame = render(&lf, &cam, W, H, Lookup::default(), &mut out);
        let (mean, n) = compare(&out, &want);
        assert!(n > 2000, "{eye}: {n} pixels compared");
        assert!(frame.pixels as u32 >= n, "{frame:?}");
        assert!(mean < 2.0, "{eye}: mean error {mean}");
        // It lies at infinity: behind anything else in a scene.
        let i = (H / 2 * W + W / 2) as usize;
        assert!(out.is_filled(i) && out.disparity[i] == 0.0);
    }
}

#[test]
fn an_environment_light_field_lies_behind_the_scene_and_is_chosen_over_its_camera_plane() {
    use crate::core::{FrameLoop, FrameView, Technique};
    use engine::{FrameOptions, Renderer, Target};
    let (backdrop, material) = backdrop();
    let far = Slab::new(slab(4, 48).uv, slab(4, 48).st, [4, 4, 48, 48], 0.5, 2000.0);
    let s = far.expect("valid").with_st_at_infinity().expect("valid");
    let draw = Draw {
        mesh: &backdrop,
        material: &material,
        transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -500.0)),
    };
    let mut env =
        LightFieldObject::new("sky", LightField::capture(&[draw], &Lighting::default(), s));
    // A grey panel in front, drawn as geometry: it hides the environment where it stands.
    let panel = procedural::quad(0.4, 0.4);
    let grey = Material::unlit(Rgba::new(0.5, 0.5, 0.5, 1.0));
    let scene = [Draw {
        mesh: &panel,
        material: &grey,
        transform: Mat4::from_translation(Vec3::new(0.2, -0.1, 1.0)),
    }];
    // (Within the 28 degrees of directions the slab holds.)
    let eye = Vec3::new(0.2, -0.1, 4.2);
    let cam = Camera::look_at(eye, eye - Vec3::Z, Vec3::Y, 0.3, W as f32 / H as f32)
        .with_depth_range(0.1, 3000.0);
    let lighting = Lighting::default();
    let view = FrameView::still(&cam, W, H, &lighting);
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    FrameLoop::new().render(
        &mut Renderer::new(),
        scene,
        &mut [&mut env as &mut dyn Technique],
        &view,
        &mut target,
        &opts,
    );
    assert_eq!(env.showing(), Showing::Slab(0));
    let want = truth(&[scene[0], draw], &cam);
    let enc = Encoder::new(ENCODING);
    let got = crate::core::DepthImage::from_target(&target, &cam);
    let mut off = 0;
    for (c, want) in got.color.iter().zip(&want) {
        let g = enc.pack(c.r, c.g, c.b, c.a).to_le_bytes();
        let t = want.expect("the backdrop fills the view").to_le_bytes();
        off += (0..3).any(|k| (g[k] as i32 - t[k] as i32).abs() > 8) as u32;
    }
    assert!(off * 50 < W * H, "{off} pixels off");
    // Outside its camera plane it is not chosen.
    assert_eq!(env.choose(Vec3::new(3.0, 0.0, 4.2)), None);
}

/// A 1200-unit square with a colour gradient, unlit.
fn backdrop() -> (engine::Mesh, Material) {
    let mut mesh = procedural::quad(1200.0, 1200.0);
    mesh.colors = vec![
        Rgba::new(0.9, 0.1, 0.1, 1.0),
        Rgba::new(0.1, 0.9, 0.1, 1.0),
        Rgba::new(0.1, 0.1, 0.9, 1.0),
        Rgba::new(0.9, 0.9, 0.1, 1.0),
    ];
    (mesh, Material::unlit(Rgba::WHITE).double_sided(true))
}

#[test]
fn planes_at_infinity_are_checked_and_saved() {
    let s = slab(3, 8);
    let both = Slab::with_infinite(s.uv, s.st, s.counts(), 0.5, 20.0, [true, true]);
    assert_eq!(both, Err(SlabError::BothAtInfinity));
    // Directions pointing back toward the uv side (the uv rectangle's points, taken as
    // directions, lie behind the origin along the slab's forward, -z).
    let behind = Slab::with_infinite(s.uv, s.st, s.counts(), 0.5, 20.0, [true, false]);
    assert!(
        matches!(behind, Err(SlabError::DirectionsBehind(_))),
        "{behind:?}"
    );
    // Saved and loaded with its planes at infinity.
    let card = Card::new(0.0, 2.0);
    let lf = LightField::capture(
        &[card.draw()],
        &Lighting::default(),
        s.with_uv_at_infinity().expect("valid"),
    );
    let dir = std::env::temp_dir().join(format!("parallax-lf-infinity-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join("ortho.plf");
    lf.save(&path).expect("saved");
    let back = LightField::load(&path).expect("loaded");
    assert_eq!(back.slab, lf.slab);
    assert!(!back.has_depth());
    let _ = std::fs::remove_dir_all(&dir);
}
