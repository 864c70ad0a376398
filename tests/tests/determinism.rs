//! Determinism: the same scene renders byte-identical colour and depth, and the same
//! statistics, whatever the number of rayon threads.

use engine::{Encoding, FrameOptions, FrameStats, Renderer, Rgba, Target};
use tests::busy::busy_scene;

const W: u32 = 320;
const H: u32 = 200;

/// Colour bytes, depth bits and stats of one frame of the busy scene.
fn frame(
    renderer: &mut Renderer,
    threads: usize,
    encoding: Encoding,
) -> (Vec<u8>, Vec<u32>, FrameStats) {
    let (scene, camera) = busy_scene(W, H);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    let mut target = Target::with_encoding(W, H, encoding);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.05, 0.1, 0.15, 1.0)),
        ..Default::default()
    };
    let stats = pool.install(|| renderer.render_scene(&scene, &camera, &mut target, &opts));
    let depth = target
        .depth_gl_image()
        .iter()
        .map(|d| d.to_bits())
        .collect();
    (target.to_rgba8_premultiplied(), depth, stats)
}

fn check_thread_counts(encoding: Encoding) {
    let (color1, depth1, stats1) = frame(&mut Renderer::new(), 1, encoding);
    assert!(
        stats1.triangles_clipped > 0 && stats1.fragments_written > (W * H) as u64,
        "{stats1:?}"
    );
    // The picture is not trivial: many distinct colours.
    let mut distinct: Vec<&[u8]> = color1.chunks_exact(4).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(distinct.len() > 1000, "only {} colours", distinct.len());
    // One renderer reused across pools of different sizes, and fresh ones.
    let mut shared = Renderer::new();
    for threads in [2, 8, 1, 8, 2] {
        for (k, r) in [&mut shared, &mut Renderer::new()].into_iter().enumerate() {
            let (color, depth, stats) = frame(r, threads, encoding);
            let what = format!(
                "{threads} threads ({})",
                ["reused renderer", "new renderer"][k]
            );
            let bad = color.iter().zip(&color1).filter(|(a, b)| a != b).count();
            assert!(bad == 0, "{what}: {bad} colour bytes differ from 1 thread");
            let bad = depth.iter().zip(&depth1).filter(|(a, b)| a != b).count();
            assert!(bad == 0, "{what}: {bad} depth values differ from 1 thread");
            assert_eq!(stats, stats1, "{what}: stats differ");
        }
    }
}

#[test]
fn same_bytes_at_1_2_and_8_threads() {
    check_thread_counts(Encoding::Srgb);
}

#[test]
fn same_bytes_at_1_2_and_8_threads_unorm() {
    check_thread_counts(Encoding::Unorm);
}

/// The visibility pre-pass (`Renderer::set_visibility_prepass`) on the busy scene (opaque,
/// alpha-tested, blended and additive draws, textures, lights): the same colour and depth
/// bytes as the one-pass path on 1 and 2 threads, the same blended shading, and no more
/// opaque shading than one pass.
#[test]
fn the_prepass_gives_the_one_pass_pixels_and_shades_less() {
    let (colour, depth, one) = frame(&mut Renderer::new(), 1, Encoding::Srgb);
    for threads in [1, 2] {
        let mut renderer = Renderer::new();
        renderer.set_visibility_prepass(true);
        let (c, d, pre) = frame(&mut renderer, threads, Encoding::Srgb);
        assert!(c == colour, "colour differs on {threads} threads");
        assert!(d == depth, "depth differs on {threads} threads");
        assert_eq!(pre.fragments_shaded_blended, one.fragments_shaded_blended);
        assert!(
            pre.fragments_shaded < one.fragments_shaded,
            "{threads} threads: {pre:?} against {one:?}"
        );
        assert!(pre.fragments_written <= one.fragments_written);
        assert_eq!(pre.triangles_set_up, one.triangles_set_up);
    }
}
