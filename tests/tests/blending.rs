//! Blending: premultiplied "over" and additive blending in linear space, blended draws
//! composited back to front whatever their submission order, depth-tested against opaque
//! geometry and writing depth only where a material asks (images standing in for opaque
//! objects).

use engine::{BlendMode, Cull, Encoding, Material, Rgba, Scene};
use glam::{Mat4, Vec3};
use tests::scenes::{pixel_camera, px, render, soup};

const W: u32 = 32;
const H: u32 = 32;

/// Largest byte difference allowed between a blended pixel and the exact linear result,
/// encoded: the engine rounds once, at resolve, from `f32` working colour, so the only
/// difference is where the exact value lies within `f32` rounding of a byte's rounding
/// boundary; one step covers that.
const BYTE_TOL: i32 = 1;

/// A full-target quad at view depth `-z`, unlit in `color` with `material` settings.
fn layer(scene: &mut Scene, z: f32, color: Rgba, blend: Option<BlendMode>) {
    let mut m = Material::unlit(color).double_sided(true);
    if let Some(b) = blend {
        m = m.blended(b);
    }
    quad(scene, z, m);
}

/// A full-target quad at view depth `-z` of material `m`.
fn quad(scene: &mut Scene, z: f32, m: Material) {
    let c = |x: f64, y: f64| {
        let p = px(x, y);
        Vec3::new(p.x, p.y, z)
    };
    let quad = soup(&[
        [c(-1.0, -1.0), c(40.0, -1.0), c(40.0, 40.0)],
        [c(-1.0, -1.0), c(40.0, 40.0), c(-1.0, 40.0)],
    ]);
    scene.add(quad, m, Mat4::IDENTITY);
}

/// Renders `scene` and checks every pixel's colour bytes against `want` (straight linear
/// RGB of an opaque result), encoded exactly by this test.
fn check_uniform(what: &str, scene: &Scene, encoding: Encoding, want: [f64; 3]) {
    let (target, _) = render(scene, &pixel_camera(W, H), W, H, encoding, Cull::None);
    let encode = |x: f64| -> i32 {
        let x = x.clamp(0.0, 1.0);
        let v = match encoding {
            Encoding::Unorm => x,
            Encoding::Srgb => {
                if x <= 0.003_130_8 {
                    12.92 * x
                } else {
                    1.055 * x.powf(1.0 / 2.4) - 0.055
                }
            }
        };
        (v * 255.0).round() as i32
    };
    let want = want.map(encode);
    for y in 0..H {
        for x in 0..W {
            let [r, g, b, a] = target.pixel(x, y).expect("inside").to_le_bytes();
            let got = [r as i32, g as i32, b as i32];
            assert!(
                got.iter().zip(want).all(|(g, w)| (g - w).abs() <= BYTE_TOL) && a == 255,
                "{what}: pixel ({x}, {y}) is {:?}, want {want:?} (alpha 255)",
                [r, g, b, a]
            );
        }
    }
}

#[test]
fn over_blending_is_linear_and_back_to_front() {
    // Opaque dark grey at the back; red 50%, then green 25%, then blue 50% nearer and
    // nearer, submitted in a scrambled order.
    let layers: [(f32, Rgba); 3] = [
        (-2.0, Rgba::new(1.0, 0.0, 0.0, 0.5)),
        (-1.0, Rgba::new(0.0, 0.0, 1.0, 0.5)),
        (-1.5, Rgba::new(0.0, 1.0, 0.0, 0.25)),
    ];
    let mut want = [0.2, 0.2, 0.2];
    let mut sorted = layers;
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0)); // farthest (most negative z) first
    for (_, c) in sorted {
        let a = c.a as f64;
        want = [0, 1, 2].map(|i| [c.r, c.g, c.b][i] as f64 * a + want[i] * (1.0 - a));
    }
    for encoding in [Encoding::Srgb, Encoding::Unorm] {
        let mut scene = Scene::default();
        for (z, c) in layers {
            layer(&mut scene, z, c, Some(BlendMode::Alpha));
        }
        layer(&mut scene, -3.0, Rgba::new(0.2, 0.2, 0.2, 1.0), None);
        check_uniform(&format!("over, {encoding:?}"), &scene, encoding, want);
    }
}

#[test]
fn blended_layers_are_depth_tested_but_write_no_depth() {
    // An opaque white wall in front of a blended red layer: the red layer is hidden. A
    // blended layer in front of an opaque one drawn later still shows over it.
    let mut scene = Scene::default();
    layer(&mut scene, -1.0, Rgba::new(1.0, 1.0, 1.0, 1.0), None);
    layer(
        &mut scene,
        -2.0,
        Rgba::new(1.0, 0.0, 0.0, 0.5),
        Some(BlendMode::Alpha),
    );
    check_uniform(
        "hidden blended layer",
        &scene,
        Encoding::Unorm,
        [1.0, 1.0, 1.0],
    );

    let mut scene = Scene::default();
    layer(
        &mut scene,
        -1.0,
        Rgba::new(0.0, 0.0, 1.0, 0.5),
        Some(BlendMode::Alpha),
    );
    layer(
        &mut scene,
        -1.5,
        Rgba::new(0.0, 1.0, 0.0, 0.4),
        Some(BlendMode::Alpha),
    );
    layer(&mut scene, -3.0, Rgba::new(0.4, 0.4, 0.4, 1.0), None);
    // Green (alpha 0.4) over grey, then blue (alpha 0.5) over that: the nearer blended
    // layer does not hide the farther one.
    let g = [0.4 * 0.6, 1.0 * 0.4 + 0.4 * 0.6, 0.4 * 0.6];
    let want = [g[0] * 0.5, g[1] * 0.5, 1.0 * 0.5 + g[2] * 0.5];
    check_uniform("stacked blended layers", &scene, Encoding::Unorm, want);
}

