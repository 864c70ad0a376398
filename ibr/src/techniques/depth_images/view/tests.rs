use super::*;
use crate::core::FrameLoop;
use engine::{FrameOptions, Lighting, Material, Mesh, Premul, Renderer, Rgba};
use glam::{Mat4, Vec3};

const W: u32 = 64;
const H: u32 = 48;

fn camera() -> Camera {
    Camera::look_at(
        Vec3::ZERO,
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        1.0,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 50.0)
}

/// A green wall at depth 5 filling the reference.
fn wall() -> DepthImage {
    let green = Rgba::new(0.1, 0.8, 0.2, 1.0).premultiply();
    let mut image = DepthImage::new(W, H, camera());
    image.color.fill(green);
    image.depth.fill(5.0);
    image
}

fn quad_at(x: f32, z: f32) -> Mat4 {
    Mat4::from_translation(Vec3::new(x, 0.0, z))
}

#[test]
fn warped_samples_and_geometry_hide_each_other_by_depth() {
    let mut view = WarpedView::new("wall", vec![wall()]);
    let quad: Mesh = engine::procedural::quad(1.0, 1.0);
    let red = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
    let blue = Material::unlit(Rgba::new(0.0, 0.0, 1.0, 1.0));
    // A red quad in front of the wall at the centre; a large blue one behind it.
    let scene = [
        Draw {
            mesh: &quad,
            material: &red,
            transform: quad_at(0.0, -3.0),
        },
        Draw {
            mesh: &quad,
            material: &blue,
            transform: Mat4::from_translation(Vec3::new(-3.0, 0.0, -8.0))
                * Mat4::from_scale(Vec3::splat(6.0)),
        },
    ];
    let cam = camera();
    let lighting = Lighting::default();
    let frame_view = FrameView::still(&cam, W, H, &lighting);
    let mut target = Target::new(W, H);
    let mut frame = FrameLoop::new();
    let mut list: [&mut dyn Technique; 1] = [&mut view];
    frame.render(
        &mut Renderer::new(),
        scene,
        &mut list,
        &frame_view,
        &mut target,
        &FrameOptions::default(),
    );
    let at = |x: u32, y: u32| target.color_linear(x, y).unwrap_or(Premul::TRANSPARENT);
    let centre = at(W / 2, H / 2);
    assert!(
        centre.r > 0.9 && centre.g < 0.1,
        "geometry in front shows: {centre:?}"
    );
    let left = at(4, H / 2);
    assert!(
        left.g > 0.7 && left.b < 0.3,
        "the wall hides geometry behind it: {left:?}"
    );
    // The wall writes its depth: distance 5 along the axis.
    let d = target.depth_reversed(4, H / 2).unwrap();
    assert!((cam.view_depth_from_reversed(d) - 5.0).abs() < 1e-3, "{d}");
    let c = frame.counters[0];
    assert_eq!(c.samples, (W * H) as u64);
    assert_eq!(c.pixels, (W * H) as u64);
    assert_eq!(c.holes, 0);
}

#[test]
fn the_pixels_a_frame_offers_are_the_filled_pixels_whatever_the_fill() {
    // An eye moved sideways sees holes beside the wall; one turned away sees nothing, so
    // no fill has anything to fill from.
    let mut moved = camera();
    moved.view *= Mat4::from_translation(Vec3::new(0.8, 0.1, 0.0));
    let away = Camera::look_at(Vec3::ZERO, Vec3::Z, Vec3::Y, 1.0, W as f32 / H as f32);
    // Carved, the holes beside the wall are unseen (past the reference's frame): no fill
    // paints them; uncarved, every fill does.
    for (eye, sees) in [(moved, true), (away, false)] {
        for (fill, carve) in [Fill::None, Fill::PullPush, Fill::Background]
            .into_iter()
            .flat_map(|f| [(f, false), (f, true)])
        {
            let mut view = WarpedView::new("wall", vec![wall()]);
            view.fill = fill;
            view.carve = carve;
            let frame = view.warp_to(&eye, W, H);
            assert_eq!(frame.pixels, view.image().filled(), "{fill:?}");
            let warped = frame.stats.pixels_written;
            match (sees, fill, carve) {
                (false, _, _) => assert_eq!(frame.pixels, 0, "{fill:?}"),
                (true, Fill::None, _) => assert!(frame.pixels < u64::from(W * H), "{frame:?}"),
                (true, _, false) => assert!(frame.pixels > warped, "{fill:?}: {frame:?}"),
                (true, _, true) => {
                    assert_eq!(frame.pixels, warped, "{fill:?}: {frame:?}");
                    let unseen = u64::from(W * H) - warped;
                    assert_eq!(frame.holes.unseen, unseen, "{fill:?}: {frame:?}");
                }
            }
        }
    }
}
