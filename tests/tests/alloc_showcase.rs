//! The showcase's frame allocates nothing once warm: billboard batches, lasers, effects,
//! impostor draws, the lens flare and its occlusion probe all reuse their memory (counted by
//! [`tests::counting`]; `ALLOC_BACKTRACE=1` shows where a counted allocation came from). One
//! test in this file, so nothing else allocates in the process while it counts.

use demos::showcase::{self, Showcase, SKY};
use engine::{FrameOptions, Renderer, Target};
use glam::Vec3;
use tests::counting::{count, traces, tracked_pool, Counting};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn a_warm_showcase_frame_allocates_nothing() {
    let (w, h) = (320, 180);
    let mut show = Showcase::new();
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(SKY),
        ..Default::default()
    };
    // A view with the plaza, the forest, the lasers, the city's images, clouds and the
    // sun in it.
    let eye = Vec3::new(-6.0, 7.0, 24.0);
    let camera = showcase::camera(eye, Vec3::new(-20.0, 10.0, -10.0), w, h);
    tracked_pool(2).install(|| {
        let mut frame = |show: &mut Showcase| {
            show.animate(2.0);
            show.render(&mut renderer, &camera, &mut target, &opts)
        };
        let (stats, first) = count(|| frame(&mut show));
        assert!(stats.fragments_written > 0);
        assert!(
            first > 0,
            "the counter saw nothing in the first frame: it is not counting"
        );
        // Warm: until every impostor in view has its image and none needs a refresh.
        let mut frames = 0;
        while frames < 60 {
            frame(&mut show);
            frames += 1;
            if show.ibr.impostors.readout().refreshes() == 0 {
                break;
            }
        }
        assert!(frames < 60, "the impostors never settled");
        let (_, warm) = count(|| frame(&mut show));
        assert_eq!(
            warm,
            0,
            "a warm showcase frame allocated {warm} times (ALLOC_BACKTRACE=1 shows where)\n{}",
            traces()
        );
    });
}
