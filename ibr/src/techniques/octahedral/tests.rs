//! The octahedral mapping against its inverse, frame selection and its continuity, the
//! impostor's image against the geometry it replaces (at baked views, between them, for a
//! coarse and a fine grid), memory reuse, thread-count independence and odd inputs.

use super::*;
use crate::core::MeshGroup;
use crate::metrics::{compare, covered_rect, Coverage, ImageError, Options, Region};
use engine::procedural::{cuboid, torus, XorShift};
use engine::{FrameOptions, Renderer, Target};

/// `n` roughly uniform unit directions (a Fibonacci sphere), poles included.
fn directions(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * i as f32 / (n - 1) as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let a = golden * i as f32;
            Vec3::new(r * a.cos(), y, r * a.sin()).normalize()
        })
        .collect()
}

/// A tilted torus coloured by its normals with a box through it, lit: every view differs.
fn subject() -> MeshGroup {
    let lit = Arc::new(Material::lit(Rgba::WHITE));
    let tilt = Mat4::from_rotation_x(0.6) * Mat4::from_rotation_z(0.3);
    let mut block = cuboid(Vec3::new(0.5, 1.4, 0.3));
    block.colors = vec![Rgba::new(0.9, 0.5, 0.1, 1.0); block.positions.len()];
    MeshGroup::new()
        .with(Arc::new(torus(0.8, 0.3, 32, 12)), lit.clone(), tilt)
        .with(
            Arc::new(block),
            lit,
            Mat4::from_translation(Vec3::new(0.3, 0.1, 0.0)),
        )
}

fn bake(grid: u32, px: u32, layout: Layout) -> (MeshGroup, OctahedralImpostor) {
    let mut s = subject();
    let imp = OctahedralImpostor::bake(&mut s, &Lighting::default(), grid, px, layout);
    (s, imp)
}

/// A narrow perspective camera far along `dir` whose image plane at the centre spans
/// exactly the impostor's `2r` quad, upright as the frames are.
fn far_camera(b: Sphere, dir: Vec3) -> Camera {
    let dist = 400.0 * b.radius;
    let (_, up) = basis(dir);
    Camera::look_at(
        b.center + dir * dist,
        b.center,
        up,
        2.0 * (b.radius / dist).atan(),
        1.0,
    )
    .with_depth_range(dist - 2.0 * b.radius, dist + 2.0 * b.radius)
}

fn render(draws: Vec<Draw<'_>>, camera: &Camera, px: u32) -> Target {
    let mut t = Target::new(px, px);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    Renderer::new().render(draws, camera, &Lighting::default(), &mut t, &opts);
    t
}

