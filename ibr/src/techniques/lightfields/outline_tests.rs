//! The outline from geometry ([`LightFieldObject::proxy_outline`]) in a frame, against a
//! render of the geometry itself from the same eye.

use super::tests::{camera, slab, H, W};
use super::*;
use crate::core::{FrameLoop, FrameView, MeshGroup, Subject, Technique};
use engine::{procedural, FrameOptions, Material, PixelRect, Renderer, Rgba, Target};
use std::sync::Arc;

/// A lit sphere in front of the focal plane (off it, so its outline moves between
/// cameras) and a box behind it, partly hidden by it.
fn subject() -> MeshGroup {
    let lit = |c: Rgba| Arc::new(Material::lit(c));
    MeshGroup::new()
        .with(
            Arc::new(procedural::uv_sphere(0.55, 24, 32)),
            lit(Rgba::new(0.8, 0.5, 0.2, 1.0)),
            Mat4::from_translation(Vec3::new(-0.1, 0.1, 0.4)),
        )
        .with(
            Arc::new(procedural::cuboid(Vec3::new(0.8, 0.8, 0.4))),
            lit(Rgba::new(0.3, 0.6, 0.7, 1.0)),
            Mat4::from_translation(Vec3::new(0.35, -0.3, -0.4)),
        )
}

/// The object alone and its geometry alone from `eye`, each as 8-bit RGBA and the
/// target (for depth).
fn frames(object: &mut LightFieldObject, eye: Vec3) -> [(Vec<u8>, Target); 2] {
    let cam = camera(eye);
    let lighting = Lighting::default();
    let view = FrameView::still(&cam, W, H, &lighting);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    let (mut renderer, mut frames) = (Renderer::new(), FrameLoop::new());
    let (mut image, mut truth) = (Target::new(W, H), Target::new(W, H));
    let mut list: [&mut dyn Technique; 1] = [object];
    frames.render(&mut renderer, [], &mut list, &view, &mut image, &opts);
    let mut draws = Vec::new();
    object.reference(&mut draws);
    frames.render(&mut renderer, draws, &mut [], &view, &mut truth, &opts);
    [(image.to_rgba8(), image), (truth.to_rgba8(), truth)]
}

/// Pixels covered by one image only, of them those not on the geometry's outline (its
/// coverage differs from one of their eight neighbours'), and the mean absolute colour
/// difference (8-bit levels) over the pixels both cover.
fn outline_and_colour(a: &[u8], b: &[u8]) -> (usize, usize, f64) {
    let covered = |x: i64, y: i64| {
        (0..W as i64).contains(&x)
            && (0..H as i64).contains(&y)
            && b[4 * (y * W as i64 + x) as usize + 3] > 0
    };
    let (mut one, mut off, mut sum, mut n) = (0, 0, 0u64, 0u64);
    for (i, (p, q)) in a.chunks_exact(4).zip(b.chunks_exact(4)).enumerate() {
        let (x, y) = ((i % W as usize) as i64, (i / W as usize) as i64);
        match (p[3] > 0, q[3] > 0) {
            (true, true) => {
                sum += (0..3).map(|k| u64::from(p[k].abs_diff(q[k]))).sum::<u64>();
                n += 3;
            }
            (false, false) => {}
            _ => {
                one += 1;
                let c = covered(x, y);
                let edge = (-1..=1).any(|dy| (-1..=1).any(|dx| covered(x + dx, y + dy) != c));
                off += usize::from(!edge);
            }
        }
    }
    (one, off, sum as f64 / n.max(1) as f64)
}

/// From eyes between the cameras, the light field's outline is the geometry's within a
/// pixel (rasterised through a crop of the eye's camera, a pixel on the outline may fall
/// the other way) and off in half as many pixels or fewer than without, its depth the
/// geometry's, and its colour inside close to the geometry's.
#[test]
fn the_outline_is_the_geometrys_and_the_colour_the_light_fields() {
    let group = subject();
    let mut draws = Vec::new();
    group.draws(&mut draws);
    let field = LightField::capture(&draws, &Lighting::default(), slab(8, 64));
    let mut object = LightFieldObject::new("sphere and box", field);
    object.reference = Some(group);
    for eye in [Vec3::new(0.13, -0.21, 4.3), Vec3::new(-0.55, 0.37, 4.6)] {
        object.proxy_outline = false;
        let [(plain, _), _] = frames(&mut object, eye);
        object.proxy_outline = true;
        let [(image, got), (truth, want)] = frames(&mut object, eye);
        assert!(matches!(object.showing(), Showing::Slab(0)));
        let (before, _, _) = outline_and_colour(&plain, &truth);
        let (one, off, colour) = outline_and_colour(&image, &truth);
        eprintln!("from {eye}: {before} outline pixels off without, {one} with ({off} off the outline), colour {colour:.2} levels");
        assert!(
            before >= 5,
            "{before} outline pixels off without the geometry"
        );
        assert_eq!(
            off, 0,
            "pixels covered by one image only off the outline, from {eye}"
        );
        assert!(
            2 * one <= before,
            "{one} pixels covered by one image only, from {eye}"
        );
        assert!(colour < 4.0, "{colour:.2} levels off inside, from {eye}");
        let cam = camera(eye);
        for (x, y) in (0..H).flat_map(|y| (0..W).map(move |x| (x, y))) {
            let (g, t) = (got.depth_reversed(x, y), want.depth_reversed(x, y));
            let (g, t) = (g.unwrap_or(0.0), t.unwrap_or(0.0));
            if t > 0.0 && g > 0.0 {
                let (g, t) = (
                    cam.view_depth_from_reversed(g),
                    cam.view_depth_from_reversed(t),
                );
                assert!(
                    (g - t).abs() < 1e-3 * t,
                    "depth {g} against {t} at ({x}, {y})"
                );
            }
        }
    }
}

