//! Tests of the shading stage (`shade`): lanes, lights and texture sampling.

use crate::color::{srgb_to_linear, Encoding};
use crate::testing::on_threads;
use crate::{
    Camera, Draw, FrameOptions, Light, Lighting, Material, Mesh, Renderer, Rgba, Shading, Target,
    Texture,
};
use glam::{Mat4, Vec3};
use std::sync::Arc;

proptest::proptest! {
    /// A pack's lanes take the values their pixels have in whole rows, bit for bit: lane `l`
    /// is pixel `xs[l]` of row `fy + dys[l]`.
    #[test]
    fn packed_lanes_evaluate_as_their_rows(
        c in -1e3f32..1e3, dx in -10f32..10.0, dy in -10f32..10.0,
        fx in -64i32..64, fy in -64i32..64,
        xs in proptest::array::uniform8(0usize..8), dys in proptest::array::uniform8(0i32..8),
    ) {
        use super::{eval, Row};
        use crate::simd::F8;
        let p = crate::setup::Plane { c, dx, dy };
        let pack = Row {
            fx: fx as f32,
            ys: F8::from_array(dys.map(|d| (fy + d) as f32)),
            xs: F8::from_array(xs.map(|x| x as f32)),
            covered: 0xff,
        };
        let got = eval(&p, &pack).to_array();
        for l in 0..8 {
            let whole = eval(&p, &Row::whole(fx as f32, (fy + dys[l]) as f32, 0xff)).to_array();
            proptest::prop_assert_eq!(got[l].to_bits(), whole[xs[l]].to_bits());
        }
    }
}

/// The quad `[-1, 1]^2` in the z = 0 plane facing +Z, two triangles, with the given uvs at
/// its corners (counter-clockwise from `(-1, -1)`).
fn unit_quad(uvs: [glam::Vec2; 4]) -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: uvs.to_vec(),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    }
}

/// A quad in the z = 0 plane facing +Z, seen head-on from z = 4, filling the middle of a
/// 32 x 32 target; returns the centre pixel as linear RGB.
fn centre(material: &Material, lighting: &Lighting) -> [f32; 3] {
    let quad = unit_quad([glam::Vec2::ZERO; 4]);
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 4.0), Vec3::ZERO, Vec3::Y, 0.6, 1.0);
    let mut target = Target::with_encoding(32, 32, Encoding::Srgb);
    let draw = Draw {
        mesh: &quad,
        material,
        transform: Mat4::IDENTITY,
    };
    let opts = FrameOptions::default();
    Renderer::new().render([draw], &camera, lighting, &mut target, &opts);
    let [r, g, b, _] = target.pixel(16, 16).expect("inside").to_le_bytes();
    [r, g, b].map(|c| srgb_to_linear(c as f32 / 255.0))
}

/// The textured, Lambert-lit path without highlights (opaque texture: no division by
/// alpha; specular 0: no view or half vectors) gives `base * texel * (ambient + light *
/// n.l)`, worked out here by hand, to the byte encoding's precision.
#[test]
fn textured_lambert_without_highlights_is_the_formula() {
    let texel = [200u8, 120, 40, 255];
    let tex = Texture::from_rgba8(1, 1, &texel, Encoding::Srgb).expect("1x1");
    assert!(tex.is_opaque());
    let base = Rgba::new(0.9, 0.8, 0.7, 1.0);
    let mut material = Material::lit(base).with_texture(Arc::new(tex));
    material.shading = Shading::Lit {
        specular: 0.0,
        shininess: 32.0,
    };
    let from = Vec3::new(0.3, 0.4, 0.866).normalize();
    let lighting = Lighting {
        ambient: Rgba::new(0.1, 0.15, 0.2, 1.0),
        lights: vec![Light::Directional {
            direction: -from,
            color: Rgba::new(0.7, 0.6, 0.5, 1.0),
        }],
    };
    let got = centre(&material, &lighting);
    let ndl = from.z; // the normal is +Z
    let (amb, light) = ([0.1, 0.15, 0.2], [0.7, 0.6, 0.5]);
    for c in 0..3 {
        let t = srgb_to_linear(texel[c] as f32 / 255.0);
        let scale = base.to_array()[c] * (amb[c] + light[c] * ndl);
        let want = scale * t;
        // One sRGB byte step near `want`, plus the sampler's rounding of the texel (its
        // square root stored in a byte: `Texture`'s 8-lane tables).
        let texel_rounding = scale * (t.sqrt() + 0.5 / 255.0) / 255.0;
        assert!(
            (got[c] - want).abs() < 0.01 * want.max(0.05) + texel_rounding,
            "channel {c}: {} vs {want}",
            got[c]
        );
    }
    // A texel that is not opaque keeps the division path and the same straight colour.
    let clear =
        Texture::from_rgba8(2, 1, &[200, 120, 40, 255, 0, 0, 0, 0], Encoding::Srgb).expect("2x1");
    assert!(!clear.is_opaque());
}

