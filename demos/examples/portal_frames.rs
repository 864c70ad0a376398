//! Prints each frame's time along the building walkthrough at 1280x720 with what its
//! portals did (warped, drawn as geometry, LDIs finished), to find the slow frames:
//! `cargo run --release -p demos --example portal_frames -- [FRAMES]` (default 60, the
//! walk of `bench portals`). Wall-clock figures from a shared machine.

use demos::showcase::building::BuildingTour;
use engine::{Renderer, Target};
use std::time::Instant;

fn main() {
    let n = std::env::args()
        .nth(1)
        .and_then(|a| a.parse::<usize>().ok())
        .unwrap_or(60)
        .max(1);
    let (w, h) = (1280, 720);
    let mut tour = BuildingTour::new();
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    for i in 0..n {
        let camera = BuildingTour::camera(i, n, w, h);
        let start = Instant::now();
        tour.render(&mut renderer, &camera, &mut target);
        let ms = start.elapsed().as_secs_f64() * 1e3;
        let f = tour.last();
        println!(
            "{i:3} {ms:7.2} ms  warped {} geometry {} LDIs finished {}",
            f.warped, f.geometry, f.rebuilds
        );
    }
}
