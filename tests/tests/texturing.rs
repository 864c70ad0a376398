//! Perspective-correct texturing: a checkerboard ground plane seen at a grazing angle,
//! against an analytic per-pixel ray-plane reference.
//!
//! Nearest filtering of `Texture::checker` makes each pixel exactly one of two colours, so
//! the comparison is per pixel: the checker cell the engine shows must be the cell the
//! exact ray hits. A pixel may disagree only where a cell boundary passes within
//! [`BOUNDARY_PX`] of its centre.

use engine::{
    Camera, Cull, Encoding, Filter, FrameOptions, Material, Mesh, Renderer, Rgba, Sampler, Scene,
    Target, Texture, Wrap,
};
use glam::{DVec3, Mat4, Vec2, Vec3};
use std::sync::Arc;
use tests::compare::EDGE_EPS_PX;
use tests::reference::{intersect, RayCast};

const W: u32 = 256;
const H: u32 = 160;
/// World units per texture repeat; the texture has 8 x 8 cells, so a cell is 1 unit.
const REPEAT: f64 = 8.0;

/// Distance (pixels) from a cell boundary within which a pixel may show either cell. The
/// engine's texture coordinates carry `f32` plane-interpolation rounding (~1e-6 of the
/// coordinate range, here < 0.01 of a pixel) and vertex snapping (< 0.003 px); 1/16 px is
/// a wide margin that still leaves most boundary-adjacent pixels checked.
const BOUNDARY_PX: f64 = 1.0 / 16.0;

/// Largest fraction of covered pixels allowed to disagree (all of them boundary pixels).
/// With the errors above, a disagreement needs a boundary within ~0.01 px of a centre,
/// which happens for well under 0.1% of pixels; a renderer interpolating texture
/// coordinates affinely gets a large fraction wrong (see `affine_interpolation_would_fail`).
const MAX_MISMATCH_FRACTION: f64 = 0.001;

fn camera() -> Camera {
    // Eye half a unit above the ground, looking almost level: the ground is seen at a
    // grazing angle, cells shrinking from hundreds of pixels to about one.
    Camera::look_at(
        Vec3::new(0.0, 0.5, 2.0),
        Vec3::new(0.0, 0.1, -20.0),
        Vec3::Y,
        1.0,
        1.0,
    )
    .with_aspect(W, H)
    .with_depth_range(0.1, 100.0)
}

/// The ground `y = 0` over `x in [-20, 20]`, `z in [z_far, z_near]`, as an `n` x `n` grid,
/// with `uv = (x, z) / REPEAT`.
fn ground(z_near: f32, z_far: f32, n: u32) -> Mesh {
    let mut m = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let x = -20.0 + 40.0 * i as f32 / n as f32;
            let z = z_near + (z_far - z_near) * j as f32 / n as f32;
            m.positions.push(Vec3::new(x, 0.0, z));
            m.uvs.push(Vec2::new(x / REPEAT as f32, z / REPEAT as f32));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            m.indices
                .extend([a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]);
        }
    }
    m
}

fn corners(m: &Mesh) -> [[DVec3; 3]; 2] {
    let p = |i: usize| m.positions[i].as_dvec3();
    let last = m.positions.len() - 1;
    let n = (m.positions.len() as f64).sqrt() as usize - 1;
    [[p(0), p(n), p(last)], [p(0), p(last), p(last - n)]]
}

/// Is the cell at world point `p` white? (`Texture::checker`: cell (i, j) has colour `a`,
/// white here, when `i + j` is even.)
fn white_at(p: DVec3) -> bool {
    let (u, v) = (p.x / REPEAT, p.z / REPEAT);
    ((u * 8.0).floor() as i64 + (v * 8.0).floor() as i64).rem_euclid(2) == 0
}

/// Where the ray through screen point `(sx, sy)` meets the ground rectangle, if it does
/// between the near and far planes.
fn hit(rc: &RayCast, rect: &[[DVec3; 3]; 2], sx: f64, sy: f64) -> Option<DVec3> {
    let (a, b) = rc.segment(sx, sy);
    rect.iter()
        .filter_map(|t| intersect(a, b - a, *t))
        .find(|s| (0.0..=1.0).contains(s))
        .map(|s| a + (b - a) * s)
}