/// An image standing in for an opaque object ([`Material::blend_depth`]) writes depth
/// where its alpha reaches the cutoff, and only there, without changing what blended layers
/// behind it show.
#[test]
fn blended_layers_write_depth_where_their_alpha_reaches_the_cutoff() {
    let image = |alpha: f32, cutoff: Option<f32>| Material {
        blend_depth: cutoff,
        ..Material::unlit(Rgba::new(0.0, 0.0, 1.0, alpha))
            .double_sided(true)
            .blended(BlendMode::Alpha)
    };
    for (alpha, cutoff, writes) in [
        (0.6, Some(0.5), true),
        (0.4, Some(0.5), false),
        (1.0, None, false),
    ] {
        let mut scene = Scene::default();
        quad(&mut scene, -1.0, image(alpha, cutoff));
        let (target, _) = render(
            &scene,
            &pixel_camera(W, H),
            W,
            H,
            Encoding::Unorm,
            Cull::None,
        );
        for y in 0..H {
            for x in 0..W {
                let written = target.depth_gl(x, y).unwrap() < 1.0;
                assert_eq!(
                    written, writes,
                    "alpha {alpha}, cutoff {cutoff:?}: ({x}, {y})"
                );
            }
        }
    }
    // Blended draws are sorted back to front, so a farther layer is drawn before the image
    // and its depth writes hide nothing of it: the pixels are those of an image that writes
    // no depth.
    let stacked = |cutoff: Option<f32>| {
        let mut scene = Scene::default();
        quad(&mut scene, -1.0, image(0.6, cutoff));
        layer(
            &mut scene,
            -2.0,
            Rgba::new(1.0, 0.0, 0.0, 0.5),
            Some(BlendMode::Alpha),
        );
        render(
            &scene,
            &pixel_camera(W, H),
            W,
            H,
            Encoding::Unorm,
            Cull::None,
        )
        .0
    };
    let (with, without) = (stacked(Some(0.5)), stacked(None));
    for y in 0..H {
        for x in 0..W {
            assert_eq!(with.pixel(x, y), without.pixel(x, y), "({x}, {y})");
        }
    }
}

#[test]
fn additive_blending_adds_in_linear_space() {
    let mut scene = Scene::default();
    layer(&mut scene, -3.0, Rgba::new(0.1, 0.2, 0.3, 1.0), None);
    layer(
        &mut scene,
        -2.0,
        Rgba::new(0.5, 0.25, 0.0, 0.5),
        Some(BlendMode::Additive),
    );
    layer(
        &mut scene,
        -1.0,
        Rgba::new(0.2, 0.2, 0.8, 1.0),
        Some(BlendMode::Additive),
    );
    // dst + src * src.a per layer
    let want = [0.1 + 0.25 + 0.2, 0.2 + 0.125 + 0.2, 0.3 + 0.0 + 0.8];
    for encoding in [Encoding::Srgb, Encoding::Unorm] {
        check_uniform(&format!("additive, {encoding:?}"), &scene, encoding, want);
    }
}

/// Screen-door transparency: at alpha `k / 16` exactly `k` pixels of every aligned 4 x 4
/// block are drawn (the ordered dither's thresholds are `(rank + 0.5) / 16`), and the
/// drawn ones write depth like opaque pixels.
#[test]
fn dithered_alpha_covers_its_fraction_of_every_4x4_block() {
    for k in [0u32, 1, 4, 7, 12, 16] {
        let mut scene = Scene::default();
        let a = k as f32 / 16.0;
        layer(&mut scene, -1.0, Rgba::new(1.0, 1.0, 1.0, a), None);
        scene.materials[0].alpha_mode = engine::AlphaMode::Dither;
        let (target, _) = render(
            &scene,
            &pixel_camera(W, H),
            W,
            H,
            Encoding::Unorm,
            Cull::None,
        );
        for by in (0..H).step_by(4) {
            for bx in (0..W).step_by(4) {
                let drawn = (0..16)
                    .filter(|i| {
                        let (x, y) = (bx + i % 4, by + i / 4);
                        target.pixel(x, y).unwrap() & 0xff == 0xff
                    })
                    .count() as u32;
                assert_eq!(drawn, k, "alpha {a} at block ({bx}, {by})");
                for i in 0..16 {
                    let (x, y) = (bx + i % 4, by + i / 4);
                    let written = target.depth_gl(x, y).unwrap() < 1.0;
                    let lit = target.pixel(x, y).unwrap() & 0xff == 0xff;
                    assert_eq!(written, lit, "depth only where drawn");
                }
            }
        }
    }
}
