//! Where light fields fail, and what they do then: six slabs show an object from every
//! side, an eye no slab covers falls back to the geometry (and says so), an eye between
//! the planes still sees rays, grazing rays and an empty slab give no NaN and no panic.

use super::tests::{compare, truth, H, W};
use super::*;
use crate::core::MeshGroup;
use crate::core::{FrameView, Technique};
use crate::warp::Warped;
use engine::{procedural, Material, Mesh, Rgba, Sphere};
use std::sync::Arc;

/// A cuboid coloured by position (vertex colours), unlit: every side looks different.
fn block() -> (Mesh, Material) {
    let mut mesh = procedural::cuboid(Vec3::new(0.8, 0.6, 0.7));
    mesh.colors = mesh
        .positions
        .iter()
        .map(|p| Rgba::new(0.5 + p.x * 0.6, 0.5 + p.y * 0.7, 0.5 + p.z * 0.6, 1.0))
        .collect();
    (mesh, Material::unlit(Rgba::WHITE))
}

/// The block, shared, and a light field of it from one slab facing +Z (its front).
fn block_in_front() -> (Arc<Mesh>, Arc<Material>, LightFieldObject) {
    let (mesh, material) = block();
    let (mesh, material) = (Arc::new(mesh), Arc::new(material));
    let draw = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let slab = Slab::facing(Vec3::ZERO, 0.6, Vec3::NEG_Z, Vec3::Y, [6, 6, 32, 32]).expect("slab");
    let field = LightField::capture(&[draw], &Lighting::default(), slab);
    (mesh, material, LightFieldObject::new("block", field))
}

fn look(eye: Vec3) -> Camera {
    Camera::look_at(
        eye,
        Vec3::ZERO,
        Vec3::Y + Vec3::X * 0.01,
        0.5,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 40.0)
}

#[test]
fn six_slabs_show_an_object_from_every_side() {
    let (mesh, material) = block();
    let draw = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let radius = 0.6;
    let slabs = Slab::cube(Vec3::ZERO, radius, [16, 16, 64, 64]).expect("six slabs");
    let fields = slabs
        .iter()
        .map(|&s| LightField::capture(&[draw], &Lighting::default(), s))
        .collect();
    let bounds = Sphere {
        center: Vec3::ZERO,
        radius,
    };
    let object = LightFieldObject::with_slabs("block", fields, bounds);
    let mut seen = [false; 6];
    let mut out = Warped::new(0, 0, look(Vec3::Z));
    for eye in [
        Vec3::new(0.3, 0.2, 3.0),
        Vec3::new(-0.2, 0.1, -3.2),
        Vec3::new(3.1, -0.3, 0.2),
        Vec3::new(-3.0, 0.4, -0.3),
        Vec3::new(0.2, 3.0, 0.3),
        Vec3::new(-0.3, -3.1, 0.2),
        Vec3::new(2.8, 2.5, 2.9),
        Vec3::new(-2.9, -2.6, 2.4),
    ] {
        let k = object
            .choose(eye)
            .unwrap_or_else(|| panic!("a slab sees it from {eye}"));
        seen[k] = true;
        // The chosen slab's cameras look at the object from the eye's side.
        assert!(
            object.slabs[k].slab.forward().dot(-eye.normalize()) > 0.5,
            "{eye}: slab {k}"
        );
        let cam = look(eye);
        let want = truth(&[draw], &cam);
        // Nearest: the cube's wide camera planes hold few cameras for their size, and
        // depth correction from the nearest camera's depths ghosts there (a known limit).
        let nearest = Lookup {
            interpolation: Interpolation::Nearest,
            depth_correction: false,
        };
        render(&object.slabs[k], &cam, W, H, nearest, &mut out);
        let (mean, n) = compare(&out, &want);
        assert!(n > 300, "{eye}: {n} pixels in common");
        assert!(mean < 12.0, "{eye}: mean error {mean}");
    }
    assert_eq!(seen, [true; 6], "every side's slab used");
}

