//! Criterion benchmarks of the 3D warp at 1920x1080, through the public API: the showcase's
//! scene captured once, then warped to an eye moved a little sideways.
//! - `warp/points`, `warp/splats`: the warp alone (order, bin, write), no hole filling;
//! - `warp/splats_pull_push`: with the depth-aware pull-push fill;
//! - `warp/splats_background`: with the background-side fill.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use demos::bench::warp::showcase_reference;
use ibr::depth_images::WarpedView;
use ibr::warp::holes::Fill;
use ibr::warp::Reconstruction;
use std::hint::black_box;
use std::time::Duration;

fn warp(c: &mut Criterion) {
    let (w, h) = (1920, 1080);
    let (reference, moved) = showcase_reference(w, h, 0.3);
    let mut group = c.benchmark_group("warp");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(6));
    group.throughput(Throughput::Elements((w * h) as u64));
    for (name, rec, fill) in [
        ("points", Reconstruction::Points, Fill::None),
        ("splats", Reconstruction::Splats, Fill::None),
        ("splats_pull_push", Reconstruction::Splats, Fill::PullPush),
        (
            "splats_background",
            Reconstruction::Splats,
            Fill::Background,
        ),
    ] {
        let mut view = WarpedView::new(name, vec![reference.clone()]);
        view.nearest = 1;
        view.count_holes = false;
        view.options.reconstruction = rec;
        view.fill = fill;
        group.bench_function(name, |b| b.iter(|| black_box(view.warp_to(&moved, w, h))));
    }
    group.finish();
}

criterion_group!(benches, warp);
criterion_main!(benches);
