//! Analytic answers: identical images, constant offsets, single pixels, coverage, regions.

use super::*;
use engine::Rgba;

/// A `w` x `h` raw image of one RGBA colour.
fn solid(w: u32, h: u32, c: [u8; 4]) -> Vec<u8> {
    c.repeat(w as usize * h as usize)
}

fn set(buf: &mut [u8], w: u32, x: u32, y: u32, c: [u8; 4]) {
    let i = (y as usize * w as usize + x as usize) * 4;
    buf[i..i + 4].copy_from_slice(&c);
}

fn cmp(w: u32, h: u32, a: &[u8], b: &[u8], opts: &Options) -> ImageError {
    compare_rgba8(
        Image::new(w, h, a).unwrap(),
        Image::new(w, h, b).unwrap(),
        opts,
    )
    .unwrap()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-9 * b.abs().max(1.0)
}

#[test]
fn identical_images_have_infinite_psnr_and_no_error() {
    let a = solid(7, 5, [10, 200, 30, 255]);
    let e = cmp(7, 5, &a, &a, &Options::default());
    assert_eq!(e.psnr_db, f64::INFINITY);
    assert_eq!(e.psnr_capped(99.0), 99.0);
    assert_eq!((e.mse, e.mean_abs, e.max_abs), (0.0, 0.0, 0));
    assert_eq!((e.frac_over, e.coverage_mismatch), (0.0, 0.0));
    assert_eq!(e.pixels, 35);

    let mut t = Target::new(9, 4);
    t.clear(Rgba::from_srgb8(40, 90, 200));
    let e = compare(&t, &t.clone(), &Options::default()).unwrap();
    assert_eq!(e.psnr_db, f64::INFINITY);
    assert_eq!(e.pixels, 36);
}

#[test]
fn a_constant_offset_of_k_levels_gives_mae_k_and_psnr_20_log10_255_over_k() {
    for k in [1u8, 5, 10, 51] {
        let a = solid(6, 4, [100 + k, 50 + k, 20 + k, 255]);
        let b = solid(6, 4, [100, 50, 20, 255]);
        let e = cmp(6, 4, &a, &b, &Options::default());
        assert!(close(e.mean_abs, k as f64), "{e:?}");
        assert!(close(e.mse, (k as f64).powi(2)), "{e:?}");
        assert!(close(e.psnr_db, 20.0 * (255.0 / k as f64).log10()), "{e:?}");
        assert_eq!(e.max_abs, k);
        // Every pixel is over a threshold below k and none at or above it.
        let below = Options {
            threshold: k - 1,
            ..Options::default()
        };
        assert_eq!(cmp(6, 4, &a, &b, &below).frac_over, 1.0);
        let at = Options {
            threshold: k,
            ..Options::default()
        };
        assert_eq!(cmp(6, 4, &a, &b, &at).frac_over, 0.0);
        // Symmetric.
        assert_eq!(cmp(6, 4, &b, &a, &Options::default()), e);
    }
}

#[test]
fn targets_compare_their_8_bit_srgb_values() {
    let (mut a, mut b) = (Target::new(16, 8), Target::new(16, 8));
    a.clear(Rgba::from_srgb8(110, 130, 150));
    b.clear(Rgba::from_srgb8(100, 120, 140));
    // The clear colours round-trip to the bytes they came from.
    assert_eq!(a.to_rgba8()[..4], [110, 130, 150, 255]);
    assert_eq!(b.to_rgba8()[..4], [100, 120, 140, 255]);
    let e = compare(&a, &b, &Options::default()).unwrap();
    assert!(close(e.mean_abs, 10.0), "{e:?}");
    assert!(close(e.psnr_db, 20.0 * (25.5f64).log10()), "{e:?}");
    assert_eq!((e.max_abs, e.frac_over, e.pixels), (10, 1.0, 128));
    assert_eq!(e.coverage_mismatch, 0.0);
}