/// With the outline from geometry only the rays within the geometry's sphere on screen
/// are looked up (a pixel outside it is a hole whatever the light field finds): for a
/// small subject in the middle of the focal plane, no more rays than the pixels of the
/// sphere's rectangle, a fraction of those the whole focal plane's rectangle asks for,
/// and its outline still the geometry's.
#[test]
fn with_the_outline_the_rays_looked_up_are_bounded_by_the_geometrys_sphere() {
    let group = MeshGroup::new().with(
        Arc::new(procedural::uv_sphere(0.3, 16, 24)),
        Arc::new(Material::lit(Rgba::new(0.8, 0.5, 0.2, 1.0))),
        Mat4::from_translation(Vec3::new(0.1, -0.1, 0.2)),
    );
    let mut draws = Vec::new();
    group.draws(&mut draws);
    let bounds = group.bounds();
    let field = LightField::capture(&draws, &Lighting::default(), slab(8, 64));
    let mut object = LightFieldObject::new("small sphere", field);
    object.reference = Some(group);
    let eye = Vec3::new(0.13, -0.21, 4.3);
    object.proxy_outline = false;
    let [(plain, _), _] = frames(&mut object, eye);
    let whole = object.last();
    object.proxy_outline = true;
    let [(image, _), (truth, _)] = frames(&mut object, eye);
    let clipped = object.last();
    let sphere = object::sphere_rect(bounds, &camera(eye), W, H).expect("in front of the eye");
    let area = |r: PixelRect| u64::from(r.x1 - r.x0) * u64::from(r.y1 - r.y0);
    let rect = object.rect().expect("an image");
    eprintln!(
        "rays {} (taps {}) without the outline, {} (taps {}) with it; sphere's rectangle {} pixels",
        whole.rays,
        whole.taps,
        clipped.rays,
        clipped.taps,
        area(sphere)
    );
    assert!(rect.x0 >= sphere.x0 && rect.y0 >= sphere.y0);
    assert!(rect.x1 <= sphere.x1 && rect.y1 <= sphere.y1);
    assert!(clipped.rays <= area(sphere), "{clipped:?}");
    assert!(
        2 * clipped.rays <= whole.rays,
        "{clipped:?} against {whole:?}"
    );
    assert!(
        2 * clipped.taps <= whole.taps,
        "{clipped:?} against {whole:?}"
    );
    let (before, _, _) = outline_and_colour(&plain, &truth);
    let (one, off, colour) = outline_and_colour(&image, &truth);
    assert_eq!(off, 0, "pixels covered by one image only off the outline");
    assert!(one <= before, "{one} outline pixels off, {before} without");
    assert!(colour < 4.0, "{colour:.2} levels off inside");
    // From the same place looking away: the slab still sees the sphere's place, but the
    // sphere is out of view, so nothing is looked up (the focal plane's rectangle, a
    // corner behind the eye, was the whole view, every row of it searched).
    let away = Camera::look_at(eye, 2.0 * eye, Vec3::Y, 0.7, W as f32 / H as f32)
        .with_depth_range(0.1, 30.0);
    let lighting = Lighting::default();
    object.prepare(&FrameView::still(&away, W, H, &lighting));
    assert!(matches!(object.showing(), Showing::Slab(0)));
    assert_eq!((object.rect(), object.last().rays), (None, 0));
}

/// With the outline from geometry, only the rays of each row's span the geometry covers
/// are looked up: the image is pixel for pixel the one every ray of the focal plane's
/// rectangle and then the outline give, from fewer rays.
#[test]
fn rays_within_the_geometrys_spans_give_the_same_image() {
    let group = subject();
    let mut draws = Vec::new();
    group.draws(&mut draws);
    let field = LightField::capture(&draws, &Lighting::default(), slab(8, 64));
    let lookup = Lookup::default();
    let lighting = Lighting::default();
    for eye in [Vec3::new(0.13, -0.21, 4.3), Vec3::new(-0.55, 0.37, 4.6)] {
        let cam = camera(eye);
        let view = FrameView::still(&cam, W, H, &lighting);
        let mut every = object::Composite::new(cam);
        every.render(&field, &view, lookup, None, None);
        let r = every.rect.expect("the focal plane in view");
        let mut outline = outline::Outline::default();
        let crop = every.image.camera;
        outline.cover(&group, &crop, r.x1 - r.x0, r.y1 - r.y0);
        outline.conform(&mut every.image);
        let mut spans = object::Composite::new(cam);
        let mut own = outline::Outline::default();
        spans.render(&field, &view, lookup, None, Some((&group, &mut own)));
        eprintln!(
            "from {eye}: rays {} every, {} within the spans",
            every.last.rays, spans.last.rays
        );
        assert_eq!(spans.rect, every.rect);
        assert!(
            spans.image.color == every.image.color,
            "colours differ from {eye}"
        );
        let bits = |d: &[f32]| d.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&spans.image.disparity), bits(&every.image.disparity));
        assert!(spans.image.color.iter().any(|&c| c != 0), "something drawn");
        assert!(
            spans.last.rays < every.last.rays,
            "{:?} against {:?}",
            spans.last,
            every.last
        );
    }
}
