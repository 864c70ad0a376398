use super::*;
use crate::color::Rgba;
use crate::testing::on_threads;
use crate::{Camera, Draw, FrameOptions, Lighting, Material, Mesh, Renderer};
use glam::{Mat4, Vec3};

const W: u32 = 150;
const H: u32 = 100;

fn camera() -> Camera {
    Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 1.5).with_depth_range(0.5, 50.0)
}

/// Reversed depth of a point `dist` along the axis.
fn reversed(dist: f32) -> f32 {
    camera()
        .clip_from_world()
        .project_point3(Vec3::new(0.0, 0.0, -dist))
        .z
}

/// A wall at distance `dist` covering the view, in `color`, as a pass.
struct Wall {
    depth: f32,
    color: Premul,
}

impl PixelPass for Wall {
    fn shade_span(&self, _x0: u32, _y: u32, out: &mut [Option<Fragment>]) {
        out.fill(Some(Fragment {
            color: self.color,
            depth: self.depth,
        }));
    }
}

/// A rasterized quad at distance `dist` spanning x in [x0, x1] (world units at that depth).
fn quad(dist: f32, x0: f32, x1: f32) -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(x0, -50.0, -dist),
            Vec3::new(x1, -50.0, -dist),
            Vec3::new(x1, 50.0, -dist),
            Vec3::new(x0, 50.0, -dist),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    }
}

fn scene(meshes: &[Mesh]) -> Target {
    let m = Material::unlit(Rgba::new(0.0, 0.0, 1.0, 1.0)).double_sided(true);
    let mut t = Target::new(W, H);
    Renderer::new().render(
        meshes.iter().map(|mesh| Draw {
            mesh,
            material: &m,
            transform: Mat4::IDENTITY,
        }),
        &camera(),
        &Lighting::default(),
        &mut t,
        &FrameOptions::default(),
    );
    t
}

fn red() -> Premul {
    Rgba::new(1.0, 0.0, 0.0, 1.0).premultiply()
}

#[test]
fn fragments_are_depth_tested_against_rasterized_geometry() {
    // Geometry nearer than the wall on the left (x < 0), farther on the right.
    let mut t = scene(&[quad(2.0, -50.0, 0.0), quad(8.0, 0.0, 50.0)]);
    let wall = Wall {
        depth: reversed(4.0),
        color: red(),
    };
    let stats = run_pass(&mut t, PixelRect::full(W, H), &wall, PassMode::default());
    assert_eq!(stats.fragments_tested, (W * H) as u64);
    assert_eq!(stats.fragments_shaded, (W * H) as u64);
    let (left, right) = (
        t.color_linear(10, 50).unwrap(),
        t.color_linear(140, 50).unwrap(),
    );
    assert!(
        left.b > 0.99 && left.r < 0.01,
        "geometry in front stays: {left:?}"
    );
    assert!(
        right.r > 0.99 && right.b < 0.01,
        "the pass is in front: {right:?}"
    );
    assert_eq!(t.depth_reversed(140, 50), Some(reversed(4.0)));
    assert!(t.depth_reversed(10, 50).unwrap() > reversed(4.0));
    // Half the image, give or take the column on the seam.
    let half = (W * H / 2) as u64;
    assert!(
        stats.fragments_written.abs_diff(half) <= H as u64,
        "{stats:?}"
    );
}

#[test]
fn blending_rectangles_and_odd_fragments() {
    let mut t = scene(&[]);
    let half = Wall {
        depth: reversed(4.0),
        color: Rgba::new(1.0, 0.0, 0.0, 0.5).premultiply(),
    };
    let blend = PassMode {
        blend: true,
        depth_write: false,
        ..Default::default()
    };
    let rect = PixelRect {
        x0: 20,
        y0: 30,
        x1: 90,
        y1: 1000, // clipped to the target
    };
    let stats = run_pass(&mut t, rect, &half, blend);
    assert_eq!(stats.fragments_written, 70 * 70);
    let c = t.color_linear(50, 50).unwrap();
    // 0.5 red over opaque black: premultiplied (0.5, 0, 0, 1), sRGB bytes within 1/255.
    assert!(
        (c.r - 0.5).abs() < 0.01 && (c.a - 1.0).abs() < 0.01,
        "{c:?}"
    );
    assert_eq!(t.depth_reversed(50, 50), Some(0.0), "depth not written");
    assert_eq!(
        t.color_linear(10, 50).unwrap().r,
        0.0,
        "outside the rectangle"
    );
    // Depths that are not finite or outside [0, 1] are skipped.
    for depth in [f32::NAN, f32::INFINITY, -0.5, 1.5] {
        let s = run_pass(
            &mut t,
            PixelRect::full(W, H),
            &Wall {
                depth,
                color: red(),
            },
            PassMode::default(),
        );
        assert_eq!(s.fragments_written, 0, "{depth}");
    }
    // Empty rectangles and targets.
    let none = PixelRect {
        x0: 40,
        y0: 0,
        x1: 40,
        y1: 10,
    };
    assert_eq!(run_pass(&mut t, none, &half, blend), FrameStats::default());
    let mut empty = Target::new(0, 0);
    assert_eq!(
        run_pass(&mut empty, PixelRect::full(9, 9), &half, blend),
        FrameStats::default()
    );
}