/// Renders `m` with a nearest-filtered checker and compares every pixel with the analytic
/// answer. Returns the number of covered pixels checked.
fn check_checker_plane(what: &str, m: &Mesh, encoding: Encoding) -> u64 {
    let cam = camera();
    let tex = Texture::checker(64, 8, Rgba::WHITE, Rgba::BLACK);
    let mat = Material {
        base_texture: Some(Arc::new(tex)),
        sampler: Sampler {
            filter: Filter::Nearest,
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
        },
        double_sided: true,
        ..Material::unlit(Rgba::WHITE)
    };
    let mut scene = Scene::default();
    scene.add(m.clone(), mat, Mat4::IDENTITY);
    // A mid-grey clear, so uncovered pixels are told apart from black cells.
    let mut target = Target::with_encoding(W, H, encoding);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.5, 0.5, 0.5, 1.0)),
        cull: Cull::None,
    };
    Renderer::new().render_scene(&scene, &cam, &mut target, &opts);
    let grey = (target.pixel(0, 0).expect("sky") & 0xff) as u8;
    assert!(
        grey != 0 && grey != 255,
        "{what}: the top-left corner should be sky"
    );

    let rc = RayCast::new(&cam, W, H);
    let rect = corners(m);
    let (mut covered, mut mismatches, mut unexplained) = (0u64, 0u64, Vec::new());
    for y in 0..H {
        for x in 0..W {
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            let ring = |r: f64| -> [Option<DVec3>; 8] {
                std::array::from_fn(|k| {
                    let a = k as f64 * std::f64::consts::FRAC_PI_4;
                    hit(&rc, &rect, cx + r * a.cos(), cy + r * a.sin())
                })
            };
            let centre = hit(&rc, &rect, cx, cy);
            if ring(EDGE_EPS_PX)
                .iter()
                .any(|h| h.is_some() != centre.is_some())
            {
                continue; // on the plane's outline
            }
            let byte = (target.pixel(x, y).expect("inside") & 0xff) as u8;
            let Some(p) = centre else {
                assert_eq!(byte, grey, "{what}: ({x}, {y}) should be sky");
                continue;
            };
            covered += 1;
            assert!(
                byte == 0 || byte == 255,
                "{what}: ({x}, {y}) is neither cell colour: {byte}"
            );
            let want = white_at(p);
            if (byte == 255) != want {
                mismatches += 1;
                let boundary = ring(BOUNDARY_PX)
                    .iter()
                    .flatten()
                    .any(|q| white_at(*q) != want);
                if !boundary {
                    unexplained.push((x, y));
                }
            }
        }
    }
    assert!(
        unexplained.is_empty(),
        "{what}: {} pixels away from any cell boundary show the wrong cell (first 10: {:?})",
        unexplained.len(),
        &unexplained[..unexplained.len().min(10)]
    );
    assert!(
        mismatches as f64 <= MAX_MISMATCH_FRACTION * covered as f64,
        "{what}: {mismatches} of {covered} pixels show the wrong cell"
    );
    assert!(
        covered > (W * H / 4) as u64,
        "{what}: only {covered} pixels of ground"
    );
    covered
}

#[test]
fn checker_plane_at_a_grazing_angle_two_triangles() {
    check_checker_plane("two triangles", &ground(1.5, -6.0, 1), Encoding::Unorm);
    check_checker_plane("two triangles, sRGB", &ground(1.5, -6.0, 1), Encoding::Srgb);
}

#[test]
fn checker_plane_at_a_grazing_angle_grid_through_the_near_plane() {
    // The grid reaches behind the eye, so its nearest triangles are clipped and their
    // texture coordinates come from the clipper.
    check_checker_plane("7x7 grid", &ground(5.0, -6.0, 7), Encoding::Unorm);
}

/// The scene is discriminating: interpolating texture coordinates affinely in screen space
/// (what a renderer without the perspective divide would do) picks the wrong cell for a
/// large fraction of the two-triangle plane.
#[test]
fn affine_interpolation_would_fail() {
    let cam = camera();
    let m = ground(1.5, -6.0, 1);
    let rc = RayCast::new(&cam, W, H);
    let raster = tests::reference::Raster::new(&cam, W, H);
    let (mut total, mut wrong) = (0u32, 0u32);
    for t in m.indices.chunks_exact(3) {
        let v = [0, 1, 2].map(|k| t[k] as usize);
        let s = v.map(|i| raster.to_screen(m.positions[i]).expect("in front"));
        let tri: [DVec3; 3] = v.map(|i| m.positions[i].as_dvec3());
        for y in 0..H {
            for x in 0..W {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let Some(p) = hit(&rc, &[tri, tri], px, py) else {
                    continue;
                };
                // Screen-space barycentrics, used directly on world x and z (so on uv).
                let d =
                    (s[1].0 - s[0].0) * (s[2].1 - s[0].1) - (s[2].0 - s[0].0) * (s[1].1 - s[0].1);
                let l1 =
                    ((px - s[0].0) * (s[2].1 - s[0].1) - (s[2].0 - s[0].0) * (py - s[0].1)) / d;
                let l2 =
                    ((s[1].0 - s[0].0) * (py - s[0].1) - (px - s[0].0) * (s[1].1 - s[0].1)) / d;
                let q = tri[0] + (tri[1] - tri[0]) * l1 + (tri[2] - tri[0]) * l2;
                total += 1;
                wrong += (white_at(q) != white_at(p)) as u32;
            }
        }
    }
    assert!(total > W * H / 4);
    assert!(
        wrong * 5 > total,
        "affine: only {wrong} of {total} pixels differ"
    );
}
