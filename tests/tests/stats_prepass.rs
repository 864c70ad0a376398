//! The visibility pre-pass on the busy scene (opaque, alpha-tested, blended and additive
//! draws, textures, lights): the same colour and depth bytes as the one-pass path on 1 and
//! 2 threads, the same blended shading, and no more opaque shading than one pass.

use engine::{Encoding, FrameOptions, FrameStats, Renderer, Rgba, Target};
use tests::busy::busy_scene;

const W: u32 = 320;
const H: u32 = 200;

/// Colour bytes, depth bits and counters of one frame of the busy scene.
fn frame(prepass: bool, threads: usize) -> (Vec<u8>, Vec<u32>, FrameStats) {
    let (scene, camera) = busy_scene(W, H);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    let mut target = Target::with_encoding(W, H, Encoding::Srgb);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.05, 0.1, 0.15, 1.0)),
        ..Default::default()
    };
    let mut renderer = Renderer::new();
    renderer.set_visibility_prepass(prepass);
    let stats = pool.install(|| renderer.render_scene(&scene, &camera, &mut target, &opts));
    let depth = target
        .depth_gl_image()
        .iter()
        .map(|d| d.to_bits())
        .collect();
    (target.to_rgba8(), depth, stats)
}

#[test]
fn the_prepass_gives_the_one_pass_pixels_and_shades_less() {
    let (colour, depth, one) = frame(false, 1);
    for threads in [1, 2] {
        let (c, d, pre) = frame(true, threads);
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
