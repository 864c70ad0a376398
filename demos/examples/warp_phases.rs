//! Times the two phases of a 1920x1080 warp (the warp itself, then the pull-push fill) on
//! the criterion bench's frame, and prints a hash of the filled image, so a change meant to
//! keep the pixels can be checked to keep them:
//! `cargo run --release -p demos --example warp_phases -- [SIDEWAYS] [--frames N] [--no-fill]
//! [--background] [--city]` (the background-side fill instead of pull-push; the `bench warp`
//! speed series' city frame, 500k triangles, instead of the showcase's)
//! (SIDEWAYS: how far the eye moves, default 0.3; `RAYON_NUM_THREADS=1` for one thread).
//! Wall-clock figures from a shared machine: compare runs alternated, not one against an
//! old number.

use demos::bench::warp::{city_reference, showcase_reference};
use ibr::warp::holes::{Fill, Filler};
use ibr::warp::{Prepared, WarpOptions, Warper};
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let flag = |name: &str| args.iter().position(|a| a == name);
    let sideways = args
        .first()
        .and_then(|a| a.parse::<f32>().ok())
        .unwrap_or(0.3);
    let frames = flag("--frames")
        .and_then(|i| args.get(i + 1))
        .and_then(|n| n.parse::<usize>().ok())
        .unwrap_or(40)
        .max(1);
    let fill = match (flag("--no-fill"), flag("--background")) {
        (Some(_), _) => Fill::None,
        (None, Some(_)) => Fill::Background,
        (None, None) => Fill::PullPush,
    };
    let (w, h) = (1920, 1080);
    let (reference, moved) = if flag("--city").is_some() {
        let city = demos::city::City::with_triangles(4, 500_000, 7);
        let (mut renderer, mut frame) = (engine::Renderer::new(), ibr::technique::FrameLoop::new());
        city_reference(&city, &mut renderer, &mut frame, (w, h))
    } else {
        showcase_reference(w, h, sideways)
    };
    let options = WarpOptions::default();
    let prepared = Prepared::from_image(&reference, options.edge);
    let (mut warper, mut filler) = (Warper::new(), Filler::default());
    let (mut warp, mut filling) = (Duration::ZERO, Duration::ZERO);
    // The fastest frame of each phase too: on a shared machine, the least disturbed.
    let (mut warp_min, mut fill_min) = (Duration::MAX, Duration::MAX);
    // Five warm-up frames, then the timed ones.
    for i in 0..frames + 5 {
        let t0 = Instant::now();
        warper.begin(&moved, w, h);
        let stats = warper.add_prepared(&prepared, &options);
        if i == 0 && std::env::var_os("STATS").is_some() {
            eprintln!("{stats:?}");
        }
        let t1 = Instant::now();
        filler.fill(warper.output_mut(), fill, options.edge);
        let t2 = Instant::now();
        if i >= 5 {
            (warp, filling) = (warp + (t1 - t0), filling + (t2 - t1));
            (warp_min, fill_min) = (warp_min.min(t1 - t0), fill_min.min(t2 - t1));
        }
    }
    let out = warper.output();
    let hash = out
        .color
        .iter()
        .zip(&out.disparity)
        .fold(0u64, |h, (c, d)| {
            h.wrapping_mul(1_000_003) ^ u64::from(*c) ^ (u64::from(d.to_bits()) << 32)
        });
    let ms = |d: Duration| d.as_secs_f64() * 1e3 / frames as f64;
    println!(
        "1920x1080, {sideways} sideways, {fill:?} fill, {frames} frames on {} threads: warp {:.2} ms, fill {:.2} ms (fastest {:.2} and {:.2}); image hash {hash:016x}",
        rayon::current_num_threads(),
        ms(warp),
        ms(filling),
        warp_min.as_secs_f64() * 1e3,
        fill_min.as_secs_f64() * 1e3,
    );
}
