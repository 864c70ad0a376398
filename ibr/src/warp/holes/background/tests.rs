//! The background fill against a slow reference: four sweeps over every pixel, each hole
//! keeping the farthest sample a sweep offers (left, right, top, bottom; strictly farther
//! replaces), on images whose sides are and are not multiples of 8 and 64.

use super::super::super::warped::{Warped, HOLE};
use super::Background;
use engine::procedural::XorShift;
use engine::Camera;
use glam::Vec3;

/// The reference: each hole's nearest sample along each of the four sweeps, the farthest
/// kept (first among equals), taken from the unfilled image. Returns the holes filled.
fn reference(image: &mut Warped) -> u64 {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let disparity = image.disparity.clone();
    let mut best: Vec<Option<usize>> = vec![None; w * h];
    let mut sweep = |line: &mut dyn Iterator<Item = usize>| {
        let mut last: Option<usize> = None;
        for i in line {
            if disparity[i] >= 0.0 {
                last = Some(i);
            } else if let Some(s) = last {
                if best[i].is_none_or(|b| disparity[s] < disparity[b]) {
                    best[i] = Some(s);
                }
            }
        }
    };
    for y in 0..h {
        sweep(&mut (y * w..(y + 1) * w));
        sweep(&mut (y * w..(y + 1) * w).rev());
    }
    for x in 0..w {
        sweep(&mut (0..h).map(|y| y * w + x));
        sweep(&mut (0..h).rev().map(|y| y * w + x));
    }
    let mut count = 0;
    for (i, b) in best.iter().enumerate() {
        if let Some(s) = *b {
            image.color[i] = image.color[s];
            image.disparity[i] = image.disparity[s];
            count += 1;
        }
    }
    count
}

/// A `w` x `h` image whose pixels are holes with probability `holes` (some of them NaN
/// rather than negative), and otherwise samples with one of a few disparities (so equal
/// ones meet) and a colour naming the pixel.
fn image(w: u32, h: u32, holes: f64, rng: &mut XorShift) -> Warped {
    let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0);
    let mut image = Warped::new(w, h, camera);
    for i in 0..image.color.len() {
        let r = (rng.next_u64() % 10_000) as f64 / 10_000.0;
        if r < holes {
            image.disparity[i] = if rng.next_u64().is_multiple_of(7) {
                f32::NAN
            } else {
                HOLE
            };
        } else {
            image.disparity[i] = [0.0, 0.25, 0.5, 1.0][(rng.next_u64() % 4) as usize];
            image.color[i] = i as u32 | 0xff00_0000;
        }
    }
    image
}

#[test]
fn the_fill_is_the_four_sweeps() {
    let mut rng = XorShift::new(7);
    let mut fill = Background::default();
    let sizes = [
        (1, 1),
        (1, 9),
        (9, 1),
        (8, 8),
        (63, 5),
        (64, 3),
        (65, 7),
        (130, 17),
        (200, 41),
    ];
    for (w, h) in sizes {
        for holes in [0.0, 0.05, 0.3, 0.7, 0.97, 1.0] {
            let start = image(w, h, holes, &mut rng);
            let (mut fast, mut slow) = (start.clone(), start);
            let holes_before = start_holes(&fast);
            let (filled, counted) = fill.fill(&mut fast);
            let expected = reference(&mut slow);
            assert_eq!(filled, expected, "{w}x{h}, {holes} holes: count");
            assert_eq!(counted, holes_before, "{w}x{h}, {holes} holes: holes");
            assert_eq!(fast.color, slow.color, "{w}x{h}, {holes} holes: colour");
            // Bitwise: NaN holes that stay holes stay NaN.
            let bits = |d: &[f32]| d.iter().map(|d| d.to_bits()).collect::<Vec<_>>();
            assert_eq!(
                bits(&fast.disparity),
                bits(&slow.disparity),
                "{w}x{h}, {holes}"
            );
        }
    }
}

#[test]
fn scratch_from_a_larger_image_leaves_no_trace() {
    let mut rng = XorShift::new(11);
    let mut fill = Background::default();
    let mut big = image(150, 60, 0.4, &mut rng);
    fill.fill(&mut big);
    let start = image(70, 20, 0.5, &mut rng);
    let (mut fast, mut slow) = (start.clone(), start);
    assert_eq!(fill.fill(&mut fast).0, reference(&mut slow));
    assert_eq!(fast.color, slow.color);
}

/// The holes of `image`: pixels whose disparity is negative or NaN.
fn start_holes(image: &Warped) -> u64 {
    image
        .disparity
        .iter()
        .filter(|d| (**d).partial_cmp(&0.0).is_none_or(|o| o.is_lt()))
        .count() as u64
}