#[test]
fn an_eye_no_slab_covers_falls_back_to_the_geometry() {
    let (mesh, material, mut object) = block_in_front();
    let lighting = Lighting::default();
    // In front: the slab. Behind or far to the side: nothing, until geometry is kept.
    for (eye, with_geometry, want) in [
        (Vec3::new(0.2, 0.1, 2.4), false, Showing::Slab(0)),
        (Vec3::new(0.0, 0.0, -3.0), false, Showing::Nothing),
        (Vec3::new(4.0, 0.0, 0.5), true, Showing::Geometry),
        (Vec3::new(0.1, 0.0, 0.1), true, Showing::Geometry),
    ] {
        if with_geometry {
            object.reference =
                Some(MeshGroup::new().with(mesh.clone(), material.clone(), Mat4::IDENTITY));
        }
        let cam = look(eye);
        object.prepare(&FrameView::still(&cam, W, H, &lighting));
        assert_eq!(object.showing(), want, "{eye}");
        let mut draws = Vec::new();
        object.draws(&mut draws);
        let c = object.counters();
        assert_eq!(draws.is_empty(), want != Showing::Geometry, "{eye}");
        assert_eq!(c.geometry, u64::from(want == Showing::Geometry), "{eye}");
        if want != Showing::Slab(0) {
            assert_eq!(object.last().rays, 0);
        }
    }
}

/// Below `min_px` of projected diameter the kept geometry is drawn; the same eye shows
/// the slab when the object is nearer (or without the threshold, or without geometry).
#[test]
fn a_small_object_on_screen_falls_back_to_its_geometry() {
    let (mesh, material, mut object) = block_in_front();
    let lighting = Lighting::default();
    let near = look(Vec3::new(0.2, 0.1, 2.4));
    let far = look(Vec3::new(0.2, 0.1, 4.8));
    let px = |object: &LightFieldObject, cam: &Camera| {
        object.projected_px(&FrameView::still(cam, W, H, &lighting))
    };
    // Twice as far, half the size on screen.
    let (big, small) = (px(&object, &near), px(&object, &far));
    assert!((big / small - 2.0).abs() < 0.1, "{big} {small}");
    let threshold = 0.5 * (big + small);
    for (cam, min_px, geometry, want) in [
        (&far, 0.0, true, Showing::Slab(0)),
        (&far, threshold, false, Showing::Slab(0)),
        (&far, threshold, true, Showing::Geometry),
        (&near, threshold, true, Showing::Slab(0)),
    ] {
        object.min_px = min_px;
        object.reference =
            geometry.then(|| MeshGroup::new().with(mesh.clone(), material.clone(), Mat4::IDENTITY));
        object.prepare(&FrameView::still(cam, W, H, &lighting));
        assert_eq!(object.showing(), want, "{min_px} {geometry}");
        let mut draws = Vec::new();
        object.draws(&mut draws);
        assert_eq!(draws.is_empty(), want != Showing::Geometry);
    }
}

#[test]
fn an_eye_between_the_planes_still_sees_the_light_field() {
    let (mesh, material) = block();
    let draw = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let slab = Slab::facing(Vec3::ZERO, 0.6, Vec3::NEG_Z, Vec3::Y, [10, 10, 48, 48]).expect("slab");
    let field = LightField::capture(&[draw], &Lighting::default(), slab);
    // The uv plane is 2.4 in front of the centre: an eye at 1.6 is between the planes,
    // its rays' lines cross the uv plane behind it.
    let cam = look(Vec3::new(0.1, -0.1, 1.6));
    let want = truth(&[draw], &cam);
    let mut out = Warped::new(0, 0, cam);
    render(&field, &cam, W, H, Lookup::default(), &mut out);
    let (mean, n) = compare(&out, &want);
    assert!(n > 500, "{n} pixels in common");
    assert!(mean < 8.0, "mean error {mean}");
}