/// The impostor seen from `dir` against the geometry, over both images' covered area.
fn error(s: &MeshGroup, imp: &mut OctahedralImpostor, dir: Vec3) -> ImageError {
    let cam = far_camera(imp.info().bounds, dir);
    let px = imp.info().frame_px;
    imp.update(&cam);
    let got = render(vec![imp.draw()], &cam, px);
    let mut draws = Vec::new();
    s.draws(&mut draws);
    let want = render(draws, &cam, px);
    let rect = covered_rect(&got, Coverage::Alpha)
        .unwrap_or_default()
        .union(covered_rect(&want, Coverage::Alpha).unwrap_or_default())
        .grow(1, px, px);
    let opts = Options {
        region: Region::Rect(rect),
        ..Default::default()
    };
    compare(&got, &want, &opts).expect("same size, something covered")
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Deterministic view directions away from the baked ones (upper hemisphere and a bit
/// below, where most cameras are).
fn views(n: usize, seed: u64) -> Vec<Vec3> {
    let mut rng = XorShift::new(seed);
    (0..n)
        .map(|_| {
            let (az, el) = (rng.range(0.0, std::f32::consts::TAU), rng.range(-0.4, 1.3));
            Vec3::new(el.cos() * az.cos(), el.sin(), el.cos() * az.sin())
        })
        .collect()
}

#[test]
fn octahedral_mapping_round_trips() {
    for d in directions(2000) {
        let uv = encode(Layout::Full, d);
        assert!(uv.abs().max_element() <= 1.0, "{d} -> {uv}");
        assert!(decode(Layout::Full, uv).distance(d) < 1e-5, "{d}");
        let uv = encode(Layout::Hemi, d);
        assert!(uv.abs().max_element() <= 1.0, "{d} -> {uv}");
        let back = decode(Layout::Hemi, uv);
        assert!(back.y >= 0.0);
        // Below the horizon: clamped to the horizon in the same azimuth.
        let want = if d.y >= 0.0 {
            d
        } else {
            Vec3::new(d.x, 0.0, d.z).normalize_or(Vec3::Z)
        };
        assert!(back.distance(want) < 1e-5, "{d}: {back} vs {want}");
    }
    // encode(decode(p)) = p inside the square (its edges are folds: two points, one view).
    let m = 41;
    for layout in [Layout::Full, Layout::Hemi] {
        for i in 0..m {
            for j in 0..m {
                let p = cell_uv(m, i, j);
                let back = encode(layout, decode(layout, p));
                assert!(back.distance(p) < 1e-5, "{layout:?} {p} -> {back}");
            }
        }
        for n in 1..=9 {
            for k in 0..n * n {
                let d = decode(layout, cell_uv(n, k % n, k / n));
                assert!((d.length() - 1.0).abs() < 1e-6);
                assert!(layout == Layout::Full || d.y >= 0.0);
            }
        }
        for odd in [
            Vec3::ZERO,
            Vec3::NAN,
            Vec3::NEG_Y,
            Vec3::splat(f32::INFINITY),
        ] {
            let uv = encode(layout, odd);
            assert!(uv.is_finite() && decode(layout, uv).is_normalized());
        }
        assert!(decode(layout, Vec2::NAN).is_normalized());
        assert!(decode(layout, Vec2::splat(7.0)).is_normalized());
    }
    // Poles and the full layout's south pole at the corners.
    assert_eq!(decode(Layout::Full, Vec2::ZERO), Vec3::Y);
    assert!(decode(Layout::Full, Vec2::ONE).distance(Vec3::NEG_Y) < 1e-6);
    assert_eq!(decode(Layout::Hemi, Vec2::ZERO), Vec3::Y);
}

#[test]
fn basis_is_orthonormal_and_faces_the_direction() {
    let mut dirs = directions(500);
    dirs.extend([Vec3::Y, Vec3::NEG_Y, Vec3::new(0.001, 1.0, 0.0).normalize()]);
    for d in dirs {
        let (r, u) = basis(d);
        assert!((r.length() - 1.0).abs() < 1e-5 && (u.length() - 1.0).abs() < 1e-5);
        assert!(r.dot(u).abs() < 1e-5 && r.dot(d).abs() < 1e-5);
        assert!(r.cross(u).distance(d) < 1e-5, "{d}");
        if d.y.abs() <= POLE {
            assert!(u.y >= 0.0, "upright away from the poles: {d}");
        }
    }
}

#[test]
fn the_view_along_a_baked_direction_picks_that_frame() {
    for layout in [Layout::Full, Layout::Hemi] {
        for n in [2, 3, 6, 9] {
            for k in 0..n * n {
                let d = decode(layout, cell_uv(n, k % n, k / n));
                let (idx, w) = select(layout, n, encode(layout, d));
                let got: f32 = (0..3).filter(|&m| idx[m] == k).map(|m| w[m]).sum();
                assert!(got > 0.999, "{layout:?} n {n} frame {k}: {idx:?} {w:?}");
            }
        }
    }
    let mut rng = XorShift::new(3);
    for _ in 0..2000 {
        let uv = Vec2::new(rng.range(-1.2, 1.2), rng.range(-1.2, 1.2));
        for layout in [Layout::Full, Layout::Hemi] {
            let (idx, w) = select(layout, 5, uv);
            assert!(w.iter().all(|&x| x >= 0.0) && (w.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            assert!(idx.iter().all(|&i| i < 25));
        }
    }
}

/// Weights per frame along a spiral from pole to pole (crossing every fold of the full
/// octahedron and the hemi one's horizon): the L1 change per step is bounded by a constant
/// times the step angle, so no frame ever pops in or out.
#[test]
fn weights_change_continuously_along_a_path() {
    let steps = 40_000;
    for layout in [Layout::Full, Layout::Hemi] {
        let n = 6;
        let weights = |d: Vec3| {
            let (idx, w) = select(layout, n, encode(layout, d));
            let mut all = [0.0f32; 36];
            for k in 0..3 {
                all[idx[k] as usize] += w[k];
            }
            all
        };
        // The hemi layout clamps views below the horizon to it, which turns fast near
        // straight down: its path stops 30 degrees below the horizon.
        let end = match layout {
            Layout::Full => std::f32::consts::PI - 0.01,
            Layout::Hemi => std::f32::consts::FRAC_PI_2 + 0.5,
        };
        let at = |t: f32| {
            let polar = 0.01 + t * (end - 0.01);
            let az = t * 7.0 * std::f32::consts::TAU + 0.3;
            Vec3::new(polar.sin() * az.cos(), polar.cos(), polar.sin() * az.sin())
        };
        let (mut prev_d, mut prev) = (at(0.0), weights(at(0.0)));
        let mut worst = 0.0f32;
        for s in 1..=steps {
            let d = at(s as f32 / steps as f32);
            let w = weights(d);
            let change: f32 = w.iter().zip(&prev).map(|(a, b)| (a - b).abs()).sum();
            // The chord: `angle_between` (an acos) is too coarse for steps this small.
            let angle = d.distance(prev_d).max(1e-7);
            worst = worst.max(change / angle);
            (prev_d, prev) = (d, w);
        }
        println!("{layout:?} n {n}: largest weight change {worst:.1} per radian");
        // Grid cells are about 3.5 / n radians across: a few times n per radian.
        assert!(worst < 8.0 * n as f32, "{layout:?}: {worst}");
    }
}

#[test]
fn baked_views_match_the_geometry() {
    for layout in [Layout::Full, Layout::Hemi] {
        let (s, mut imp) = bake(6, 64, layout);
        assert_eq!(imp.bake_renders(), 36);
        assert_eq!(imp.atlas().size().0, 6 * 64);
        let (mut psnr, mut ortho) = (Vec::new(), Vec::new());
        for k in [0, 7, 14, 21, 28, 35] {
            let d = imp.frame_direction(k).unwrap();
            let e = error(&s, &mut imp, d);
            let (idx, w) = imp.frames();
            let on_k: f32 = (0..3).filter(|&m| idx[m] == k).map(|m| w[m]).sum();
            assert!(on_k > 0.999, "{idx:?} {w:?}");
            psnr.push(e.psnr_db);
            // Perspective from 400 r against the orthographic bake: silhouettes move by
            // up to a tenth of a pixel, enough to flip some aliased edge pixels.
            assert!(e.psnr_db > 28.0, "{layout:?} frame {k}: {e:?}");
            // Through the bake's own orthographic camera the pipeline is nearly lossless.
            let cam = frame_camera(imp.info().bounds.center, imp.info().bounds.radius, d);
            imp.update(&cam);
            let got = render(vec![imp.draw()], &cam, 64);
            let mut draws = Vec::new();
            s.draws(&mut draws);
            let want = render(draws, &cam, 64);
            let e = compare(&got, &want, &Options::default()).unwrap();
            ortho.push(e.psnr_capped(99.0));
            assert!(
                e.psnr_db > 45.0 && e.max_abs <= 8,
                "{layout:?} frame {k}: {e:?}"
            );
        }
        println!("{layout:?} at baked views: PSNR {psnr:.1?} dB, orthographic {ortho:.1?} dB");
    }
}

#[test]
fn blending_is_not_worse_than_the_nearest_frame_between_views() {
    let (s, mut imp) = bake(6, 64, Layout::Full);
    let (mut blend, mut near) = (Vec::new(), Vec::new());
    for d in views(12, 11) {
        imp.set_blend(Blend::Three);
        blend.push(error(&s, &mut imp, d).mse);
        imp.set_blend(Blend::Nearest);
        near.push(error(&s, &mut imp, d).mse);
        assert_eq!(imp.frames().1, [1.0, 0.0, 0.0]);
    }
    let db = |mse: f64| 10.0 * (255.0f64 * 255.0 / mse).log10();
    let (b, n) = (mean(&blend), mean(&near));
    println!(
        "between views, n 6: blend mse {b:.1} ({:.1} dB), nearest mse {n:.1} ({:.1} dB)",
        db(b),
        db(n)
    );
    assert!(b <= n * 1.1, "blend {b} vs nearest {n}");
}

#[test]
fn error_grows_as_the_grid_coarsens() {
    let dirs = views(10, 5);
    let mut means = Vec::new();
    for n in [4, 12] {
        let (s, mut imp) = bake(n, 48, Layout::Full);
        let e: Vec<f64> = dirs.iter().map(|&d| error(&s, &mut imp, d).mse).collect();
        means.push(mean(&e));
        println!(
            "n {n}: mean mse {:.1} between views, {} bytes",
            mean(&e),
            imp.bytes()
        );
    }
    assert!(means[0] > means[1] * 1.2, "{means:?}");
}

/// The composed image as the eye moves in 0.25-degree steps over several cells: blended
/// it changes a little each step; the nearest frame jumps when the frame changes.
#[test]
fn the_blended_image_changes_continuously() {
    let (_, mut imp) = bake(5, 48, Layout::Full);
    let image =
        |imp: &OctahedralImpostor| imp.image().expect("composed").levels()[0].texels.clone();
    let diff = |a: &[u32], b: &[u32]| {
        let sum: u64 = a
            .iter()
            .zip(b)
            .flat_map(|(x, y)| {
                (0..4).map(move |k| (x >> (8 * k) & 255).abs_diff(y >> (8 * k) & 255))
            })
            .map(u64::from)
            .sum();
        sum as f64 / (a.len() * 4) as f64
    };
    let mut worst = [0.0f64; 2];
    for (m, blend) in [Blend::Three, Blend::Nearest].into_iter().enumerate() {
        imp.set_blend(blend);
        let mut prev = None;
        for s in 0..240 {
            let a = (s as f32 * 0.25).to_radians();
            let d = Vec3::new(a.cos(), 0.3 + 0.2 * a.sin(), a.sin()).normalize();
            imp.update(&far_camera(imp.info().bounds, d));
            let img = image(&imp);
            if let Some(p) = prev.replace(img.clone()) {
                worst[m] = worst[m].max(diff(&p, &img));
            }
        }
    }
    println!(
        "largest per-step mean change: blend {:.2}, nearest {:.2} levels",
        worst[0], worst[1]
    );
    assert!(worst[0] < 1.5, "{worst:?}");
    assert!(worst[1] > 2.0 * worst[0], "{worst:?}");
}

#[test]
fn warm_updates_do_not_allocate() {
    let (_, mut imp) = bake(4, 32, Layout::Hemi);
    let state = |imp: &OctahedralImpostor| {
        let m = &imp.mesh;
        let tex = imp.image().expect("composed");
        let levels: Vec<(*const u32, usize)> = tex
            .levels()
            .iter()
            .map(|l| (l.texels.as_ptr(), l.texels.capacity()))
            .collect();
        (
            [
                m.positions.capacity(),
                m.uvs.capacity(),
                m.colors.capacity(),
                m.indices.capacity(),
            ],
            levels,
        )
    };
    let cam = |i: usize| {
        let a = i as f32 * 0.21;
        Camera::look_at(
            Vec3::new(a.cos() * 6.0, 2.0 + a.sin(), a.sin() * 6.0),
            Vec3::ZERO,
            Vec3::Y,
            1.0,
            1.0,
        )
    };
    imp.update(&cam(0));
    let warm = state(&imp);
    let mut recomposed = 0;
    for i in 1..=30 {
        recomposed += imp.update(&cam(i)) as u32;
        assert_eq!(state(&imp), warm, "update {i}");
    }
    assert_eq!(recomposed, 30);
    assert!(!imp.update(&cam(30)), "same view: nothing to recompose");
}

#[test]
fn identical_at_one_and_two_threads() {
    let run = || {
        let (_, mut imp) = bake(4, 32, Layout::Full);
        let cam = far_camera(imp.info().bounds, Vec3::new(0.4, 0.5, 0.7).normalize());
        imp.update(&cam);
        let frame = render(vec![imp.draw()], &cam, 40).to_rgba8_premultiplied();
        (
            imp.atlas().clone(),
            imp.image().expect("composed").clone(),
            frame,
        )
    };
    let in_pool = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(run)
    };
    assert!(in_pool(1) == in_pool(2));
}

#[test]
fn odd_inputs_do_not_panic() {
    let mut s = subject();
    let light = Lighting::default();
    let imp = OctahedralImpostor::bake(&mut s, &light, 0, 0, Layout::Full);
    assert_eq!(
        (imp.info().grid, imp.info().frame_px),
        (MIN_GRID, MIN_FRAME_PX)
    );
    let imp = OctahedralImpostor::bake(&mut s, &light, 1, 8, Layout::Hemi);
    assert_eq!(imp.info().grid, MIN_GRID);
    let imp = OctahedralImpostor::bake(&mut s, &light, 1000, 1000, Layout::Full);
    assert_eq!(imp.info().grid, MAX_GRID);
    assert!(imp.info().grid * imp.info().frame_px <= MAX_ATLAS_SIDE);

    let (_, mut imp) = bake(3, 16, Layout::Full);
    let c = imp.info().bounds.center;
    let before = (imp.frames(), imp.image().expect("composed").clone());
    // Eye at the centre, NaN and infinite cameras: the last image stays.
    assert!(!imp.update(&Camera::look_at(c, c + Vec3::Z, Vec3::Y, 1.0, 1.0)));
    let mut nan = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0);
    nan.view.w_axis.x = f32::NAN;
    assert!(!imp.update(&nan));
    nan.view = Mat4::from_cols_array(&[f32::INFINITY; 16]);
    assert!(!imp.update(&nan));
    assert_eq!(
        (imp.frames(), imp.image().expect("composed").clone()),
        before
    );
    // Straight down on a hemi impostor: the horizon frames; straight up and down on a full
    // one; an orthographic camera uses its view direction.
    let (_, mut hemi) = bake(3, 16, Layout::Hemi);
    hemi.update(&Camera::look_at(
        Vec3::NEG_Y * 5.0,
        Vec3::ZERO,
        Vec3::Z,
        1.0,
        1.0,
    ));
    let (idx, w) = hemi.frames();
    let k = idx[(0..3).fold(0, |b, m| if w[m] > w[b] { m } else { b })];
    assert!(hemi.frame_direction(k).unwrap().y < 0.5);
    for eye in [Vec3::Y, Vec3::NEG_Y] {
        imp.update(&Camera::look_at(c + eye * 5.0, c, Vec3::Z, 1.0, 1.0));
        assert!(imp.draw().mesh.positions.iter().all(|p| p.is_finite()));
    }
    let ortho = Camera {
        view: Mat4::look_at_rh(Vec3::new(0.0, 0.0, 9.0), Vec3::ZERO, Vec3::Y),
        projection: Projection::Orthographic {
            left: -1.0,
            right: 1.0,
            bottom: -1.0,
            top: 1.0,
            near: 0.1,
            far: 20.0,
        },
    };
    imp.update(&ortho);
    let (idx, w) = imp.frames();
    let d: Vec3 = (0..3)
        .map(|m| imp.frame_direction(idx[m]).unwrap() * w[m])
        .sum();
    assert!(d.normalize().z > 0.8, "{d}");
    // An empty subject: a tiny, transparent impostor.
    let mut empty = MeshGroup::new();
    let mut imp = OctahedralImpostor::bake(&mut empty, &light, 2, 4, Layout::Full);
    assert!(imp.info().bounds.radius > 0.0);
    imp.update(&ortho);
    assert!(imp.image().expect("composed").levels()[0]
        .texels
        .iter()
        .all(|&t| t == 0));
    assert!(imp.bytes() > 0 && imp.info().version == 0);
}
