//! The fundamental matrix against the one two known cameras give, the prewarp's rows, and
//! the morph from point pairs against the morph from cameras, on the morph tests' cards.

use super::super::tests::{covered, looking, psnr, verged, views};
use super::*;
use crate::stereo::scenes::{H, W};
use crate::techniques::morph::fundamental::FundamentalError;
use crate::techniques::morph::{plain_morph, Correspondence};
use engine::procedural::XorShift;
use glam::{DMat4, Vec2, Vec3};

/// `F = K_b^-T [t]_x R K_a^-1` for pixels (x right, y down) of `W` x `H` images of `a`
/// and `b`: from the cameras' matrices, not from any points.
fn analytic(a: &Camera, b: &Camera) -> DMat3 {
    let k = |c: &Camera| {
        let p = c.projection.gl_matrix().as_dmat4();
        // Camera space (looking down -z) to clip x, y, w; then clip to pixels.
        let rows = |r: usize| [p.row(r).x, p.row(r).y, p.row(r).z];
        let (x, y, w) = (rows(0), rows(1), rows(3));
        let clip = from_rows(&[x[0], x[1], x[2], y[0], y[1], y[2], w[0], w[1], w[2]]);
        let (w2, h2) = (f64::from(W) * 0.5, f64::from(H) * 0.5);
        from_rows(&[w2, 0.0, w2, 0.0, -h2, h2, 0.0, 0.0, 1.0]) * clip
    };
    let view = |c: &Camera| {
        let v: DMat4 = c.view.as_dmat4();
        (DMat3::from_mat4(v), v.w_axis.truncate())
    };
    let ((ra, ta), (rb, tb)) = (view(a), view(b));
    let r = rb * ra.transpose();
    let t = tb - r * ta;
    k(b).inverse().transpose() * cross_matrix(t) * r * k(a).inverse()
}

/// `m` scaled to unit Frobenius norm.
fn unit(m: DMat3) -> DMat3 {
    let n = m.to_cols_array().iter().map(|v| v * v).sum::<f64>().sqrt();
    m * (1.0 / n)
}

/// The largest entry of `a - b` or of `a + b`, whichever is smaller: equal up to sign.
fn apart(a: DMat3, b: DMat3) -> f64 {
    let largest = |m: DMat3| m.to_cols_array().iter().fold(0f64, |x, v| x.max(v.abs()));
    largest(a - b).min(largest(a + b))
}

/// `n` random points in front of both cameras, seen by both inside the image: their
/// pixels in each.
fn pairs(a: &Camera, b: &Camera, n: usize, seed: u64) -> Vec<(Vec2, Vec2)> {
    let mut rng = XorShift::new(seed);
    let mut out = Vec::new();
    while out.len() < n {
        let p = Vec3::new(
            rng.range(-2.0, 2.0),
            rng.range(-1.5, 1.5),
            rng.range(-2.0, 2.0),
        );
        let inside = |q: Vec2| q.x >= 0.0 && q.y >= 0.0 && q.x < W as f32 && q.y < H as f32;
        if let (Some((pa, _)), Some((pb, _))) = (project(a, p, W, H), project(b, p, W, H)) {
            if inside(pa) && inside(pb) {
                out.push((pa, pb));
            }
        }
    }
    out
}

/// A normally distributed number (Box and Muller), standard deviation `sigma`.
fn gauss(rng: &mut XorShift, sigma: f32) -> f32 {
    let (u, v) = (rng.next_f32().max(1e-7), rng.next_f32());
    sigma * (-2.0 * u.ln()).sqrt() * (std::f32::consts::TAU * v).cos()
}