#[test]
fn grazing_rays_and_an_empty_slab_give_no_nan() {
    let slab = Slab::facing(Vec3::ZERO, 0.6, Vec3::NEG_Z, Vec3::Y, [4, 4, 16, 16]).expect("slab");
    // A slab seeing nothing: every sample empty, no depth.
    let empty = LightField::capture(&[], &Lighting::default(), slab);
    let Rays::Raw(raw) = &empty.rays else {
        panic!("raw");
    };
    assert!(raw.samples.iter().all(|&c| c == 0));
    assert!(raw.depth.iter().all(|z| z.is_infinite()));
    let (codes, report) = empty
        .quantise(&VqSettings {
            codewords: 16,
            training_tiles: 64,
            ..VqSettings::default()
        })
        .expect("quantised");
    assert_eq!(report.codewords, 1, "one empty codeword");
    let (mesh, material) = block();
    let draw = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let full = LightField::capture(&[draw], &Lighting::default(), slab);
    // Eyes looking almost along the planes, and one in the uv plane's own plane.
    for eye in [
        Vec3::new(-3.0, 0.0, 2.4),
        Vec3::new(0.0, 5.0, 0.01),
        Vec3::new(1.0, 0.2, 2.4),
    ] {
        let cam = Camera::look_at(eye, eye + Vec3::new(1.0, 0.0, -1e-4), Vec3::Y, 1.2, 1.0)
            .with_depth_range(0.01, 40.0);
        for lf in [&empty, &codes, &full] {
            let mut out = Warped::new(0, 0, cam);
            let f = render(lf, &cam, W, H, Lookup::default(), &mut out);
            assert!(f.pixels <= f.rays);
            assert!(out.disparity.iter().all(|d| !d.is_nan()));
            assert!(out.color.iter().all(|c| {
                let [r, g, b, a] = c.to_le_bytes();
                r <= a && g <= a && b <= a
            }));
        }
    }
}

#[test]
fn aperture_prefiltering_blurs_off_the_focal_plane_and_keeps_it_sharp_on_it() {
    use super::tests::{camera, slab, Card};
    let lighting = Lighting::default();
    let none = &mut |_: usize, _: usize| {};
    // In the focal plane: the same samples (each view sees the card where the others do).
    let flat = Card::new(0.0, 2.0);
    let draws = [flat.draw()];
    let plain = LightField::capture(&draws, &lighting, slab(3, 32));
    let one = LightField::capture_prefiltered(&draws, &lighting, slab(3, 32), 1, none);
    let (Rays::Raw(a), Rays::Raw(b)) = (&plain.rays, &one.rays) else {
        panic!("raw");
    };
    assert_eq!(a, b, "an aperture of one is the plain capture");
    let filtered = LightField::capture_prefiltered(&draws, &lighting, slab(3, 32), 3, none);
    let Rays::Raw(f) = &filtered.rays else {
        panic!("raw");
    };
    let close = a
        .samples
        .iter()
        .zip(&f.samples)
        .filter(|(x, y)| {
            let (x, y) = (x.to_le_bytes(), y.to_le_bytes());
            (0..4).all(|k| x[k].abs_diff(y[k]) <= 2)
        })
        .count();
    assert!(
        close * 100 >= a.samples.len() * 99,
        "{close} of {}",
        a.samples.len()
    );
    // Off the focal plane, few cameras: the plain light field shows the card as hard
    // ghost copies where there is none; prefiltered, they are soft, and the card keeps
    // its coverage.
    let near = Card::new(1.5, 0.8);
    let draws = [near.draw()];
    let cam = camera(Vec3::new(0.11, -0.17, 4.5));
    let want = truth(&draws, &cam);
    let hard_ghosts = |lf: &LightField| {
        let mut out = Warped::new(0, 0, cam);
        let lookup = Lookup {
            interpolation: Interpolation::Quadrilinear,
            depth_correction: false,
        };
        render(lf, &cam, W, H, lookup, &mut out);
        // Half-opaque or more where the card is not, and less where it is.
        let solid = |i: usize| out.is_filled(i) && out.color_linear(i).a >= 0.5;
        let ghosts = (0..want.len())
            .filter(|&i| want[i].is_none() && solid(i))
            .count();
        let missing = (0..want.len())
            .filter(|&i| want[i].is_some() && !solid(i))
            .count();
        (ghosts, missing)
    };
    let plain = hard_ghosts(&LightField::capture(&draws, &lighting, slab(3, 48)));
    let filtered = hard_ghosts(&LightField::capture_prefiltered(
        &draws,
        &lighting,
        slab(3, 48),
        4,
        none,
    ));
    assert!(
        plain.0 > 20,
        "{plain:?} hard ghost and missing pixels unfiltered"
    );
    assert!(
        filtered.0 * 4 < plain.0,
        "prefiltered {filtered:?}, plain {plain:?}"
    );
    assert!(
        filtered.1 <= plain.1 + 10,
        "prefiltered {filtered:?}, plain {plain:?}"
    );
}
