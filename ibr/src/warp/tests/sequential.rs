//! The banded warp against the plain sequential one: every run in order, each sample's
//! whole rectangle written at once, no segments, no bands and no blocks. Binning by segment
//! bounds must leave out only samples that land nowhere, and write the rest in the same
//! order; runs of points copied as blocks must write what they would one by one.

use super::super::rows::{warp_row, Lane};
use super::super::*;
use super::{boxes, camera, cast};
use crate::core::LayeredDepthImage;
use glam::Vec3;

/// The warp of `source` to `target`, sample by sample in the traversal order.
fn sequential(source: &Prepared, target: &Camera, w2: u32, h2: u32, o: &WarpOptions) -> Warped {
    let mut out = Warped::new(w2, h2, *target);
    let (w1, h1) = source.size();
    let Some(eq) = Equation::new(source.camera(), w1, h1, target, w2, h2) else {
        return out;
    };
    let (epipole, in_front) = eq.epipole_pixel();
    let mut runs = Vec::new();
    order::runs(w1, h1, epipole, in_front, &mut runs);
    let lane = Lane::new(&eq, o, w2, h2);
    let put = Put {
        w: w2 as usize,
        vis: o.visibility,
        slack: 1.0 + o.edge,
        enc: Encoder::new(ENCODING),
    };
    let mut band = Band {
        color: &mut out.color,
        disparity: &mut out.disparity,
        y_base: 0,
        rows: h2 as usize,
    };
    for run in &runs {
        let (lo, hi) = run.span();
        if source.single() {
            // Sample by sample (the banded warp copies runs of points as blocks).
            let reverse = run.step < 0;
            let mut each = |g: &Group| {
                for i in 0..g.n {
                    put.sample(&mut band, g, if reverse { g.n - 1 - i } else { i });
                }
            };
            warp_row(&lane, source, run.y, (lo, hi), reverse, &mut each);
        } else {
            for x in run.pixels() {
                let p = (run.y * w1 + x) as usize;
                let base = lane.base(x, run.y);
                for s in source.first[p]..source.first[p + 1] {
                    let mut stats = WarpStats::default();
                    if let Some(e) = lane.sample(source, s as usize, base, &mut stats) {
                        put.entry(&mut band, &e);
                    }
                }
            }
        }
    }
    out
}

/// A small deterministic generator (xorshift), for camera placements.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
}

#[test]
fn bands_write_what_the_sequential_warp_writes_from_any_eye() {
    // Several blocks per reference row and several bands per target.
    let (w1, h1, w2, h2) = (150, 100, 170, 130);
    let at = Vec3::new(0.0, 0.0, -4.0);
    let near = camera(Vec3::new(0.0, 0.0, 2.0), at);
    let image = cast(&near, w1, h1, &boxes());
    let back = cast(&camera(Vec3::new(0.3, 0.2, 1.0), at), w1, h1, &boxes());
    let ldi = LayeredDepthImage::from_layers(&[image.clone(), back]).expect("one camera");
    let sources = [
        Prepared::from_image(&image, 0.05),
        Prepared::from_ldi(&ldi, 0.05),
    ];
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut warper = Warper::new();
    let (mut cases, mut seen) = (0, 0);
    for i in 0..120 {
        // Eyes in front of, beside and behind the reference, some in its image plane
        // (epipole at infinity); views turned and rolled, some looking away.
        let eye = match i % 4 {
            0 => Vec3::new(
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
                rng.range(1.0, 3.0),
            ),
            1 => Vec3::new(rng.range(-4.0, 4.0), rng.range(-2.0, 2.0), 2.0),
            _ => Vec3::new(
                rng.range(-3.0, 3.0),
                rng.range(-2.0, 2.0),
                rng.range(-3.0, 6.0),
            ),
        };
        let look = Vec3::new(
            rng.range(-3.0, 3.0),
            rng.range(-2.0, 2.0),
            rng.range(-7.0, 7.0),
        );
        let up = Vec3::new(rng.range(-1.0, 1.0), 1.0, rng.range(-1.0, 1.0));
        if (look - eye).cross(up).length() < 1e-3 {
            continue;
        }
        let fov = rng.range(0.4, 2.0);
        let target =
            Camera::look_at(eye, look, up, fov, w2 as f32 / h2 as f32).with_depth_range(0.1, 50.0);
        for (s, source) in sources.iter().enumerate() {
            for (v, rec) in [
                (Visibility::Ordered, Reconstruction::Splats),
                (Visibility::DepthBuffer, Reconstruction::Points),
            ] {
                let o = WarpOptions {
                    visibility: v,
                    reconstruction: rec,
                    ..WarpOptions::default()
                };
                warper.begin(&target, w2, h2);
                warper.add_prepared(source, &o);
                let want = sequential(source, &target, w2, h2, &o);
                let got = warper.output();
                cases += 1;
                seen += (got.filled() > 0) as u32;
                assert!(
                    got.color == want.color && got.disparity == want.disparity,
                    "eye {eye} looking at {look}, source {s}, {v:?} {rec:?}"
                );
            }
        }
    }
    // Most eyes see some of the scene (the rest look away or are behind it).
    assert!(seen * 2 > cases, "{seen} of {cases} warps wrote anything");
}