#[test]
fn one_changed_pixel_sets_the_max_and_the_fraction_over() {
    let b = solid(10, 10, [0, 0, 0, 255]);
    let mut a = b.clone();
    set(&mut a, 10, 3, 7, [0, 200, 0, 255]);
    let e = cmp(10, 10, &a, &b, &Options::default());
    assert_eq!(e.max_abs, 200);
    assert!(close(e.frac_over, 0.01));
    assert!(close(e.mean_abs, 200.0 / 300.0));
    let mse = 200.0 * 200.0 / 300.0;
    assert!(close(e.mse, mse));
    assert!(close(e.psnr_db, 10.0 * (255.0 * 255.0 / mse).log10()));
    assert_eq!(e.coverage_mismatch, 0.0);
}

#[test]
fn coverage_by_alpha_counts_pixels_drawn_in_one_image_only() {
    // b: transparent; a: three drawn pixels, one of them black (drawn, same RGB).
    let b = solid(4, 5, [0, 0, 0, 0]);
    let mut a = b.clone();
    set(&mut a, 4, 0, 0, [255, 255, 255, 255]);
    set(&mut a, 4, 3, 4, [20, 20, 20, 128]);
    set(&mut a, 4, 1, 2, [0, 0, 0, 255]);
    let e = cmp(4, 5, &a, &b, &Options::default());
    assert!(close(e.coverage_mismatch, 3.0 / 20.0), "{e:?}");
    assert!(close(e.frac_over, 2.0 / 20.0), "{e:?}");
    // Both drawn (different colours) is not a mismatch.
    let mut c = a.clone();
    set(&mut c, 4, 0, 0, [0, 0, 255, 255]);
    assert!(close(
        cmp(4, 5, &a, &c, &Options::default()).coverage_mismatch,
        0.0
    ));
    assert_eq!(
        covered_rect_rgba8(Image::new(4, 5, &a).unwrap(), Coverage::Alpha),
        Some(Rect::new(0, 0, 4, 5))
    );
    assert_eq!(
        covered_rect_rgba8(Image::new(4, 5, &b).unwrap(), Coverage::Alpha),
        None
    );
}

#[test]
fn coverage_by_background_colour_ignores_alpha() {
    let sky = [120, 160, 220];
    let b = solid(5, 2, [120, 160, 220, 255]);
    let mut a = b.clone();
    set(&mut a, 5, 4, 1, [30, 90, 20, 255]);
    set(&mut a, 5, 2, 0, [120, 160, 220, 0]);
    let opts = Options {
        coverage: Coverage::Background(sky),
        ..Options::default()
    };
    let e = cmp(5, 2, &a, &b, &opts);
    assert!(close(e.coverage_mismatch, 0.1), "{e:?}");
    // By alpha, only the transparent pixel differs.
    assert!(close(
        cmp(5, 2, &a, &b, &Options::default()).coverage_mismatch,
        0.1
    ));
    assert_eq!(
        covered_rect_rgba8(Image::new(5, 2, &a).unwrap(), Coverage::Background(sky)),
        Some(Rect::new(4, 1, 1, 1))
    );
}

#[test]
fn rectangles_and_masks_restrict_the_comparison() {
    let b = solid(8, 6, [50, 50, 50, 255]);
    let mut a = b.clone();
    set(&mut a, 8, 6, 5, [50, 50, 80, 255]);
    // A rectangle missing the changed pixel sees identical images.
    let left = Options {
        region: Region::Rect(Rect::new(0, 0, 4, 6)),
        ..Options::default()
    };
    let e = cmp(8, 6, &a, &b, &left);
    assert_eq!((e.psnr_db, e.pixels), (f64::INFINITY, 24));
    // A rectangle reaching past the image is clipped: 2 x 1 pixels, one changed.
    let corner = Options {
        region: Region::Rect(Rect::new(6, 5, 100, 100)),
        ..Options::default()
    };
    let e = cmp(8, 6, &a, &b, &corner);
    assert_eq!((e.pixels, e.max_abs), (2, 30));
    assert!(close(e.frac_over, 0.5));
    assert!(close(e.mean_abs, 30.0 / 6.0));
    // A mask of the changed pixel alone.
    let mut m = vec![false; 48];
    m[5 * 8 + 6] = true;
    let e = cmp(
        8,
        6,
        &a,
        &b,
        &Options {
            region: Region::Mask(&m),
            ..Options::default()
        },
    );
    assert_eq!((e.pixels, e.frac_over, e.max_abs), (1, 1.0, 30));
    assert!(close(e.psnr_db, 10.0 * (255.0f64 * 255.0 / 300.0).log10()));
}

