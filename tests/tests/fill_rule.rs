//! Fill rule: triangles that share edges cover every pixel centre exactly once (no cracks,
//! no double coverage), and each triangle covers exactly the pixels the reference
//! rasterizer says it does.
//!
//! Coverage is read through a count buffer: additive blending of exactly 1/255 per layer
//! into a unorm target. Geometry is authored in screen pixels through an orthographic
//! camera and quantized to the 1/256-pixel snapping grid, so the reference's `f64`
//! projection and the engine's `f32` one land on the same fixed-point vertices and the
//! comparison allows 0 wrong pixels. Ownership (which triangle covers a pixel) is checked
//! too, through `Shading::FaceId`: a tiling can cover every pixel once with the wrong
//! rule (e.g. bottom-right), but not with the right owners.

use engine::{Camera, Encoding, Material, Mesh, Rgba, Scene, Shading};
use glam::{Mat4, Vec3};
use tests::golden::{assert_same_image, check_golden};
use tests::reference::{Counts, Raster};
use tests::scenes::{fan, pixel_camera, px, render, render_counts, triangles, Lattice, Rng};

/// Renders `meshes` as a count buffer and checks it pixel for pixel against the reference.
/// With `full`, the meshes cover the whole target and every pixel must be covered exactly
/// once; otherwise every pixel must be covered at most once. Returns the counts.
fn check_coverage(
    what: &str,
    meshes: &[Mesh],
    camera: &Camera,
    w: u32,
    h: u32,
    full: bool,
) -> Counts {
    let (got, stats) = render_counts(meshes, camera, w, h);
    let reference = Raster::new(camera, w, h);
    let tris: Vec<[Vec3; 3]> = meshes.iter().flat_map(triangles).collect();
    let want = reference.counts(&tris, false);
    // The reference itself must describe a proper tiling (a broken scene is not a test).
    let want_max = want.counts.iter().max().copied().unwrap_or(0);
    assert!(
        want_max <= 1,
        "{what}: the scene overlaps itself in the reference"
    );
    let mut wrong = Vec::new();
    let (mut cracks, mut doubles) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let (g, r) = (got.get(x, y), want.get(x, y));
            if g != r {
                wrong.push((x, y, g, r));
            }
            if full && g == 0 {
                cracks += 1;
            }
            if g > 1 {
                doubles += 1;
            }
        }
    }
    assert!(
        wrong.is_empty() && cracks == 0 && doubles == 0,
        "{what}: {} pixels differ from the reference (x, y, engine, reference; first 10: {:?}), \
         {cracks} uncovered, {doubles} covered more than once",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
    assert_eq!(
        stats.fragments_written,
        want.counts.iter().map(|&c| c as u64).sum::<u64>(),
        "{what}: fragments_written"
    );
    check_owners(what, meshes, camera, w, h);
    got
}

/// Which triangle owns each pixel: the meshes drawn as one draw with `Shading::FaceId`
/// (colour = triangle index + 1, exact unorm bytes) against the reference's owner.
fn check_owners(what: &str, meshes: &[Mesh], camera: &Camera, w: u32, h: u32) {
    let mut all = Mesh::default();
    for m in meshes {
        all.append(m);
    }
    let mut scene = Scene::default();
    let mat = Material {
        shading: Shading::FaceId,
        depth_test: false,
        double_sided: true,
        ..Default::default()
    };
    scene.add(all.clone(), mat, Mat4::IDENTITY);
    let (target, _) = render(&scene, camera, w, h, Encoding::Unorm, engine::Cull::None);
    let reference = Raster::new(camera, w, h);
    let mut owner = vec![0u32; (w * h) as usize];
    for (i, t) in triangles(&all).into_iter().enumerate() {
        let st = reference.screen_tri(t).expect("on screen");
        if let Some((x0, y0, x1, y1)) = st.pixel_box(w, h) {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    if st.covers(x, y) {
                        owner[(y * w as i64 + x) as usize] = i as u32 + 1;
                    }
                }
            }
        }
    }
    let mut wrong = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let got = target.pixel(x, y).expect("inside") & 0xff_ffff;
            let want = owner[(y * w + x) as usize];
            if got != want {
                wrong.push((x, y, got, want));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "{what}: {} pixels owned by the wrong triangle (x, y, engine id, reference id; 0 = none; first 10: {:?})",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
}

