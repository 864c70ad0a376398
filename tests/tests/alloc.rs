//! Zero allocations after the first frame: once a renderer has drawn a scene into a target,
//! drawing the same scene again allocates nothing (counted by [`tests::counting`]; set
//! `ALLOC_BACKTRACE=1` to see where a counted allocation came from). This file holds a
//! single test, so no other test runs in the process while it counts.

use engine::{FrameOptions, Renderer, Rgba, Target};
use tests::busy::busy_scene;
use tests::counting::{count, traces, tracked_pool, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn second_frame_allocates_nothing() {
    let (w, h) = (320, 200);
    let (scene, camera) = busy_scene(w, h);
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.1, 0.1, 0.1, 1.0)),
        ..Default::default()
    };
    tracked_pool(2).install(|| {
        let mut frame = || {
            let stats = renderer.render_scene(&scene, &camera, &mut target, &opts);
            assert!(stats.fragments_written > 0, "{stats:?}");
        };
        let ((), first) = count(&mut frame);
        assert!(first > 0, "the counter saw no allocation in the first frame: it is not counting");
        let ((), second) = count(&mut frame);
        assert_eq!(
            second,
            0,
            "the second frame allocated {second} times (run with ALLOC_BACKTRACE=1 to see where)\n{}",
            traces()
        );
    });
}
