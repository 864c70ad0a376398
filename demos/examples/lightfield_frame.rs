//! Times a light-field frame: a lit torus captured into a 32 x 32 (uv) by 256 x 256 (st)
//! slab, then rendered at 1280x720 from an eye between the capture cameras, the slab
//! filling most of the frame, by each lookup; prints capture time, frame times and the
//! pixels and samples read; then the same quantised (2x2x2x2 tiles, `CODEWORDS` codewords,
//! default 16384): training and encoding time, sizes, PSNR against the raw render and
//! frame times from the codes:
//! `cargo run --release -p demos --example lightfield_frame [CODEWORDS]`.
//! Wall-clock figures from a shared machine.

use demos::bench::lightfield::{frame_case, FRAME_SIZE};
use ibr::lightfield::{render, Interpolation, Lookup, VqSettings};
use ibr::warp::Warped;
use std::time::Instant;

fn main() {
    let start = Instant::now();
    let (lf, camera) = frame_case();
    let (w, h) = FRAME_SIZE;
    println!(
        "capture: 32x32 views of 256x256 ({} samples) in {:.2} s on {} threads",
        lf.slab.len(),
        start.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    let codewords: u32 = std::env::args()
        .nth(1)
        .map_or(16384, |a| a.parse().expect("a codeword count"));
    let start = Instant::now();
    let settings = VqSettings {
        codewords,
        ..VqSettings::default()
    };
    let (q, report) = lf.quantise(&settings).expect("quantised");
    println!(
        "quantised in {:.2} s: {report:?}",
        start.elapsed().as_secs_f64()
    );
    let dir = std::env::temp_dir();
    let (raw_path, vq_path) = (dir.join("lf_raw.plf"), dir.join("lf_vq.plf"));
    let start = Instant::now();
    q.save(&vq_path).expect("saved");
    let saved = start.elapsed().as_secs_f64();
    lf.save(&raw_path).expect("saved");
    let size = |p: &std::path::Path| std::fs::metadata(p).map_or(0, |m| m.len()) as f64;
    println!(
        "raw {:.1} MB, VQ in memory {:.1} MB ({:.1}:1), file {:.2} MB ({:.1}:1, saved in {saved:.2} s)",
        size(&raw_path) / 1e6,
        q.bytes() as f64 / 1e6,
        lf.bytes() as f64 / q.bytes() as f64,
        size(&vq_path) / 1e6,
        size(&raw_path) / size(&vq_path),
    );
    let mut out = Warped::new(0, 0, camera);
    let mut from_codes = Warped::new(0, 0, camera);
    for (name, interpolation, depth_correction) in [
        ("nearest", Interpolation::Nearest, false),
        ("bilinear uv", Interpolation::BilinearUv, false),
        ("quadrilinear", Interpolation::Quadrilinear, false),
        (
            "quadrilinear, depth-corrected",
            Interpolation::Quadrilinear,
            true,
        ),
    ] {
        let lookup = Lookup {
            interpolation,
            depth_correction,
        };
        let mut best = f64::INFINITY;
        let mut frame = Default::default();
        for _ in 0..8 {
            let t = Instant::now();
            frame = render(&lf, &camera, w, h, lookup, &mut out);
            best = best.min(t.elapsed().as_secs_f64());
        }
        println!("{name:32} {:7.2} ms (best of 8)  {frame:?}", best * 1e3);
        let mut best = f64::INFINITY;
        for _ in 0..8 {
            let t = Instant::now();
            render(&q, &camera, w, h, lookup, &mut from_codes);
            best = best.min(t.elapsed().as_secs_f64());
        }
        let (mut se, mut n) = (0.0f64, 0usize);
        for (a, b) in out.color.iter().zip(&from_codes.color) {
            for (x, y) in a.to_le_bytes().iter().zip(b.to_le_bytes()).take(3) {
                se += (f64::from(*x) - f64::from(y)).powi(2);
                n += 1;
            }
        }
        let psnr = 10.0 * (255.0f64.powi(2) / (se / n as f64)).log10();
        println!(
            "{:32} {:7.2} ms from codes, {psnr:.1} dB against raw",
            "",
            best * 1e3
        );
    }
}