/// Lattice basis for `deg` degrees and `step` pixels; multiples of 45 degrees are exact.
fn basis(deg: f64, step: f64) -> ((f64, f64), (f64, f64)) {
    match deg {
        0.0 => ((step, 0.0), (0.0, step)),
        45.0 => ((step, step), (-step, step)),
        90.0 => ((0.0, step), (-step, 0.0)),
        _ => {
            let (s, c) = deg.to_radians().sin_cos();
            ((step * c, step * s), (-step * s, step * c))
        }
    }
}

/// A full-screen grid of quads rotated by `deg`, offset by `off` pixels, each quad split
/// into two triangles (alternating diagonals).
fn check_quad_grid(deg: f64, step: f64, off: (f64, f64), w: u32, h: u32) {
    let (a, b) = basis(deg, step);
    let radius = ((w * w + h * h) as f64).sqrt() / 2.0 + 2.0 * step;
    let lattice = Lattice {
        origin: (w as f64 / 2.0 + off.0, h as f64 / 2.0 + off.1),
        a,
        b,
        n: (radius / step).ceil() as i32 + 1,
        diagonal: &|i, j| (i + j) % 2 == 0,
        flip: &|i, _| i % 3 == 0,
        jitter: &|_, _| (0.0, 0.0),
    };
    let m = lattice.build(&px);
    check_coverage(
        &format!("quad grid {deg} deg, step {step}, offset {off:?}, {w}x{h}"),
        &[m],
        &pixel_camera(w, h),
        w,
        h,
        true,
    );
}

#[test]
fn rotated_quad_grids_cover_every_pixel_once() {
    let angles = [
        0.0, 45.0, 90.0, 0.5, 7.0, 26.565_051, 30.0, 60.0, 89.3, 135.0, 200.0, 333.3,
    ];
    let offsets = [
        (0.0, 0.0),
        (0.5, 0.5),
        (0.5, 0.0),
        (0.25, 0.75),
        (1.0 / 256.0, 3.0 / 256.0),
        (0.123, 0.456),
    ];
    for (k, &deg) in angles.iter().enumerate() {
        for &off in &offsets {
            // Steps that put vertices on pixel centres, corners and in between.
            let step = [1.0, 2.0, 3.0, 5.5, 8.0, 13.25][k % 6];
            check_quad_grid(deg, step, off, 150, 100);
        }
    }
}

#[test]
fn quad_grids_across_tile_and_block_edges() {
    // Sizes that end mid-block and mid-tile, and a single row / column.
    for (w, h) in [(200, 130), (67, 9), (1, 70), (70, 1), (129, 65)] {
        check_quad_grid(0.0, 4.0, (0.5, 0.5), w, h);
        check_quad_grid(45.0, 2.0, (0.0, 0.5), w, h);
        check_quad_grid(17.0, 6.0, (0.3, 0.1), w, h);
    }
}

/// A full-screen jittered grid with random diagonals and windings.
fn check_jittered_mesh(seed: u64, step: f64, grid: f64, w: u32, h: u32) {
    let mut rng = Rng(seed);
    let n = ((w.max(h) as f64) / step / 2.0).ceil() as i32 + 2;
    let side = (2 * n + 1) as usize;
    // Interior jitter up to 0.2 steps per axis keeps every triangle's orientation (no
    // fold-overs), so the mesh is a proper tiling.
    let jit: Vec<(f64, f64)> = (0..side * side)
        .map(|_| {
            let q = |v: f64| (v / grid).round() * grid;
            (
                q(rng.range(-0.2, 0.2) * step),
                q(rng.range(-0.2, 0.2) * step),
            )
        })
        .collect();
    let diag: Vec<bool> = (0..side * side).map(|_| rng.below(2) == 0).collect();
    let flip: Vec<bool> = (0..side * side).map(|_| rng.below(2) == 0).collect();
    let at = |i: i32, j: i32| (j + n) as usize * side + (i + n) as usize;
    let lattice = Lattice {
        origin: (w as f64 / 2.0, h as f64 / 2.0),
        a: (step, 0.0),
        b: (0.0, step),
        n,
        diagonal: &|i, j| diag[at(i, j)],
        flip: &|i, j| flip[at(i, j)],
        jitter: &|i, j| jit[at(i, j)],
    };
    let m = lattice.build(&px);
    check_coverage(
        &format!("jittered mesh seed {seed}, step {step}, grid {grid}, {w}x{h}"),
        &[m],
        &pixel_camera(w, h),
        w,
        h,
        true,
    );
}

