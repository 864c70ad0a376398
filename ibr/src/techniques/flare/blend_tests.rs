//! The flare's sprites blended into the frame against the same quads rendered over it.

use super::*;
use engine::{FrameOptions, Lighting, Renderer};

/// A sun flare at full visibility in a `w` x `h` frame over a grey opaque sky, with the
/// sky's target.
fn sun_over_sky(w: u32, h: u32, toward: Vec3) -> (Camera, LensFlare, Target) {
    let eye = Vec3::new(0.0, 0.0, 5.0);
    let camera = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 1.0, w as f32 / h as f32)
        .with_depth_range(0.1, 100.0);
    let mut target = Target::new(w, h);
    let sky = Rgba::new(0.25, 0.35, 0.55, 1.0);
    let opts = FrameOptions {
        clear: Some(sky),
        ..FrameOptions::default()
    };
    Renderer::new().render([], &camera, &Lighting::default(), &mut target, &opts);
    let mut flare = LensFlare::default();
    let shown = flare.update(&camera, &target, FlareSource::Directional(toward), 1e6);
    assert_eq!(shown, 1.0, "the sun is in view and nothing hides it");
    (camera, flare, target)
}

/// Each byte's largest difference between two frames, and how many pixels differ.
fn difference(a: &Target, b: &Target) -> (u8, usize) {
    let (a, b) = (a.to_rgba8_premultiplied(), b.to_rgba8_premultiplied());
    let most = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max();
    let pixels = a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x != y).count();
    (most.unwrap_or(0), pixels)
}

#[test]
fn blending_the_sprites_adds_the_light_rendering_their_quads_does() {
    for (w, h) in [(160, 90), (320, 180)] {
        let (camera, flare, sky) = sun_over_sky(w, h, Vec3::new(0.35, 0.2, -1.0));
        assert!(
            flare.placed().iter().any(|p| p.lod > 0.0)
                && flare.placed().iter().any(|p| p.lod < 0.0),
            "some sprites shrink their cells and some magnify them"
        );
        let mut drawn = sky.clone();
        let over = FrameOptions {
            clear: None,
            ..FrameOptions::default()
        };
        let lighting = Lighting::default();
        Renderer::new().render([flare.draw()], &camera, &lighting, &mut drawn, &over);
        let mut blended = sky.clone();
        flare.blend(&mut blended);
        let (most, pixels) = difference(&drawn, &blended);
        let (_, lit) = difference(&sky, &drawn);
        assert!(lit > (w * h / 4) as usize, "the flare lights {lit} pixels");
        // The same texels, filter and sums; the quads' interpolated coordinates and the
        // order of the float sums may round a byte the other way.
        // Measured: 628 of 8,896 lit pixels differ at 160x90, each by one level.
        eprintln!("{w}x{h}: {pixels} of {lit} lit pixels differ, by up to {most}");
        assert!(most <= 1, "{w}x{h}: bytes differ by up to {most}");
        assert!(
            pixels * 5 < lit,
            "{w}x{h}: {pixels} of {lit} lit pixels differ"
        );
    }
}

#[test]
fn the_blend_touches_only_pixels_within_the_sprites_reach() {
    let (w, h) = (320, 180);
    let (_, flare, sky) = sun_over_sky(w, h, Vec3::new(0.1, 0.05, -1.0));
    let mut blended = sky.clone();
    let stats = flare.blend(&mut blended);
    let (squares, reach) = (flare.sprite_pixels(w, h), flare.reach_pixels(w, h));
    eprintln!("squares {squares}, reach {reach}, {stats:?}");
    let (_, changed) = difference(&sky, &blended);
    assert!(changed as u64 <= stats.fragments_written, "{changed}");
    // Overlapping sprites are one pixel written, so at most the sum of their reaches.
    assert!(stats.fragments_written <= reach, "{stats:?} {reach}");
    // The discs and rings of the shapes are about two thirds of their squares.
    assert!(reach * 4 < squares * 3, "{reach} of {squares}");
    // Pixels nothing reaches keep their bytes: every changed pixel is within a sprite's
    // disc of reach.
    let (a, b) = (
        sky.to_rgba8_premultiplied(),
        blended.to_rgba8_premultiplied(),
    );
    for (i, (x, y)) in a.chunks(4).zip(b.chunks(4)).enumerate() {
        if x != y {
            let p = Vec2::new((i as u32 % w) as f32 + 0.5, (i as u32 / w) as f32 + 0.5);
            let within = flare.placed().iter().any(|s| {
                let r = (p - s.centre).length() / s.half;
                r < s.reach.outer && r > s.reach.inner
            });
            assert!(within, "pixel {p} changed outside every sprite's reach");
        }
    }
    // The halo's and ring's holes are left alone, so their reach is a ring.
    let alpha = AtlasAlpha::new(&atlas(CELL_PX));
    for shape in [FlareShape::Halo, FlareShape::Ring] {
        assert!(
            alpha.reach(shape).inner > 0.3,
            "{shape:?} {:?}",
            alpha.reach(shape)
        );
    }
    for shape in FlareShape::ALL {
        assert!(
            alpha.reach(shape).outer < 1.05,
            "{shape:?} {:?}",
            alpha.reach(shape)
        );
    }
}

#[test]
fn no_sprites_blend_nothing() {
    let (w, h) = (64, 48);
    let (camera, mut flare, sky) = sun_over_sky(w, h, Vec3::new(0.1, 0.05, -1.0));
    // The sun behind the eye: no sprites.
    flare.update(&camera, &sky, FlareSource::Directional(Vec3::Z), 1e6);
    let mut blended = sky.clone();
    let stats = flare.blend(&mut blended);
    assert_eq!(stats.fragments_tested, 0);
    assert_eq!(blended, sky);
    assert_eq!(flare.reach_pixels(w, h), 0);
}