/// A point light is dropped for a triangle only where it adds nothing: at random points
/// of random triangles, every light whose attenuation is above zero (the shader's
/// `1 - (d / range)^2`, worked out here in f64) has its bit set, and lights far out of
/// range have theirs clear.
#[test]
fn lights_out_of_range_are_dropped_only_where_they_add_nothing() {
    let mut rng = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut v3 = |s: f32| Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5) * s;
    let (mut dropped, mut kept) = (0, 0);
    for _ in 0..2000 {
        let tri = [v3(20.0), v3(20.0), v3(20.0)];
        let position = v3(40.0);
        let range = 0.5 + 15.0 * (v3(1.0).x + 0.5);
        let lighting = Lighting {
            ambient: Rgba::BLACK,
            lights: vec![
                Light::Directional {
                    direction: Vec3::NEG_Y,
                    color: Rgba::WHITE,
                },
                Light::Point {
                    position,
                    color: Rgba::WHITE,
                    range,
                },
            ],
        };
        let bits = super::reach(&lighting, tri);
        assert!(bits & 1 != 0, "directional lights always reach");
        let reaches = bits & 2 != 0;
        if reaches {
            kept += 1;
        } else {
            dropped += 1;
        }
        for _ in 0..50 {
            let (a, b) = (v3(1.0).x + 0.5, v3(1.0).x + 0.5);
            let (a, b) = if a + b > 1.0 {
                (1.0 - a, 1.0 - b)
            } else {
                (a, b)
            };
            let q = tri[0] + (tri[1] - tri[0]) * a + (tri[2] - tri[0]) * b;
            let d = q.as_dvec3().distance(position.as_dvec3()) / range as f64;
            assert!(reaches || d >= 1.0, "light at {d} of its range dropped");
        }
    }
    assert!(
        dropped > 100 && kept > 100,
        "{dropped} dropped, {kept} kept"
    );
}

/// The row's widest footprint is the covered lanes' maximum, NaN lanes left out, at
/// least 0: the same level of detail as the per-lane fold it replaced, over random
/// squared footprints (zeros, NaN and infinity among them) and every lane mask.
#[test]
fn widest_footprint_is_the_fold_over_covered_lanes() {
    use crate::simd::F8;
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    for _ in 0..2000 {
        let lanes: [f32; 8] = std::array::from_fn(|_| match next() % 8 {
            0 => 0.0,
            1 => f32::NAN,
            2 => f32::INFINITY,
            3 => 1e-30,
            _ => (next() >> 40) as f32 / 4096.0,
        });
        for covered in 0..=255u32 {
            let want = (0..8)
                .filter(|l| covered >> l & 1 != 0)
                .map(|l| lanes[l])
                .fold(0.0f32, f32::max);
            let got = super::widest(F8::from_array(lanes), covered);
            assert_eq!(got, want, "{lanes:?} covered {covered:#x}");
            assert_eq!(
                super::fast_log2(got).to_bits(),
                super::fast_log2(want).to_bits()
            );
        }
    }
}

/// Flat faces: one normal per triangle, normalised and flipped for back faces; zero
/// normals give the face normal; normals that vary across the triangle give none.
#[test]
fn flat_normals_are_worked_out_once_per_triangle() {
    use crate::vertex::NRM;
    let mut attr = [[0.0f32; 3]; 12];
    attr[NRM + 2] = [2.0, 0.0, 0.0];
    let face = Vec3::new(0.0, 1.0, 0.0);
    assert_eq!(super::flat_normal(&attr, face, true), Some(Vec3::Z));
    assert_eq!(super::flat_normal(&attr, face, false), Some(-Vec3::Z));
    attr[NRM + 2] = [0.0; 3];
    assert_eq!(super::flat_normal(&attr, face, true), Some(face));
    attr[NRM] = [0.5, 0.0, 0.25];
    assert_eq!(super::flat_normal(&attr, face, true), None);
}