#[test]
fn the_eight_point_algorithm_finds_the_cameras_fundamental_matrix() {
    let (a, b) = verged();
    let truth = unit(analytic(&a, &b));
    for n in [8, 30] {
        let pairs = pairs(&a, &b, n, 3);
        // The reference is right: the points satisfy it.
        for &(pa, pb) in &pairs {
            let r = pb
                .as_dvec2()
                .extend(1.0)
                .dot(truth * pa.as_dvec2().extend(1.0));
            assert!(r.abs() < 1e-5, "{r}");
        }
        let f = Fundamental::from_points(&pairs).expect("a fundamental matrix");
        let off = apart(f.matrix(), truth);
        let worst = pairs
            .iter()
            .map(|&(pa, pb)| f.distance(pa, pb))
            .fold(0.0, f64::max);
        // (Measured: 3e-6 and 2e-7 from it, 6e-6 and 1e-5 px from the lines.)
        eprintln!("{n} pairs: {off:.2e} from the cameras' F, {worst:.2e} px from the lines");
        assert!(
            off < 1e-4,
            "{n} pairs: {off:.2e}\n{:?}\n{truth:?}",
            f.matrix()
        );
        assert!(worst < 1e-3, "{worst}");
        // Rank 2, and the epipoles are its null vectors and where each eye sees the other.
        let m = f.matrix();
        assert!(m.determinant().abs() < 1e-12, "{}", m.determinant());
        assert!((m * f.epipole_a()).length() < 1e-12);
        assert!((m.transpose() * f.epipole_b()).length() < 1e-12);
        let seen = |c: &Camera, eye: Vec3| {
            let clip = c.gl_view_proj().as_dmat4() * eye.as_dvec3().extend(1.0);
            let (w2, h2) = (f64::from(W) * 0.5, f64::from(H) * 0.5);
            DVec3::new(w2 * (clip.x + clip.w), h2 * (clip.w - clip.y), clip.w).normalize()
        };
        for (e, want) in [
            (f.epipole_a(), seen(&a, b.eye())),
            (f.epipole_b(), seen(&b, a.eye())),
        ] {
            assert!(e.dot(want).abs() > 1.0 - 1e-6, "{e:?} against {want:?}");
        }
    }
}

#[test]
fn half_a_pixel_of_noise_keeps_the_epipolar_lines_within_a_pixel() {
    let (a, b) = verged();
    let mut rng = XorShift::new(9);
    let exact = pairs(&a, &b, 60, 5);
    let noisy: Vec<(Vec2, Vec2)> = exact
        .iter()
        .map(|&(pa, pb)| {
            let mut jitter = || Vec2::new(gauss(&mut rng, 0.5), gauss(&mut rng, 0.5));
            (pa + jitter(), pb + jitter())
        })
        .collect();
    let f = Fundamental::from_points(&noisy).expect("a fundamental matrix");
    let mean = |set: &[(Vec2, Vec2)]| {
        set.iter().map(|&(pa, pb)| f.distance(pa, pb)).sum::<f64>() / set.len() as f64
    };
    // Fresh exact pairs, not fitted: how far the estimate's lines are from the truth.
    let fresh = pairs(&a, &b, 60, 6);
    let (on_noisy, on_fresh) = (mean(&noisy), mean(&fresh));
    // (Measured: 0.59 px on the noisy pairs, 0.28 px on fresh exact ones.)
    eprintln!("mean distance {on_noisy:.2} px on the noisy pairs, {on_fresh:.2} px on fresh ones");
    assert!(on_noisy < 1.0 && on_fresh < 1.0, "{on_noisy} {on_fresh}");
    assert!(f.matrix().determinant().abs() < 1e-12);
}

#[test]
fn too_few_degenerate_and_non_finite_pairs_are_errors() {
    let (a, b) = verged();
    let good = pairs(&a, &b, 12, 7);
    assert_eq!(
        Fundamental::from_points(&good[..7]),
        Err(FundamentalError::TooFew(7))
    );
    let mut nan = good.clone();
    nan[4].1.y = f32::NAN;
    assert_eq!(
        Fundamental::from_points(&nan),
        Err(FundamentalError::NotFinite(4))
    );
    // All on one line in both images.
    let line: Vec<(Vec2, Vec2)> = (0..12)
        .map(|i| {
            let t = i as f32 * 10.0;
            (
                Vec2::new(10.0 + t, 20.0 + 0.5 * t),
                Vec2::new(5.0 + t, 22.0 + 0.5 * t),
            )
        })
        .collect();
    let err = Fundamental::from_points(&line).unwrap_err();
    assert!(matches!(err, FundamentalError::Degenerate(_)), "{err}");
    // All on one plane: a family of matrices fits them.
    let mut rng = XorShift::new(17);
    let plane: Vec<(Vec2, Vec2)> = (0..40)
        .filter_map(|_| {
            let p = Vec3::new(rng.range(-1.5, 1.5), rng.range(-1.0, 1.0), 0.0);
            Some((project(&a, p, W, H)?.0, project(&b, p, W, H)?.0))
        })
        .collect();
    let err = Fundamental::from_points(&plane).unwrap_err();
    assert!(matches!(err, FundamentalError::Degenerate(_)), "{err}");
    let same = vec![(Vec2::new(3.0, 4.0), Vec2::new(5.0, 6.0)); 10];
    assert_eq!(
        Fundamental::from_points(&same),
        Err(FundamentalError::Coincident("first"))
    );
    // Through the morph: an error, no panic.
    let blank = DepthImage::new(W, H, a);
    let err = ViewMorph::from_points(&blank, &blank, &line, 64).unwrap_err();
    assert!(matches!(err, MorphError::Fundamental(_)), "{err}");
}