/// A pass whose fragments vary per pixel.
struct Gradient;

impl PixelPass for Gradient {
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]) {
        for (i, f) in out.iter_mut().enumerate() {
            let x = x0 + i as u32;
            if !(x + y).is_multiple_of(3) {
                let v = (x as f32 / W as f32, y as f32 / H as f32);
                *f = Some(Fragment {
                    color: Rgba::new(v.0, v.1, 0.5, 1.0).premultiply(),
                    depth: 0.2 + 0.5 * v.0,
                });
            }
        }
    }
}

#[test]
fn the_same_pixels_at_any_thread_count() {
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut t = scene(&[quad(3.0, -1.0, 1.0)]);
            let s = run_pass(
                &mut t,
                PixelRect::full(W, H),
                &Gradient,
                PassMode::default(),
            );
            (t, s)
        })
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.0, b.0);
    assert_eq!(a.1, b.1);
    assert!(a.1.fragments_written > 0);
}

/// [`Gradient`] with its colours packed in `encoding` first.
struct PackedGradient(Encoding);

impl PackedPass for PackedGradient {
    fn encoding(&self) -> Encoding {
        self.0
    }
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<PackedFragment>]) {
        let mut span = [None; TILE];
        Gradient.shade_span(x0, y, &mut span[..out.len()]);
        let enc = Encoder::new(self.0);
        for (o, f) in out.iter_mut().zip(span) {
            *o = f.map(|f| PackedFragment {
                color: enc.pack(f.color.r, f.color.g, f.color.b, f.color.a),
                depth: f.depth,
            });
        }
    }
}

#[test]
fn packed_passes_store_what_a_pass_of_the_same_colours_stores() {
    // Packed in the target's encoding: the bytes go in as they are, the same bytes the
    // encoder gives for the unpacked colour. Packed otherwise, or blended: decoded and
    // re-encoded, so equal to the unpacked pass of the decoded colours.
    for (target_enc, pass_enc, blend) in [
        (Encoding::Srgb, Encoding::Srgb, false),
        (Encoding::Srgb, Encoding::Srgb, true),
        (Encoding::Unorm, Encoding::Srgb, false),
    ] {
        let mode = PassMode {
            blend,
            ..PassMode::default()
        };
        let run = |packed: bool| {
            let mut t = scene(&[quad(3.0, -1.0, 1.0)]);
            t.set_encoding(target_enc);
            let rect = PixelRect::full(W, H);
            let s = if packed {
                run_packed_pass(&mut t, rect, &PackedGradient(pass_enc), mode)
            } else {
                run_pass(&mut t, rect, &Decoded(pass_enc), mode)
            };
            (t, s)
        };
        let (a, b) = (run(true), run(false));
        assert_eq!(a.1, b.1, "{target_enc:?} {pass_enc:?} {blend}");
        assert!(a.0 == b.0, "{target_enc:?} {pass_enc:?} {blend}");
        assert!(a.1.fragments_written > 0);
    }
}

/// [`Gradient`]'s colours after a round trip through `encoding`'s bytes.
struct Decoded(Encoding);

impl PixelPass for Decoded {
    fn shade_span(&self, x0: u32, y: u32, out: &mut [Option<Fragment>]) {
        let mut span = [None; TILE];
        PackedGradient(self.0).shade_span(x0, y, &mut span[..out.len()]);
        for (o, f) in out.iter_mut().zip(span) {
            *o = f.map(|f| Fragment {
                color: unpack(self.0, f.color),
                depth: f.depth,
            });
        }
    }
}
