//! Sparse capture against dense capture and the geometry: the slab's own cameras rebin to
//! the dense light field, scattered photographs to one close to the geometry, and regions
//! no photograph saw are filled and reported as invented.

use super::tests::{camera, compare, slab, truth, Card, H, W};
use super::*;
use crate::capture::capture_batch;
use crate::warp::Warped;

/// Photographs of `draws` from `eyes`, all looking at the origin.
fn photographs(draws: &[Draw<'_>], eyes: &[Vec3], size: u32) -> Vec<crate::images::DepthImage> {
    let cameras: Vec<Camera> = eyes
        .iter()
        .map(|&e| Camera::look_at(e, Vec3::ZERO, Vec3::Y, 0.9, 1.0).with_depth_range(0.1, 30.0))
        .collect();
    capture_batch(draws, &cameras, &Lighting::default(), size, size)
}

#[test]
fn the_slabs_own_cameras_rebin_to_the_dense_capture() {
    let card = Card::new(0.3, 1.6);
    let draws = [card.draw()];
    let s = slab(4, 24);
    let dense = LightField::capture(&draws, &Lighting::default(), s);
    let cameras: Vec<Camera> = (0..s.nv)
        .flat_map(|j| (0..s.nu).map(move |i| s.camera(i, j)))
        .collect();
    let images = capture_batch(&draws, &cameras, &Lighting::default(), s.ns, s.nt);
    let sparse = rebin(s, &images);
    assert_eq!(sparse.rays, s.len() as u64);
    assert_eq!(sparse.invented(), 0.0);
    assert!(sparse.confident() > 0.99, "{}", sparse.confident());
    for v in 0..s.nv {
        for u in 0..s.nu {
            for t in 0..s.nt {
                for st in 0..s.ns {
                    let (a, b) = (
                        sparse.field.sample(u, v, st, t).to_le_bytes(),
                        dense.sample(u, v, st, t).to_le_bytes(),
                    );
                    for k in 0..4 {
                        assert!(a[k].abs_diff(b[k]) <= 2, "({u} {v} {st} {t}): {a:?} {b:?}");
                    }
                    let (za, zb) = (
                        sparse.field.depth_at(u, v, st, t),
                        dense.depth_at(u, v, st, t),
                    );
                    assert!(
                        za == zb || (za - zb).abs() < 1e-3 * zb,
                        "({u} {v} {st} {t}): {za} {zb}"
                    );
                }
            }
        }
    }
}

#[test]
fn scattered_photographs_rebin_close_to_the_geometry() {
    let card = Card::new(0.0, 2.0);
    let draws = [card.draw()];
    // A hand-held-like wander around the uv plane, near and far.
    let eyes: Vec<Vec3> = (0..30)
        .map(|k| {
            let a = k as f32 * 2.4;
            let r = 0.2 + 0.75 * ((k * 7 % 11) as f32 / 10.0);
            Vec3::new(r * a.cos(), r * a.sin(), 4.0 + 0.6 * (a * 0.37).sin())
        })
        .collect();
    let images = photographs(&draws, &eyes, 64);
    let sparse = rebin(slab(6, 32), &images);
    assert!(sparse.rays > 20_000, "{}", sparse.rays);
    let cam = camera(Vec3::new(0.13, -0.21, 4.0));
    let want = truth(&draws, &cam);
    let mut out = Warped::new(0, 0, cam);
    render(&sparse.field, &cam, W, H, Lookup::default(), &mut out);
    let (mean, n) = compare(&out, &want);
    assert!(n > 500, "covers {n} pixels");
    assert!(mean < 6.0, "mean error {mean} levels");
}

#[test]
fn regions_no_photograph_saw_are_filled_and_reported_invented() {
    let card = Card::new(0.0, 2.0);
    let draws = [card.draw()];
    // Photographs from the left of the uv plane only.
    let eyes: Vec<Vec3> = (0..12)
        .map(|k| Vec3::new(-0.9 + 0.07 * k as f32, 0.6 - 0.1 * k as f32, 4.0))
        .collect();
    let images = photographs(&draws, &eyes, 48);
    let s = slab(8, 24);
    let sparse = rebin(s, &images);
    let invented = sparse.invented();
    assert!(invented > 0.3 && invented < 1.0, "{invented}");
    // Per uv sample: the left half saw rays, the right half's are all invented.
    let seen = |u: u32| {
        (0..s.nv).any(|v| {
            let first = ((v * s.nu + u) * s.nt * s.ns) as usize;
            sparse.weights[first..first + (s.ns * s.nt) as usize]
                .iter()
                .any(|&w| w > 0.0)
        })
    };
    assert!(seen(1) && !seen(7));
    // Every sample is valid: premultiplied colour, positive or infinite depth.
    let Rays::Raw(raw) = &sparse.field.rays else {
        panic!("raw");
    };
    for (c, z) in raw.samples.iter().zip(&raw.depth) {
        let [r, g, b, a] = c.to_le_bytes();
        assert!(r <= a && g <= a && b <= a, "{c:08x}");
        assert!(*z > 0.0 && !z.is_nan());
    }
    // A view from the unseen right renders the card from invented samples, not holes.
    let cam = camera(Vec3::new(0.8, -0.3, 4.0));
    let want = truth(&draws, &cam);
    let mut out = Warped::new(0, 0, cam);
    render(&sparse.field, &cam, W, H, Lookup::default(), &mut out);
    let (_, n) = compare(&out, &want);
    assert!(n > 500, "covers {n} pixels");
}

#[test]
fn no_photographs_rebin_to_an_empty_light_field() {
    let sparse = rebin(slab(2, 8), &[]);
    assert_eq!(sparse.rays, 0);
    assert_eq!(sparse.invented(), 1.0);
    assert!(sparse.field.has_depth());
    let cam = camera(Vec3::new(0.0, 0.0, 4.0));
    let mut out = Warped::new(0, 0, cam);
    let frame = render(&sparse.field, &cam, W, H, Lookup::default(), &mut out);
    assert!(frame.rays > 0);
    assert_eq!(frame.pixels, 0, "nothing to show");
}
