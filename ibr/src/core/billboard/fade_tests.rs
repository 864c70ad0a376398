//! The stipple of a dithered axial billboard handing over to its top sprite: a baked tree
//! drawn with screen-door alpha (`AlphaMode::Dither`, as the showcase's forest) over a
//! magenta background, seen across the fade band.

use super::*;
use crate::core::sprites;
use engine::procedural::{self, TreeKind};
use engine::{AlphaMode, Camera, FrameOptions, Lighting, Renderer, Target};

const SIDE: u32 = 96;

/// Pixels of the tree (not the magenta background) in a render.
fn tree_mask(target: &Target) -> Vec<bool> {
    let mut mask = Vec::with_capacity((SIDE * SIDE) as usize);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let c = target.color_linear(x, y).unwrap();
            mask.push(!(c.r > 0.9 && c.g < 0.1 && c.b > 0.9));
        }
    }
    mask
}

/// Stipple: pixels at least 3 of whose 4 neighbours are of the other kind (a tree pixel
/// alone in the background or a hole alone in the tree), per tree pixel. A solid
/// silhouette has them only at single-pixel spikes of its outline.
fn stipple(mask: &[bool]) -> f32 {
    let n = SIDE as usize;
    let mut odd = 0;
    for y in 1..n - 1 {
        for x in 1..n - 1 {
            let me = mask[y * n + x];
            let others = [(x - 1, y), (x + 1, y), (x, y - 1), (x, y + 1)]
                .iter()
                .filter(|&&(a, b)| mask[b * n + a] != me)
                .count();
            odd += (others >= 3) as usize;
        }
    }
    odd as f32 / mask.iter().filter(|&&t| t).count().max(1) as f32
}

/// A dithered tree with a top sprite, seen from `elevation` degrees, 12 units away.
fn render_tree(elevation: f32) -> Vec<bool> {
    let mesh = procedural::tree(TreeKind::Broadleaf, 1.0, 3);
    let lit = Material::lit(Rgba::WHITE);
    let sprite = sprites::bake_upright(
        &mesh,
        &lit,
        &Lighting::default(),
        Vec3::new(1.0, 0.0, 0.6),
        96,
    );
    let material = Material {
        alpha_mode: AlphaMode::Dither,
        vertex_colors: true,
        ..Material::unlit(Rgba::WHITE).with_texture(sprite.texture.clone())
    };
    let facing = Facing::Axial {
        axis: Vec3::Y,
        fallback: AxialFallback {
            top: Some(sprite.top),
            ..AxialFallback::default()
        },
    };
    let height = 5.0;
    let mut batch = BillboardBatch::new(material);
    batch.push(Billboard {
        pivot: sprite.pivot,
        region: sprite.side,
        ..Billboard::new(
            Vec3::ZERO,
            facing,
            Vec2::new(sprite.size.x / sprite.size.y, 1.0) * height,
        )
    });
    let centre = Vec3::Y * (0.5 * height);
    let e = elevation.to_radians();
    let eye = centre + Vec3::new(e.cos() * 0.8, e.sin(), e.cos() * 0.6) * 12.0;
    let cam = Camera::look_at(eye, centre, Vec3::Y, 0.6, 1.0);
    batch.build(&View::new(&cam, SIDE));
    let mut target = Target::new(SIDE, SIDE);
    let opts = FrameOptions {
        clear: Some(Rgba::new(1.0, 0.0, 1.0, 1.0)),
        ..FrameOptions::default()
    };
    Renderer::new().render(
        [batch.draw()],
        &cam,
        &Lighting::default(),
        &mut target,
        &opts,
    );
    tree_mask(&target)
}

/// Across the fade band (55 to 75 degrees of elevation at the tree's base) the tree shows,
/// on average, little more stipple than its sprites' own soft edges give outside the band.
/// (A cross-fade `fade` / `1 - fade` dithered both quads against one pattern: at mid-band
/// there were more stipple pixels than tree pixels.)
#[test]
fn a_dithered_tree_handing_over_to_its_top_sprite_shows_little_stipple() {
    let outside: Vec<f32> = [40.0, 50.0, 80.0, 88.0]
        .iter()
        .map(|&e| stipple(&render_tree(e)))
        .collect();
    let base = outside.iter().sum::<f32>() / outside.len() as f32;
    let mut inside = Vec::new();
    // Elevations seen from the tree's centre, 12 units out: 51 to 71 here are about 55 to
    // 75 from its base, where the fade is measured.
    for k in 0..=20 {
        let e = 51.0 + k as f32;
        let mask = render_tree(e);
        assert!(
            mask.iter().filter(|&&t| t).count() > 400,
            "the tree is drawn at {e}"
        );
        inside.push(stipple(&mask));
    }
    let mean = inside.iter().sum::<f32>() / inside.len() as f32;
    println!("stipple outside the band {outside:?} (mean {base}), inside {inside:?} (mean {mean})");
    // Measured: outside 0.06 to 0.14 (mean 0.085); inside a mean of 0.126, against 0.699
    // with the cross-fade.
    assert!(
        mean <= 2.0 * base,
        "mean stipple {mean} in the band against {base} outside"
    );
}
