//! Tests of the showcase scene, its animation, the fly camera and the headless path.

use super::*;
use engine::{AlphaMode, Light, Material};
use glam::Vec3;

#[test]
fn scene_is_valid_and_has_every_feature() {
    let show = Showcase::new();
    let s = &show.scene;
    validate(s).unwrap();
    assert!(s.draws().count() == s.instances.len());
    let mats: Vec<&Material> = s.draws().map(|d| d.material).collect();
    assert!(mats
        .iter()
        .any(|m| matches!(m.alpha_mode, AlphaMode::Mask { .. })));
    assert!(mats.iter().any(|m| m.alpha_mode == AlphaMode::Blend));
    assert!(mats.iter().any(|m| m.base_texture.is_some()));
    assert!(s
        .draws()
        .any(|d| d.material.vertex_colors && !d.mesh.colors.is_empty()));
    assert!(s
        .lighting
        .lights
        .iter()
        .any(|l| matches!(l, Light::Point { .. })));
    assert!(s
        .lighting
        .lights
        .iter()
        .any(|l| matches!(l, Light::Directional { .. })));
}

#[test]
fn animation_moves_the_lamp_and_is_deterministic() {
    let mut a = Showcase::new();
    let mut b = Showcase::new();
    a.animate(1.5);
    b.animate(1.5);
    assert_eq!(a.scene, b.scene);
    let before = a.scene.lighting.clone();
    a.animate(2.5);
    assert_ne!(before, a.scene.lighting);
}

#[test]
fn fly_camera_moves_where_it_looks() {
    let mut c = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -5.0));
    assert!((c.forward() - Vec3::NEG_Z).length() < 1e-5);
    c.update(
        &FlyInput {
            forward: 1.0,
            ..Default::default()
        },
        0.5,
    );
    assert!((c.position - Vec3::new(0.0, 0.0, -3.0)).length() < 1e-4);
    c.update(
        &FlyInput {
            right: 1.0,
            up: 1.0,
            ..Default::default()
        },
        1.0 / 6.0,
    );
    assert!((c.position - Vec3::new(1.0, 1.0, -3.0)).length() < 1e-4);
    let looking = FlyCamera::looking_at(Vec3::ZERO, Vec3::new(1.0, 1.0, 0.0));
    assert!((looking.forward() - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-5);
    c.update(
        &FlyInput {
            pitch: 10.0,
            ..Default::default()
        },
        0.0,
    );
    assert!(c.pitch <= 1.5);
}

#[test]
fn path_stays_above_the_ground() {
    let show = Showcase::new();
    for i in 0..120 {
        let (eye, _) = show.path(i, 120);
        assert!(eye.y > show.terrain.height_at(eye.x, eye.z) + 1.0);
    }
}

/// A tap shorter than a frame (press and release between two frames) still toggles; a held
/// key's auto-repeated presses count once; two taps in one frame cancel out.
#[test]
fn key_taps_toggle_once_per_press_from_events() {
    let mut taps = TapCounter::default();
    // Press and release between two frames: the key is up again when the frame looks.
    taps.event(true);
    taps.event(false);
    let n = taps.take();
    assert_eq!(n, 1);
    assert!(toggled(false, n));
    assert_eq!(taps.take(), 0, "taken once");
    assert!(!toggled(false, 0));
    // Held over several frames with auto-repeat: one tap, on the first frame.
    taps.event(true);
    assert_eq!(taps.take(), 1);
    taps.event(true);
    taps.event(true);
    assert_eq!(taps.take(), 0);
    taps.event(false);
    assert_eq!(taps.take(), 0);
    // Two quick taps within one frame: toggled twice, back where it was.
    for down in [true, false, true, false] {
        taps.event(down);
    }
    let n = taps.take();
    assert_eq!(n, 2);
    assert!(toggled(true, n));
}