#[test]
fn jittered_meshes_have_no_cracks_or_overlaps() {
    for seed in 0..12 {
        // Jitter on the sub-pixel grid (anything goes) ...
        check_jittered_mesh(seed, 7.0, 1.0 / 256.0, 160, 96);
        // ... and on the half-pixel grid, where many pixel centres lie exactly on edges
        // and on vertices.
        check_jittered_mesh(100 + seed, 6.0, 0.5, 128, 72);
        check_jittered_mesh(200 + seed, 3.0, 0.5, 80, 80);
    }
}

/// Fans around centres at pixel centres, pixel corners and arbitrary points. Each fan's
/// union is a convex polygon: every pixel covered at most once, and the pixel at the shared
/// centre vertex exactly once when the centre is a pixel centre.
fn check_fans(spokes: u32, phase: f64, radius: f64, w: u32, h: u32) -> Counts {
    let centres = [
        (20.5, 20.5),
        (60.0, 20.0),
        (100.37, 21.81),
        (20.5, 60.0),
        (60.5, 60.5),
        (99.0, 61.5),
    ];
    let fans: Vec<Mesh> = centres
        .iter()
        .map(|&c| fan(c, radius, spokes, phase, &px))
        .collect();
    let got = check_coverage(
        &format!("fans of {spokes} spokes, phase {phase}, radius {radius}"),
        &fans,
        &pixel_camera(w, h),
        w,
        h,
        false,
    );
    for &(cx, cy) in &centres {
        if cx % 1.0 == 0.5 && cy % 1.0 == 0.5 {
            assert_eq!(got.get(cx as u32, cy as u32), 1, "fan centre ({cx}, {cy})");
        }
    }
    got
}

#[test]
fn triangle_fans_cover_their_polygon_once() {
    for spokes in [3, 4, 5, 6, 8, 12, 16, 32] {
        for phase in [0.0, std::f64::consts::FRAC_PI_4, 0.1, 1.0] {
            for radius in [3.0, 7.5, 17.0] {
                check_fans(spokes, phase, radius, 120, 80);
            }
        }
    }
}

#[test]
fn fans_with_exact_axis_and_diagonal_spokes() {
    // Rim points on the axes and diagonals, so spokes run exactly through pixel centres.
    for &(cx, cy) in &[(10.5, 10.5), (30.0, 10.0), (50.5, 10.0)] {
        for r in [1.0, 2.0, 5.0, 8.0] {
            let rim = [
                (1.0, 0.0),
                (1.0, 1.0),
                (0.0, 1.0),
                (-1.0, 1.0),
                (-1.0, 0.0),
                (-1.0, -1.0),
                (0.0, -1.0),
                (1.0, -1.0),
            ];
            let mut positions = vec![px(cx, cy)];
            positions.extend(rim.iter().map(|(dx, dy)| px(cx + r * dx, cy + r * dy)));
            let indices = (0..8u32)
                .flat_map(|k| [0, 1 + k, 1 + (k + 1) % 8])
                .collect();
            let m = tests::scenes::mesh(positions, indices);
            let got = check_coverage(
                &format!("axis fan at ({cx}, {cy}) r {r}"),
                &[m],
                &pixel_camera(64, 24),
                64,
                24,
                false,
            );
            if cx % 1.0 == 0.5 && cy % 1.0 == 0.5 {
                assert_eq!(got.get(cx as u32, cy as u32), 1);
            }
        }
    }
}

