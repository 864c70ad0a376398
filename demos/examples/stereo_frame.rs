//! Times the stereo matchers on a rendered 640x480 pair with exact ground truth (the
//! showcase's plaza seen from its edge, a 0.3-unit baseline, up to 64 pixels of disparity)
//! and prints their Middlebury error:
//! `cargo run --release -p demos --example stereo_frame -- [--runs N] [--sgm]` (the best
//! of N runs, 3 by default; `--sgm`: semi-global matching only, not the slow block
//! matcher). Wall-clock figures from a shared machine: compare builds by alternating runs.

use demos::showcase::{self, Showcase};
use glam::Vec3;
use ibr::stereo::{luminance, measure, BlockMatch, Sgm, SgmBuffers, StereoPair};
use std::time::Instant;

fn main() {
    let (w, h) = (640, 480);
    let show = Showcase::new();
    let draws: Vec<_> = show.scene.draws().collect();
    let camera = showcase::camera(Vec3::new(-3.0, 3.0, 12.0), Vec3::new(0.0, 1.0, 0.0), w, h);
    let pair = StereoPair::render(&draws, &show.scene.lighting, &camera, 0.3, w, h);
    let (l, r) = (luminance(&pair.left), luminance(&pair.right));
    let args: Vec<String> = std::env::args().skip(1).collect();
    let runs = args
        .iter()
        .position(|a| a == "--runs")
        .and_then(|i| args.get(i + 1))
        .and_then(|n| n.parse::<usize>().ok())
        .unwrap_or(3)
        .max(1);
    let names: &[&str] = if args.iter().any(|a| a == "--sgm") {
        &["sgm"]
    } else {
        &["block", "sgm"]
    };
    for &name in names {
        let mut best = f64::INFINITY;
        let mut est = None;
        let mut buffers = SgmBuffers::default();
        for _ in 0..runs {
            let t = Instant::now();
            let d = match name {
                "block" => BlockMatch::default().run(&l, &r, w, h),
                _ => Sgm::default().run_with(&mut buffers, &l, &r, w, h),
            }
            .expect("images of the size given");
            best = best.min(t.elapsed().as_secs_f64());
            est = Some(d);
        }
        let m = measure(&est.expect("run"), &pair.truth, Some(&pair.visible)).expect("sizes");
        println!(
            "{name:6} {:7.1} ms (best of {runs}): non-occluded bad 1 {:.1}%, bad 2 {:.1}%, RMS {:.2} px, unknown {:.1}%",
            best * 1e3,
            100.0 * m.nonocc.bad1,
            100.0 * m.nonocc.bad2,
            m.nonocc.rms,
            100.0 * m.nonocc.unknown
        );
    }
}
