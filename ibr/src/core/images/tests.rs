use super::atlas::Atlas;
use super::*;
use engine::{Projection, Rgba};

fn cameras() -> [Camera; 3] {
    let view = glam::Mat4::look_at_rh(Vec3::new(1.0, 2.0, 6.0), Vec3::ZERO, Vec3::Y);
    let persp = Camera {
        view,
        projection: Projection::Perspective {
            fov_y: 0.9,
            aspect: 1.5,
            near: 0.5,
            far: 40.0,
        },
    };
    let ortho = Camera {
        view,
        projection: Projection::Orthographic {
            left: -3.0,
            right: 2.0,
            bottom: -1.5,
            top: 2.5,
            near: 0.5,
            far: 40.0,
        },
    };
    let off_axis = persp.crop(
        glam::Vec2::new(10.0, -5.0),
        glam::Vec2::new(50.0, 30.0),
        60,
        40,
    );
    [persp, ortho, off_axis]
}

/// Projects a world point to (pixel x, pixel y, depth along the axis).
fn project(c: &Camera, p: Vec3, w: u32, h: u32) -> (f32, f32, f32) {
    let q = c.clip_from_world().project_point3(p);
    let depth = -(c.view.transform_point3(p)).z;
    (
        (q.x * 0.5 + 0.5) * w as f32,
        (0.5 - q.y * 0.5) * h as f32,
        depth,
    )
}

#[test]
fn unproject_inverts_the_projection_for_every_camera_kind() {
    for c in cameras() {
        for p in [
            Vec3::ZERO,
            Vec3::new(0.7, -0.4, 1.1),
            Vec3::new(-1.2, 0.9, -3.0),
        ] {
            let (x, y, d) = project(&c, p, 60, 40);
            let back = unproject(&c, x, y, d, 60, 40).expect("finite");
            assert!(
                (back - p).length() < 1e-3,
                "{:?}: {p} -> {back}",
                c.projection
            );
        }
        assert_eq!(unproject(&c, 3.0, 3.0, EMPTY, 60, 40), None);
        assert_eq!(unproject(&c, 3.0, 3.0, f32::NAN, 60, 40), None);
        assert_eq!(unproject(&c, 3.0, 3.0, 1.0, 0, 40), None);
    }
}

#[test]
fn axial_depth_inverts_the_stored_reversed_depth() {
    for c in cameras() {
        let p = Vec3::new(0.3, 0.2, -1.0);
        let d = c.clip_from_world().project_point3(p).z;
        let want = -(c.view.transform_point3(p)).z;
        assert!((axial_depth(&c, d) - want).abs() < 1e-3 * want);
        assert_eq!(axial_depth(&c, 0.0), EMPTY, "cleared");
        assert_eq!(axial_depth(&c, f32::NAN), EMPTY);
    }
}

#[test]
fn pixels_planes_and_world_points() {
    let [c, ..] = cameras();
    let mut im = DepthImage::new(4, 3, c);
    assert_eq!(im.covered(), 0);
    assert_eq!(im.world_point(1, 1), None);
    let red = Rgba::new(1.0, 0.0, 0.0, 0.5).premultiply();
    im.set(1, 2, red, 5.0);
    im.set(9, 9, red, 5.0); // outside: ignored
    assert_eq!(im.get(1, 2), Some((red, 5.0)));
    assert_eq!(im.get(4, 0), None);
    assert_eq!(im.covered(), 1);
    let p = im.world_point(1, 2).expect("covered");
    let (x, y, d) = project(&c, p, 4, 3);
    assert!((x - 1.5).abs() < 1e-3 && (y - 2.5).abs() < 1e-3 && (d - 5.0).abs() < 1e-3);
    assert!(DepthImage::from_planes(2, 2, vec![red; 4], vec![1.0; 3], c).is_none());
    assert!(DepthImage::from_planes(2, 2, vec![red; 4], vec![1.0; 4], c).is_some());
}

#[test]
fn layers_merge_into_sorted_samples_and_split_back() {
    let [c, ..] = cameras();
    let a = Rgba::new(1.0, 0.0, 0.0, 1.0).premultiply();
    let b = Rgba::new(0.0, 1.0, 0.0, 1.0).premultiply();
    let mut near = DepthImage::new(3, 2, c);
    let mut far = DepthImage::new(3, 2, c);
    near.set(0, 0, a, 2.0);
    far.set(0, 0, b, 7.0);
    far.set(2, 1, b, 3.0); // only in the second layer
                           // Given out of order, still nearest first.
    let ldi = LayeredDepthImage::from_layers(&[far.clone(), near.clone()]).expect("same size");
    assert_eq!(ldi.samples(0, 0).len(), 2);
    assert_eq!(ldi.samples(0, 0)[0].depth, 2.0);
    assert_eq!(ldi.samples(0, 0)[1].color, b);
    assert_eq!(ldi.samples(1, 0), &[]);
    assert_eq!(ldi.samples(2, 1).len(), 1);
    assert_eq!(ldi.samples(7, 7), &[]);
    assert_eq!(ldi.sample_count(), 3);
    assert_eq!(ldi.depth_complexity(), 2);
    assert_eq!(ldi.layer(0).get(0, 0), Some((a, 2.0)));
    assert_eq!(ldi.layer(1).get(0, 0), Some((b, 7.0)));
    assert_eq!(ldi.layer(1).get(2, 1).map(|s| s.1), Some(EMPTY));
    assert!(LayeredDepthImage::from_layers(&[]).is_none());
    assert!(LayeredDepthImage::from_layers(&[near, DepthImage::new(2, 2, c)]).is_none());
    assert_eq!(LayeredDepthImage::empty(3, 2, c).sample_count(), 0);
}

#[test]
fn atlas_cells_round_trip_and_stay_apart() {
    let [c, ..] = cameras();
    let mut atlas = Atlas::new(3, 2, 4, 5);
    assert_eq!(atlas.size(), (12, 10));
    assert_eq!(atlas.cell_origin(4), Some((4, 5)));
    assert_eq!(atlas.cell_origin(6), None);
    let mut cell = DepthImage::new(4, 5, c);
    for y in 0..5 {
        for x in 0..4 {
            let v = (y * 4 + x) as f32 / 20.0;
            cell.set(x, y, Rgba::new(v, v, v, 1.0).premultiply(), 1.0 + v);
        }
    }
    assert!(atlas.write_cell(4, &cell));
    assert!(!atlas.write_cell(6, &cell));
    assert_eq!(atlas.cell(4).as_ref(), Some(&cell));
    assert_eq!(atlas.cell(3), None, "not written");
    // Its neighbours are untouched.
    let (w, _) = atlas.size();
    for (x, y) in [(3u32, 5u32), (8, 5), (4, 4)] {
        assert_eq!(atlas.depth[(y * w + x) as usize], EMPTY);
    }
    let t = atlas.to_texture(engine::Encoding::Srgb, false);
    assert_eq!((t.width(), t.height()), (12, 10));
}