#[test]
fn the_prewarp_puts_pairs_on_one_row() {
    let (a, b) = verged();
    let fitted = pairs(&a, &b, 30, 11);
    let f = Fundamental::from_points(&fitted).expect("a fundamental matrix");
    let prewarp = Prewarp::new(&f, &fitted, (W, H)).expect("a prewarp");
    // On the pairs it was fitted to and on others.
    let others = pairs(&a, &b, 100, 12);
    let (mut dy, mut lo) = (0f32, f32::INFINITY);
    for &(pa, pb) in fitted.iter().chain(&others) {
        let (qa, qb) = (prewarp.map_a(pa), prewarp.map_b(pb));
        dy = dy.max((qa.y - qb.y).abs());
        lo = lo.min(qa.x - qb.x);
    }
    // (Measured: 2e-5 px; disparities 8.1 to 49.6 on the fitted pairs, 5.5 at least on
    // the others.)
    eprintln!(
        "rows {dy:.2e} px apart at most; disparities {:.1} to {:.1}, {lo:.1} on others",
        prewarp.disparities.0, prewarp.disparities.1
    );
    assert!(dy < 0.5, "{dy}");
    assert!(prewarp.disparities.0 > 0.0);
}

/// Pairs from the known depth of `views[0]`: a grid of pixels, those whose point `views[1]`
/// sees (not hidden there); with the points.
fn pairs_from_depth(v: &[DepthImage]) -> Vec<((Vec2, Vec2), Vec3)> {
    let (a, b) = (&v[0], &v[1]);
    let mut out = Vec::new();
    for gy in 0..8 {
        for gx in 0..10 {
            let (x, y) = (8 + gx * 16, 7 + gy * 15);
            let Some(point) = a.world_point(x, y) else {
                continue;
            };
            let Some((pb, z)) = project(&b.camera, point, W, H) else {
                continue;
            };
            let seen = b
                .get(pb.x as u32, pb.y as u32)
                .is_some_and(|(_, zb)| (zb - z).abs() < 0.02 * z);
            if pb.x >= 0.0 && pb.y >= 0.0 && seen {
                out.push(((Vec2::new(x as f32 + 0.5, y as f32 + 0.5), pb), point));
            }
        }
    }
    out
}