/// Opaque triangles in distinct colours (exact unorm bytes), drawn with depth testing off:
/// the engine's image must equal the reference's picture of the same triangles exactly.
/// The stored golden is then the same picture, for humans to look at.
fn check_palette_scene(name: &str, meshes: &[Mesh], w: u32, h: u32) {
    let camera = pixel_camera(w, h);
    let mut scene = Scene::default();
    let mut tris = Vec::new();
    let mut colours = Vec::new();
    let mut k = 0u32;
    for m in meshes {
        for t in triangles(m) {
            // Bytes chosen by hand; colour c / 255 encodes to byte c exactly in unorm.
            let c = [
                (37 * k + 90) % 200 + 55,
                (91 * k + 30) % 200 + 55,
                (53 * k + 150) % 200 + 55,
            ];
            let rgba = Rgba::new(
                c[0] as f32 / 255.0,
                c[1] as f32 / 255.0,
                c[2] as f32 / 255.0,
                1.0,
            );
            let mat = Material {
                depth_test: false,
                double_sided: true,
                ..Material::unlit(rgba)
            };
            scene.add(tests::scenes::soup(&[t]), mat, Mat4::IDENTITY);
            tris.push(t);
            colours.push(c);
            k += 1;
        }
    }
    let (target, _) = render(&scene, &camera, w, h, Encoding::Unorm, engine::Cull::None);
    // Reference picture: black, and each pixel the colour of the (last) triangle owning it.
    let reference = Raster::new(&camera, w, h);
    let mut expected = vec![0u8; (w * h * 4) as usize];
    for px in expected.chunks_exact_mut(4) {
        px[3] = 255;
    }
    for (t, c) in tris.iter().zip(&colours) {
        let st = reference.screen_tri(*t).expect("on screen");
        for y in 0..h {
            for x in 0..w {
                if st.covers(x as i64, y as i64) {
                    let i = ((y * w + x) * 4) as usize;
                    expected[i..i + 3].copy_from_slice(&c.map(|v| v as u8));
                }
            }
        }
    }
    assert_same_image(name, w, h, &expected, &target.to_rgba8());
    check_golden(name, &target);
}

#[test]
fn golden_fans_match_the_reference_picture() {
    let fans: Vec<Mesh> = [
        (16.5, 16.5, 0.0, 8),
        (48.0, 16.0, 0.3, 5),
        (16.25, 48.75, 0.0, 12),
        (47.5, 47.5, std::f64::consts::FRAC_PI_4, 4),
    ]
    .iter()
    .map(|&(x, y, ph, n)| fan((x, y), 13.0, n, ph, &px))
    .collect();
    check_palette_scene("fill_rule_fans", &fans, 64, 64);
}

#[test]
fn golden_diagonal_grid_matches_the_reference_picture() {
    // A 45-degree lattice whose vertices are pixel centres: every edge runs through pixel
    // centres, so the picture is decided by ties alone.
    let lattice = Lattice {
        origin: (24.5, 16.5),
        a: (4.0, 4.0),
        b: (-4.0, 4.0),
        n: 7,
        diagonal: &|i, j| (i * 7 + j * 3) % 2 == 0,
        flip: &|i, j| (i + 2 * j) % 3 == 0,
        jitter: &|_, _| (0.0, 0.0),
    };
    check_palette_scene("fill_rule_diagonal_grid", &[lattice.build(&px)], 48, 32);
}

/// Vertices off the snapping grid (by 1/1024 and 3/1024 pixel, so `round(v * 256)` goes to
/// the nearest step, never to a tie): coverage must match the reference's snapped
/// triangles, e.g. an edge 1/1024 px left of a pixel centre snaps onto it.
fn check_off_grid(dx: f64, dy: f64) {
    let (w, h) = (40u32, 40u32);
    let p = |x: f64, y: f64| Vec3::new(x as f32, -(y as f32), -1.0);
    // Vertical, horizontal and diagonal edges through pixel centres (x.5), nudged.
    let tris = vec![
        [
            p(10.5 + dx, 2.5 + dy),
            p(10.5 + dx, 30.5 - dy),
            p(30.5 - dx, 2.5 + dy),
        ],
        [
            p(10.5 + dx, 30.5 - dy),
            p(30.5 - dx, 30.5 - dy),
            p(30.5 - dx, 2.5 + dy),
        ],
        [
            p(2.5 + dx, 33.5 + dy),
            p(37.5 - dx, 38.5 + dy),
            p(2.5 - dx, 38.5 - dy),
        ],
    ];
    check_coverage(
        &format!("off-grid by ({dx}, {dy})"),
        &[tests::scenes::soup(&tris)],
        &pixel_camera(w, h),
        w,
        h,
        false,
    );
}

#[test]
fn snapping_rounds_to_the_nearest_256th() {
    for k in [-3.0, -1.0, 1.0, 3.0] {
        for j in [-3.0, -1.0, 0.0, 1.0, 3.0] {
            check_off_grid(k / 1024.0, j / 1024.0);
        }
    }
}
