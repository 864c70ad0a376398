//! The measures on maps whose answers are worked out by hand.

use super::*;
use engine::load::{parse_pfm, pfm_bytes};

const INF: f32 = f32::INFINITY;

fn map(w: u32, h: u32, data: &[f32]) -> Disparity {
    Disparity::new(w, h, data.to_vec()).expect("a valid map")
}

#[test]
fn a_perfect_estimate_has_no_error() {
    let t = map(3, 2, &[1.0, 2.5, 0.0, 7.0, 3.25, 4.0]);
    let m = measure(&t, &t, None).unwrap();
    assert_eq!(m.all.pixels, 6);
    assert_eq!(
        (m.all.bad1, m.all.bad2, m.all.rms, m.all.unknown),
        (0.0, 0.0, 0.0, 0.0)
    );
    assert_eq!(m.nonocc, m.all);
}

#[test]
fn errors_count_by_threshold_and_rms_is_over_known_estimates() {
    // Truth 10 everywhere but an unknown pixel; estimates off by 0, 0.5, 1.5, 3, unknown.
    let t = map(3, 2, &[10.0, 10.0, 10.0, 10.0, 10.0, INF]);
    let e = map(3, 2, &[10.0, 10.5, 8.5, 13.0, INF, 4.0]);
    let m = measure(&e, &t, None).unwrap().all;
    // Five evaluated (the truth's unknown pixel is not).
    assert_eq!(m.pixels, 5);
    // Off by more than 1: 1.5, 3 and the unknown one.
    assert!((m.bad1 - 3.0 / 5.0).abs() < 1e-12, "{m:?}");
    // Off by more than 2: 3 and the unknown one.
    assert!((m.bad2 - 2.0 / 5.0).abs() < 1e-12, "{m:?}");
    // Over the four known: sqrt((0 + 0.25 + 2.25 + 9) / 4).
    assert!((m.rms - (11.5f64 / 4.0).sqrt()).abs() < 1e-12, "{m:?}");
    assert!((m.unknown - 1.0 / 5.0).abs() < 1e-12, "{m:?}");
}

#[test]
fn the_visibility_mask_restricts_the_non_occluded_figures_only() {
    let t = map(2, 2, &[5.0, 5.0, 5.0, 5.0]);
    let e = map(2, 2, &[5.0, 5.0, 5.0, 9.0]);
    // The last pixel is occluded in the right image.
    let m = measure(&e, &t, Some(&[true, true, true, false])).unwrap();
    assert_eq!((m.nonocc.pixels, m.nonocc.bad2), (3, 0.0));
    assert_eq!(m.all.pixels, 4);
    assert!((m.all.bad2 - 0.25).abs() < 1e-12);
    assert!((m.all.rms - 2.0).abs() < 1e-12, "sqrt(16 / 4)");
}

#[test]
fn bad_maps_and_mismatched_sizes_are_refused() {
    assert!(matches!(
        Disparity::new(2, 2, vec![1.0; 3]),
        Err(StereoError::Size { found: 3, .. })
    ));
    for bad in [f32::NAN, -1.0, f32::NEG_INFINITY] {
        let e = Disparity::new(2, 1, vec![0.5, bad]).unwrap_err();
        assert!(matches!(e, StereoError::Value { x: 1, y: 0, .. }), "{e}");
    }
    let (a, b) = (map(2, 1, &[0.0, 1.0]), map(1, 2, &[0.0, 1.0]));
    assert_eq!(
        measure(&a, &b, None),
        Err(StereoError::Mismatch(2, 1, 1, 2))
    );
    assert!(matches!(
        measure(&a, &a, Some(&[true])),
        Err(StereoError::Size { .. })
    ));
}

#[test]
fn a_map_round_trips_through_pfm_with_infinity_where_unknown() {
    let d = map(3, 2, &[0.0, 1.5, INF, 64.25, INF, 2.0]);
    let image = parse_pfm(&pfm_bytes(&d.to_float_image())).expect("PFM bytes");
    let back = Disparity::from_float_image(image).expect("a valid map");
    assert_eq!(back, d);
    assert!(!back.known(2) && back.known(3));
}