/// One level of detail for a whole triangle (`triangle_lod`) is taken only where it stands
/// for every row: over random triangles' planes (`1/w` from nearly constant to strongly
/// perspective, boxes up to 64 x 64, textures 8 to 256 texels wide), wherever it answers,
/// each 8-pixel row of the box takes a level (`row_lod`, the shader's own) within half of
/// `LOD_SPREAD` of it (1/8 level), plus 1e-3 for rounding. Near-affine triangles (the
/// sprites) mostly get one; strongly perspective ones mostly do not.
#[test]
fn one_level_per_triangle_is_within_half_the_spread_of_every_row() {
    use super::{barycentrics, row_lod, triangle_lod, Row, LOD_SPREAD};
    use crate::setup::{Plane, Tri};
    let mut rng = crate::procedural::XorShift::new(0x2545_f491_4f6c_dd1d);
    let mut next = move || rng.next_f32();
    let texels = vec![128u8; 256 * 256 * 4];
    let texs: Vec<Texture> = [8, 64, 256]
        .map(|s| Texture::from_rgba8(s, s, &texels[..(s * s * 4) as usize], Encoding::Srgb))
        .into_iter()
        .map(|t| t.expect("square"))
        .collect();
    let (mut one, mut near_affine, mut worst) = (0, 0, 0.0f32);
    let cases = 3000;
    for case in 0..cases {
        let (bw, bh) = (1 + (next() * 63.0) as u16, 1 + (next() * 63.0) as u16);
        let mut tri = Tri::with_box([10, 20, 10 + bw, 20 + bh], 0);
        // A third of the cases nearly affine (`1/w` within 0.2% over 64 pixels), the rest up
        // to 2% a pixel.
        let slope = if case % 3 == 0 { 3e-5 } else { 0.02 };
        let c = 0.05 + 4.0 * next();
        tri.iw = Plane {
            c,
            dx: c * slope * (2.0 * next() - 1.0),
            dy: c * slope * (2.0 * next() - 1.0),
        };
        let mut plane = || Plane {
            c: c * next(),
            dx: c * (2.0 * next() - 1.0) / 32.0,
            dy: c * (2.0 * next() - 1.0) / 32.0,
        };
        (tri.l1, tri.l2) = (plane(), plane());
        let mut d = || 4.0 * next() - 2.0;
        let uv = [[0.5, d(), d()], [0.5, d(), d()]];
        let tex = &texs[case % texs.len()];
        let Some(lod) = triangle_lod(&tri, uv, tex) else {
            continue;
        };
        one += 1;
        near_affine += (case % 3 == 0) as usize;
        for y in 0..=bh {
            for x0 in (0..=bw).step_by(8) {
                let lanes = (bw - x0 + 1).min(8);
                let row = Row::whole(x0 as f32, y as f32, (1u32 << lanes) - 1);
                let (l1, l2, w) = barycentrics(&tri, &row);
                let got = row_lod(&tri, uv, tex, &row, [l1, l2, w]);
                let off = (got - lod).abs();
                worst = worst.max(off);
                assert!(
                    off <= LOD_SPREAD / 2.0 + 1e-3,
                    "case {case}: row ({x0}, {y}) level {got}, triangle's {lod}"
                );
            }
        }
    }
    assert!(
        near_affine > cases / 3 / 2,
        "{near_affine} near-affine triangles with one level"
    );
    assert!(one < cases / 2, "{one} of {cases} with one level");
    assert!(worst > 0.0, "the rows' levels vary within the spread");
    // Non-finite planes are left to the rows.
    let mut tri = Tri::with_box([0, 0, 8, 8], 0);
    tri.iw = Plane {
        c: 1.0,
        dx: f32::NAN,
        dy: 0.0,
    };
    assert_eq!(
        triangle_lod(&tri, [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], &texs[0]),
        None
    );
}

/// A trilinear textured quad (a sprite facing the camera, one level a triangle, and a
/// floor in perspective, a level a row) gives the same pixels at 1 and 2 threads.
#[test]
fn trilinear_levels_give_the_same_pixels_at_any_thread_count() {
    use crate::texture::Filter;
    let (w, h) = (64u32, 64u32);
    let texels: Vec<u8> = (0..w * h * 4).map(|i| (i * 37 % 251) as u8).collect();
    let tex = Arc::new(Texture::from_rgba8(w, h, &texels, Encoding::Srgb).expect("64x64"));
    let mut material = Material::lit(Rgba::WHITE).with_texture(tex);
    material.sampler.filter = Filter::Trilinear;
    let quad = unit_quad([
        glam::Vec2::new(0.0, 4.0),
        glam::Vec2::new(4.0, 4.0),
        glam::Vec2::new(4.0, 0.0),
        glam::Vec2::new(0.0, 0.0),
    ]);
    let camera = Camera::look_at(Vec3::new(0.0, 0.5, 3.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
    let sprite = Mat4::from_scale(Vec3::splat(0.6));
    let floor = Mat4::from_translation(Vec3::new(0.0, -0.5, 0.0))
        * Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(3.0));
    let lighting = Lighting::default();
    let mut frames = Vec::new();
    for threads in [1, 2] {
        let mut target = Target::with_encoding(160, 96, Encoding::Srgb);
        let draws = [floor, sprite].map(|transform| Draw {
            mesh: &quad,
            material: &material,
            transform,
        });
        let opts = FrameOptions::default();
        on_threads(threads, || {
            Renderer::new().render(draws, &camera, &lighting, &mut target, &opts)
        });
        frames.push(target.to_rgba8());
    }
    assert_eq!(frames[0], frames[1]);
    // Something was drawn: the frame is not one colour.
    assert!(frames[0].chunks(4).any(|p| p != &frames[0][..4]));
}