#[test]
fn mismatched_sizes_and_bad_inputs_are_errors() {
    let (a, b) = (Target::new(4, 4), Target::new(4, 5));
    assert_eq!(
        compare(&a, &b, &Options::default()),
        Err(MetricsError::SizeMismatch {
            a: (4, 4),
            b: (4, 5)
        })
    );
    let err = compare(&a, &b, &Options::default()).unwrap_err();
    assert!(err.to_string().contains("4x4 against 4x5"), "{err}");
    assert_eq!(
        Image::new(2, 2, &[0; 15]),
        Err(MetricsError::BufferLength {
            width: 2,
            height: 2,
            len: 15
        })
    );
    let p = solid(2, 2, [0; 4]);
    let q = solid(1, 4, [0; 4]);
    assert!(matches!(
        compare_rgba8(
            Image::new(2, 2, &p).unwrap(),
            Image::new(1, 4, &q).unwrap(),
            &Options::default()
        ),
        Err(MetricsError::SizeMismatch { .. })
    ));
    let short = [true; 3];
    let opts = Options {
        region: Region::Mask(&short),
        ..Options::default()
    };
    assert_eq!(
        compare(&a, &a.clone(), &opts),
        Err(MetricsError::MaskLength {
            expected: 16,
            len: 3
        })
    );
    let outside = Options {
        region: Region::Rect(Rect::new(10, 10, 3, 3)),
        ..Options::default()
    };
    assert_eq!(compare(&a, &a.clone(), &outside), Err(MetricsError::Empty));
    let empty = Target::new(0, 0);
    assert_eq!(
        compare(&empty, &empty.clone(), &Options::default()),
        Err(MetricsError::Empty)
    );
}

#[test]
fn rectangles_union_clip_and_grow() {
    let r = Rect::new(2, 3, 4, 5);
    assert_eq!(r.union(Rect::default()), r);
    assert_eq!(Rect::default().union(r), r);
    assert_eq!(r.union(Rect::new(0, 7, 1, 4)), Rect::new(0, 3, 6, 8));
    assert_eq!(r.clip(4, 100), Rect::new(2, 3, 2, 5));
    assert!(r.clip(1, 1).is_empty());
    assert_eq!(r.grow(3, 10, 9), Rect::new(0, 0, 9, 9));
    // A drawn target's covered rectangle; a transparent one has none.
    let mut t = Target::new(6, 6);
    assert_eq!(covered_rect(&t, Coverage::Alpha), None);
    t.clear(Rgba::new(0.2, 0.2, 0.2, 1.0));
    assert_eq!(
        covered_rect(&t, Coverage::Alpha),
        Some(Rect::new(0, 0, 6, 6))
    );
}

#[test]
fn pooled_errors_weigh_each_comparison_by_its_pixels() {
    // 10 pixels off by 10 levels and 30 identical pixels: one image of 40 pixels.
    let (a, b) = (
        solid(5, 2, [60, 60, 60, 255]),
        solid(5, 2, [50, 50, 50, 255]),
    );
    let off = cmp(5, 2, &a, &b, &Options::default());
    let c = solid(6, 5, [9, 9, 9, 255]);
    let same = cmp(6, 5, &c, &c, &Options::default());
    let p = ImageError::pooled([&off, &same]).unwrap();
    assert_eq!((p.pixels, p.max_abs), (40, 10));
    assert!(close(p.mean_abs, 2.5));
    assert!(close(p.mse, 25.0));
    assert!(close(p.psnr_db, 20.0 * (255.0f64 / 5.0).log10()));
    assert!(close(p.frac_over, 0.25));
    assert_eq!(ImageError::pooled([&same]).unwrap().psnr_db, f64::INFINITY);
    assert_eq!(ImageError::pooled([]), None);
}