#[test]
fn the_morph_from_points_ends_at_the_views_and_follows_the_camera_morph() {
    let (a, b) = verged();
    let v = views(&[a, b]);
    let found = pairs_from_depth(&v);
    let pairs: Vec<(Vec2, Vec2)> = found.iter().map(|f| f.0).collect();
    assert!(pairs.len() >= 20, "{} pairs", pairs.len());
    let morph = ViewMorph::from_points(&v[0], &v[1], &pairs, 96).expect("morphable");
    for (s, view) in [(0.0, &v[0]), (1.0, &v[1])] {
        let (image, _) = morph.frame(s);
        let (p, c) = (psnr(&image, view), covered(&image, view));
        // (Measured: 24.3 and 23.4 dB over every pixel; from cameras 26.7 and 24.6.)
        eprintln!("s {s}: {p:.1} dB over {:.1}% of the view", 100.0 * c);
        assert!(
            p > 20.0 && c > 0.8,
            "s {s}: {p:.1} dB over {:.1}%",
            100.0 * c
        );
    }
    let cameras = ViewMorph::new(&v[0], &v[1], Correspondence::Stereo { max_disparity: 96 })
        .expect("morphable");
    let truth = views(&[cameras.camera_at(0.5)]).remove(0);
    let (points, stats) = morph.frame(0.5);
    let (calibrated, _) = cameras.frame(0.5);
    let plain = plain_morph(&v[0], &v[1], 0.5);
    let against = psnr(&points, &calibrated);
    let (p_points, p_cameras, p_plain) = (
        psnr(&points, &truth),
        psnr(&calibrated, &truth),
        psnr(&plain, &truth),
    );
    eprintln!(
        "s 0.5: from points {against:.1} dB against the camera morph over {:.1}%; against the \
         cameras' in-between view: points {p_points:.1}, cameras {p_cameras:.1}, plain \
         {p_plain:.1} dB; {stats:?}",
        100.0 * covered(&points, &calibrated)
    );
    assert!(stats.from_left > 0 && stats.from_right > 0, "{stats:?}");
    // Where the halfway view from points puts the pairs' points (their prewarped positions
    // averaged, then the interpolated postwarp), against where the cameras' halfway view
    // sees them: how far apart the two in-between views are.
    let post = morph.postwarp.expect("a morph from points");
    let (ha, hb) = (post.a.inverse(), post.b.inverse());
    let halfway = (post.a + post.b) * 0.5;
    let offsets: Vec<f32> = found
        .iter()
        .filter_map(|&((pa, pb), point)| {
            let (qa, qb) = (apply(&ha, pa.as_dvec2()), apply(&hb, pb.as_dvec2()));
            let at = apply(&halfway, (qa + qb) * 0.5).as_vec2();
            let (seen, _) = project(&cameras.camera_at(0.5), point, W, H)?;
            Some(at.distance(seen))
        })
        .collect();
    let mean = offsets.iter().sum::<f32>() / offsets.len() as f32;
    let worst = offsets.iter().fold(0f32, |m, &d| m.max(d));
    eprintln!("points {mean:.2} px from the cameras' halfway view on average, {worst:.2} at most");
    // (Measured: 1.26 px on average, 2.57 at most; the two halfway frames 18.8 dB apart
    // over 99.6%; against the cameras' halfway view 16.6 dB from points, 17.8 from cameras,
    // 18.1 for the plain morph, which has the exact depth where the others match.)
    assert!(mean < 3.0 && worst < 6.0, "{mean:.2} px, {worst:.2} px");
    assert!(against > 15.5, "{against:.1} dB");
    assert!(
        p_points > p_cameras - 3.0,
        "{p_points:.1} dB, {p_cameras:.1} dB"
    );
}

#[test]
fn motion_toward_the_scene_is_refused_without_cameras() {
    // The second eye straight ahead of the first: its epipole is in the image.
    let a = looking(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO);
    let b = looking(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO);
    let pairs = pairs(&a, &b, 30, 13);
    let blank = |c| DepthImage::new(W, H, c);
    let err = ViewMorph::from_points(&blank(a), &blank(b), &pairs, 64).unwrap_err();
    assert!(
        matches!(err, MorphError::EpipoleInImage { image: "first", .. }),
        "{err}"
    );
    assert!(err.to_string().contains("epipole"), "{err}");
}

/// Pixel position and view depth of `p` in a `width` x `height` image of `camera`, `None`
/// behind the near plane (as the layers' fitted projection does it).
fn project(camera: &Camera, p: Vec3, width: u32, height: u32) -> Option<(Vec2, f32)> {
    let z = -(camera.view * p.extend(1.0)).z;
    if z.is_nan() || z <= camera.near_far().0 {
        return None;
    }
    let clip = camera.gl_view_proj() * p.extend(1.0);
    let (x, y) = (clip.x / clip.w, clip.y / clip.w);
    let px = Vec2::new(x + 1.0, 1.0 - y) * 0.5 * Vec2::new(width as f32, height as f32);
    px.is_finite().then_some((px, z))
}
