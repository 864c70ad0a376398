//! The warp reuses its memory: once a warped view has made frames along a path, making
//! them again allocates nothing: warp, hole count, pull-push and background fill (counted
//! by [`tests::counting`]). (A new eye may grow a bin of the warp's binning stage once, as
//! a new draw list would.) One test in this file, so no other test runs in the process
//! while it counts.

use engine::{FrameOptions, Renderer, Rgba, Target};
use glam::Vec3;
use ibr::depth_images::WarpedView;
use ibr::images::DepthImage;
use ibr::warp::holes::Fill;
use tests::busy::busy_scene;
use tests::counting::{count, traces, tracked_pool, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn a_warped_frame_allocates_nothing_after_the_first() {
    let (w, h) = (160, 100);
    let (scene, camera) = busy_scene(w, h);
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.1, 0.1, 0.1, 1.0)),
        ..Default::default()
    };
    Renderer::new().render_scene(&scene, &camera, &mut target, &opts);
    let reference = DepthImage::from_target(&target, &camera);
    let mut view = WarpedView::new("busy", vec![reference.clone(), reference]);
    let moved = |dx: f32| {
        let mut c = camera;
        c.view *= glam::Mat4::from_translation(Vec3::new(-dx, 0.0, 0.0));
        c
    };
    tracked_pool(2).install(|| {
        for fill in [Fill::PullPush, Fill::Background] {
            view.fill = fill;
            let (_, first) = count(|| view.warp_to(&moved(0.1), w, h));
            assert!(
                first > 0,
                "the counter saw no allocation in the first frame"
            );
            view.warp_to(&moved(0.2), w, h);
            let (frame, second) = count(|| {
                view.warp_to(&moved(0.1), w, h);
                view.warp_to(&moved(0.2), w, h)
            });
            assert!(
                frame.stats.samples > 0 && frame.holes.total() > 0,
                "{frame:?}"
            );
            assert_eq!(
                second,
                0,
                "{fill:?}: the warps along the path again allocated {second} times\n{}",
                traces()
            );
        }
    });
}
