//! Criterion benchmarks of the light-field render at 1280x720, through the public API: a
//! lit torus captured into a 32x32x256x256 slab once (`demos::bench::lightfield::frame_case`),
//! rendered from an eye between the capture cameras by each lookup, from the raw samples
//! and from 1,024 codewords of 2x2x2x2 tiles (`lightfield/<lookup>` and
//! `lightfield/<lookup>_codes`).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use demos::bench::lightfield::{frame_case, FRAME_SIZE};
use ibr::lightfield::{render, Interpolation, Lookup, VqSettings};
use ibr::warp::Warped;
use std::hint::black_box;
use std::time::Duration;

fn lightfield(c: &mut Criterion) {
    let (w, h) = FRAME_SIZE;
    let (raw, camera) = frame_case();
    let settings = VqSettings {
        codewords: 1024,
        ..VqSettings::default()
    };
    let (codes, _) = raw.quantise(&settings).expect("valid settings");
    let mut group = c.benchmark_group("lightfield");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(5));
    group.throughput(Throughput::Elements(u64::from(w * h)));
    let mut out = Warped::new(0, 0, camera);
    for (name, interpolation, depth_correction) in [
        ("nearest", Interpolation::Nearest, false),
        ("bilinear_uv", Interpolation::BilinearUv, false),
        ("quadrilinear", Interpolation::Quadrilinear, false),
        ("quadrilinear_dc", Interpolation::Quadrilinear, true),
    ] {
        let lookup = Lookup {
            interpolation,
            depth_correction,
        };
        for (suffix, field) in [("", &raw), ("_codes", &codes)] {
            group.bench_function(format!("{name}{suffix}"), |b| {
                b.iter(|| black_box(render(field, &camera, w, h, lookup, &mut out)))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, lightfield);
criterion_main!(benches);
