//! Light slabs against the geometry they were captured from.

use super::*;
use crate::core::{FrameView, Technique};
use crate::warp::Warped;
use engine::color::Encoder;
use engine::{procedural, FrameOptions, Material, Mesh, Renderer, Rgba, Target};
use glam::Vec2;

pub(super) const W: u32 = 64;
pub(super) const H: u32 = 48;

/// A slab whose uv plane is the 2 x 2 square at z = 4 and st plane the one at z = 0,
/// images upright (x along +X, y down along -Y).
pub(super) fn slab(nuv: u32, nst: u32) -> Slab {
    let square = |z: f32| Rect3::centered(Vec3::new(0.0, 0.0, z), Vec3::X * 2.0, Vec3::NEG_Y * 2.0);
    Slab::new(square(4.0), square(0.0), [nuv, nuv, nst, nst], 0.5, 20.0).expect("a valid slab")
}

/// A `size` x `size` card at depth `z` (facing +z) coloured by a smooth gradient (vertex
/// colours), unlit.
pub(super) struct Card {
    mesh: Mesh,
    material: Material,
    at: Mat4,
}

impl Card {
    pub(super) fn new(z: f32, size: f32) -> Card {
        let mut mesh = procedural::quad(size, size);
        mesh.colors = vec![
            Rgba::new(0.9, 0.1, 0.1, 1.0),
            Rgba::new(0.1, 0.9, 0.1, 1.0),
            Rgba::new(0.1, 0.1, 0.9, 1.0),
            Rgba::new(0.9, 0.9, 0.1, 1.0),
        ];
        Card {
            mesh,
            material: Material::unlit(Rgba::WHITE).double_sided(true),
            at: Mat4::from_translation(Vec3::new(0.0, 0.0, z)),
        }
    }

    pub(super) fn draw(&self) -> Draw<'_> {
        Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: self.at,
        }
    }
}

pub(super) fn camera(eye: Vec3) -> Camera {
    Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.7, W as f32 / H as f32).with_depth_range(0.1, 30.0)
}

/// The geometry as the camera sees it: per pixel its colour packed as the light field
/// stores it, or `None` where nothing covers it.
pub(super) fn truth(draws: &[Draw<'_>], camera: &Camera) -> Vec<Option<u32>> {
    let mut t = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    let lighting = Lighting::default();
    Renderer::new().render(draws.iter().copied(), camera, &lighting, &mut t, &opts);
    let enc = Encoder::new(ENCODING);
    let image = crate::core::DepthImage::from_target(&t, camera);
    image
        .color
        .iter()
        .map(|c| (c.a >= 0.5).then(|| enc.pack(c.r, c.g, c.b, c.a)))
        .collect()
}

/// Mean absolute difference (8-bit levels of the stored encoding, colour channels) over
/// the pixels both cover, and how many they are.
pub(super) fn compare(out: &Warped, truth: &[Option<u32>]) -> (f32, u32) {
    let (mut sum, mut n) = (0.0, 0);
    for (i, want) in truth.iter().enumerate() {
        let Some(want) = *want else { continue };
        if !out.is_filled(i) {
            continue;
        }
        let (g, t) = (out.color[i].to_le_bytes(), want.to_le_bytes());
        sum += (0..3)
            .map(|k| (g[k] as f32 - t[k] as f32).abs())
            .sum::<f32>();
        n += 1;
    }
    (sum / (3 * n.max(1)) as f32, n)
}

#[test]
fn capture_cameras_put_st_samples_on_pixel_centres() {
    let s = slab(3, 8);
    for (i, j) in [(0, 0), (2, 1), (1, 2)] {
        let cam = s.camera(i, j);
        let m = cam.clip_from_world();
        for (ps, pt) in [(0u32, 0u32), (7, 0), (3, 5), (7, 7)] {
            let p = s.st.at((ps as f32 + 0.5) / 8.0, (pt as f32 + 0.5) / 8.0);
            let c = m * p.extend(1.0);
            let ndc = Vec2::new(c.x / c.w, c.y / c.w);
            let px = Vec2::new((ndc.x + 1.0) * 4.0, (1.0 - ndc.y) * 4.0);
            assert!(
                px.distance(Vec2::new(ps as f32 + 0.5, pt as f32 + 0.5)) < 1e-3,
                "camera ({i}, {j}), sample ({ps}, {pt}) at {px}"
            );
        }
    }
}

#[test]
fn a_card_in_the_focal_plane_looks_as_the_geometry_does() {
    let card = Card::new(0.0, 2.0);
    let draws = [card.draw()];
    let lf = LightField::capture(&draws, &Lighting::default(), slab(5, 48));
    let mut out = Warped::new(0, 0, camera(Vec3::Z));
    // Eyes between the capture cameras and in front of their plane.
    for eye in [Vec3::new(0.13, -0.21, 4.0), Vec3::new(-0.3, 0.25, 3.0)] {
        let cam = camera(eye);
        let want = truth(&draws, &cam);
        for (interpolation, depth_correction) in [
            (Interpolation::Quadrilinear, false),
            (Interpolation::Quadrilinear, true),
            (Interpolation::BilinearUv, false),
        ] {
            let lookup = Lookup {
                interpolation,
                depth_correction,
            };
            let frame = render(&lf, &cam, W, H, lookup, &mut out);
            let (mean, n) = compare(&out, &want);
            assert!(n > 500, "{eye}: the card covers {n} pixels");
            assert!(frame.pixels as u32 >= n, "{frame:?}");
            let limit = if interpolation == Interpolation::Quadrilinear {
                2.0
            } else {
                4.0
            };
            assert!(mean < limit, "{eye} {lookup:?}: mean error {mean}");
        }
    }
}

#[test]
fn denser_cameras_ghost_less_off_the_focal_plane() {
    // A card halfway to the camera plane: each camera sees it shifted, so the render
    // blends shifted copies (ghosts) unless the cameras are dense.
    let card = Card::new(1.5, 0.8);
    let draws = [card.draw()];
    let cam = camera(Vec3::new(0.11, -0.17, 4.5));
    let want = truth(&draws, &cam);
    let error = |nuv: u32, corrected: bool| {
        let lf = LightField::capture(&draws, &Lighting::default(), slab(nuv, 48));
        let mut out = Warped::new(0, 0, cam);
        render(
            &lf,
            &cam,
            W,
            H,
            Lookup {
                interpolation: Interpolation::Quadrilinear,
                depth_correction: corrected,
            },
            &mut out,
        );
        // Pixels where coverage disagrees count fully.
        let mut wrong = 0;
        for (i, want) in want.iter().enumerate() {
            let got = out.is_filled(i) && out.color_linear(i).a >= 0.5;
            wrong += (want.is_some() != got) as u32;
        }
        wrong
    };
    let (sparse, dense) = (error(3, false), error(15, false));
    assert!(sparse > 0, "sparse cameras show ghosts");
    assert!(
        dense * 2 < sparse,
        "3x3 cameras: {sparse} pixels off, 15x15: {dense}"
    );
    // Depth correction reads each camera where it saw the card: the ghosts go.
    let corrected = error(3, true);
    assert!(
        corrected * 2 < sparse,
        "3x3 cameras corrected: {corrected} pixels off, uncorrected {sparse}"
    );
}

#[test]
fn a_thin_bar_off_the_focal_plane_stays_whole_and_unghosted_with_depth_correction() {
    // A bar 1.4 samples thick halfway to sparse cameras: each sees it far from where the
    // others do, so a blend without depth correction shows three faint copies, and a
    // surface found from one camera alone breaks where that camera misses the bar.
    let mut mesh = procedural::quad(1.6, 0.06);
    mesh.colors = vec![Rgba::new(0.9, 0.6, 0.2, 1.0); mesh.positions.len()];
    let material = Material::unlit(Rgba::WHITE).double_sided(true);
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::from_translation(Vec3::new(0.0, 0.1, 1.5)),
    }];
    let cam = camera(Vec3::new(0.23, -0.31, 4.5));
    let want = truth(&draws, &cam);
    let lf = LightField::capture(&draws, &Lighting::default(), slab(3, 48));
    let coverage = |corrected: bool| {
        let mut out = Warped::new(0, 0, cam);
        let lookup = Lookup {
            interpolation: Interpolation::Quadrilinear,
            depth_correction: corrected,
        };
        render(&lf, &cam, W, H, lookup, &mut out);
        // Bar pixels drawn solid, and pixels drawn solid or faint where there is no bar.
        let (mut kept, mut ghosts) = (0, 0);
        for (i, want) in want.iter().enumerate() {
            let a = if out.is_filled(i) {
                out.color_linear(i).a
            } else {
                0.0
            };
            kept += (want.is_some() && a >= 0.5) as u32;
            ghosts += (want.is_none() && a > 0.05) as u32;
        }
        (kept, ghosts)
    };
    let bar = want.iter().filter(|w| w.is_some()).count() as u32;
    let (kept, ghosts) = coverage(true);
    let (_, uncorrected) = coverage(false);
    assert!(bar > 20, "{bar} bar pixels");
    // (Before the march along each ray and the other cameras' say, 0 of 35 were kept and
    // 59 ghost pixels drawn; now 29 and none.)
    assert!(kept * 4 >= bar * 3, "{kept} of {bar} bar pixels kept");
    assert!(
        ghosts * 4 < bar && ghosts * 4 < uncorrected,
        "{ghosts} ghost pixels corrected, {uncorrected} uncorrected, bar {bar}"
    );
}

#[test]
fn rays_outside_the_slab_or_from_behind_are_holes() {
    let card = Card::new(0.0, 2.0);
    let draws = [card.draw()];
    let lf = LightField::capture(&draws, &Lighting::default(), slab(3, 16));
    let mut out = Warped::new(0, 0, camera(Vec3::Z));
    // From behind the focal plane, looking back at it: no ray of this slab.
    let behind = Camera::look_at(Vec3::new(0.0, 0.0, -3.0), Vec3::ZERO, Vec3::Y, 0.7, 1.0);
    let f = render(&lf, &behind, W, H, Lookup::default(), &mut out);
    assert_eq!((f.rays, out.filled()), (0, 0));
    // Far to the side: rays cross the st square but not the uv square.
    let side = camera(Vec3::new(6.0, 0.0, 4.0));
    let f = render(
        &lf,
        &side,
        W,
        H,
        Lookup {
            interpolation: Interpolation::Nearest,
            depth_correction: true,
        },
        &mut out,
    );
    assert_eq!((f.rays, out.filled()), (0, 0));
    // Odd sizes and a degenerate camera: no panic, no NaN.
    for (w, h) in [(0, 0), (1, 1), (0, 5)] {
        let f = render(
            &lf,
            &camera(Vec3::new(0.0, 0.0, 4.0)),
            w,
            h,
            Lookup::default(),
            &mut out,
        );
        assert!(f.pixels <= (w * h) as u64);
    }
    let nan = camera(Vec3::new(f32::NAN, 0.0, 4.0));
    render(&lf, &nan, W, H, Lookup::default(), &mut out);
    assert!(out.disparity.iter().all(|d| !d.is_nan()));
}

#[test]
fn bad_slabs_are_refused_with_the_reason() {
    let sq = |z: f32| Rect3::centered(Vec3::new(0.0, 0.0, z), Vec3::X, Vec3::NEG_Y);
    assert_eq!(
        Slab::new(sq(4.0), sq(0.0), [0, 2, 2, 2], 0.1, 10.0),
        Err(SlabError::NoSamples(0, 2, 2, 2))
    );
    assert!(matches!(
        Slab::new(sq(0.0), sq(4.0), [2; 4], 0.1, 10.0),
        Err(SlabError::Behind(_))
    ));
    let tilted = Rect3::centered(Vec3::ZERO, Vec3::X, Vec3::new(0.0, -1.0, 1.0));
    assert_eq!(
        Slab::new(sq(4.0), tilted, [2; 4], 0.1, 10.0),
        Err(SlabError::NotParallel)
    );
    let flat = Rect3::centered(Vec3::ZERO, Vec3::X, Vec3::X);
    assert_eq!(
        Slab::new(sq(4.0), flat, [2; 4], 0.1, 10.0),
        Err(SlabError::Degenerate)
    );
    assert!(matches!(
        Slab::new(sq(4.0), sq(0.0), [2; 4], 1.0, 1.0),
        Err(SlabError::DepthRange(..))
    ));
}

/// The packed colour of `want` at the pixel `p` projects into.
fn want_at(want: &[Option<u32>], cam: &Camera, p: Vec3) -> u32 {
    let c = cam.clip_from_world() * p.extend(1.0);
    let x = ((c.x / c.w + 1.0) * 0.5 * W as f32) as u32;
    let y = ((1.0 - c.y / c.w) * 0.5 * H as f32) as u32;
    want[(y * W + x) as usize].unwrap_or(0)
}

#[test]
fn in_a_scene_the_light_field_is_depth_tested_against_the_geometry() {
    // The light field of a card in the focal plane, between a wall behind it and a grey
    // panel in front of its left half: as the geometry shows them.
    let card = Card::new(0.0, 2.0);
    let card_draw = card.draw();
    let lf = LightField::capture(&[card_draw], &Lighting::default(), slab(5, 48));
    let mut object = LightFieldObject::new("card", lf);
    let wall = procedural::quad(12.0, 12.0);
    let wall_mat = Material::unlit(Rgba::new(0.2, 0.3, 0.6, 1.0));
    let panel = procedural::quad(1.0, 3.0);
    let panel_mat = Material::unlit(Rgba::new(0.5, 0.5, 0.5, 1.0));
    let scene = [
        Draw {
            mesh: &wall,
            material: &wall_mat,
            transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -2.0)),
        },
        Draw {
            mesh: &panel,
            material: &panel_mat,
            transform: Mat4::from_translation(Vec3::new(-0.6, 0.0, 1.5)),
        },
    ];
    let cam = camera(Vec3::new(0.2, -0.1, 4.2));
    let lighting = Lighting::default();
    let view = FrameView::still(&cam, W, H, &lighting);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    let mut target = Target::new(W, H);
    let mut frame = crate::core::FrameLoop::new();
    let mut renderer = Renderer::new();
    frame.render(
        &mut renderer,
        scene.iter().copied(),
        &mut [&mut object as &mut dyn Technique],
        &view,
        &mut target,
        &opts,
    );
    let all = [scene[0], scene[1], card_draw];
    let want = truth(&all, &cam);
    let enc = Encoder::new(ENCODING);
    let got = crate::core::DepthImage::from_target(&target, &cam);
    let (mut sum, mut n) = (0.0f32, 0u32);
    for (c, want) in got.color.iter().zip(&want) {
        let (g, t) = (
            enc.pack(c.r, c.g, c.b, c.a).to_le_bytes(),
            want.expect("covered").to_le_bytes(),
        );
        sum += (0..3)
            .map(|k| (g[k] as f32 - t[k] as f32).abs())
            .sum::<f32>()
            / 3.0;
        n += 1;
    }
    let mean = sum / n as f32;
    let used = object.counters();
    assert!(used.pixels > 400 && used.images == 1, "{used:?}");
    // The frame matches the geometry (edges and resampling aside).
    assert!(mean < 3.0, "mean error {mean} levels");
    // In front of the card the panel shows (the light field's depth lost the test), beside
    // it the card, beyond the card the wall.
    let pixel = |p: Vec3| {
        let c = cam.clip_from_world() * p.extend(1.0);
        let x = ((c.x / c.w + 1.0) * 0.5 * W as f32) as u32;
        let y = ((1.0 - c.y / c.w) * 0.5 * H as f32) as u32;
        let c = got.color[(y * W + x) as usize];
        enc.pack(c.r, c.g, c.b, c.a)
    };
    let grey = enc.pack(0.5, 0.5, 0.5, 1.0);
    assert_eq!(
        pixel(Vec3::new(-0.6, 0.0, 1.5)),
        grey,
        "the panel hides the card"
    );
    let near_right = pixel(Vec3::new(0.6, 0.3, 0.0));
    assert_ne!(near_right, grey, "the card shows beside the panel");
    assert_eq!(
        near_right,
        want_at(&want, &cam, Vec3::new(0.6, 0.3, 0.0)),
        "as the geometry"
    );
    // The crop follows the card: fewer rays than the frame's pixels.
    assert!(
        object.last().rays < (W * H) as u64 / 2,
        "{:?}",
        object.last()
    );
}

/// A fresh folder for this test process.
fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("parallax-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn a_saved_light_field_loads_back_and_bad_files_are_refused_by_name() {
    use super::file::FileError;
    let card = Card::new(0.0, 2.0);
    let draws = [card.draw()];
    let lf = LightField::capture(&draws, &Lighting::default(), slab(3, 8));
    let dir = temp_dir("lightfield");
    let path = dir.join("card.plf");
    lf.save(&path).expect("saved");
    let back = LightField::load(&path).expect("loaded");
    assert_eq!(back.slab, lf.slab);
    let (Rays::Raw(back), Rays::Raw(raw)) = (&back.rays, &lf.rays) else {
        panic!("raw light fields load raw");
    };
    assert_eq!(back, raw);
    assert!(back.has_depth());
    let bytes = std::fs::read(&path).unwrap();
    let write = |name: &str, b: &[u8]| {
        let p = dir.join(name);
        std::fs::write(&p, b).unwrap();
        p
    };
    let named = |e: FileError, p: &std::path::Path| {
        let text = e.to_string();
        assert!(text.contains(&p.display().to_string()), "{text}");
        e
    };
    // Truncated in the samples, in the header, or empty.
    for cut in [bytes.len() - 1, 100, 0] {
        let p = write("cut.plf", &bytes[..cut]);
        let e = named(LightField::load(&p).unwrap_err(), &p);
        assert!(
            matches!(
                e,
                FileError::Length { .. } | FileError::NotALightField { .. }
            ),
            "{e}"
        );
    }
    // Trailing bytes.
    let mut long = bytes.clone();
    long.push(0);
    let p = write("long.plf", &long);
    assert!(matches!(
        named(LightField::load(&p).unwrap_err(), &p),
        FileError::Length { .. }
    ));
    // Not ours, another version.
    let p = write("png.plf", b"\x89PNG\r\n\x1a\n rest of a png");
    assert!(matches!(
        named(LightField::load(&p).unwrap_err(), &p),
        FileError::NotALightField { .. }
    ));
    let mut v3 = bytes.clone();
    v3[8] = 3;
    let p = write("v3.plf", &v3);
    assert!(matches!(
        named(LightField::load(&p).unwrap_err(), &p),
        FileError::Version { found: 3, .. }
    ));
    // A version 1 file (no planes at infinity) still loads; one claiming a plane at
    // infinity, or a flag no version knows, does not.
    let mut v1 = bytes.clone();
    v1[8] = 1;
    let p = write("v1.plf", &v1);
    assert_eq!(
        LightField::load(&p).expect("a version 1 file").slab,
        lf.slab
    );
    for (at, version) in [(13, 1), (14, 2)] {
        let mut flagged = bytes.clone();
        flagged[8] = version;
        flagged[at] = 1;
        let p = write("flags.plf", &flagged);
        assert!(matches!(
            named(LightField::load(&p).unwrap_err(), &p),
            FileError::Unknown { .. }
        ));
    }
    // A header claiming 65535^4 samples (a huge allocation if believed): refused before
    // reading them.
    let mut huge = bytes.clone();
    for k in 0..4 {
        huge[16 + 4 * k..20 + 4 * k].copy_from_slice(&u32::MAX.to_le_bytes()[..4]);
    }
    let p = write("huge.plf", &huge);
    let e = named(LightField::load(&p).unwrap_err(), &p);
    assert!(
        matches!(e, FileError::Count { .. } | FileError::Length { .. }),
        "{e}"
    );
    // A NaN in the geometry: a bad slab.
    let mut nan = bytes.clone();
    nan[32..36].copy_from_slice(&f32::NAN.to_le_bytes());
    nan[44..48].copy_from_slice(&f32::NAN.to_le_bytes());
    let p = write("nan.plf", &nan);
    assert!(matches!(
        named(LightField::load(&p).unwrap_err(), &p),
        FileError::Slab { .. }
    ));
    // Missing.
    let p = dir.join("missing.plf");
    assert!(matches!(
        named(LightField::load(&p).unwrap_err(), &p),
        FileError::Io { .. }
    ));
    let _ = std::fs::remove_dir_all(&dir);
}

/// One-pixel cracks inside an image (a hole with drawn pixels on both sides, across or
/// along) take the nearer side's colour and depth; a silhouette's outside (drawn on one
/// side only) stays a hole.
#[test]
fn cracks_between_drawn_pixels_are_filled_from_the_nearer_side() {
    let (near, far) = (0xff00_00ffu32, 0xffff_0000u32);
    // 5 x 3: a column of near pixels, a crack, far pixels; the last column empty.
    let mut c = object::Composite::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0));
    c.image = Warped::new(5, 3, c.image.camera);
    for y in 0..3 {
        for (x, (col, d)) in [(near, 0.5), (0, 0.0), (far, 0.1), (far, 0.1), (0, 0.0)]
            .into_iter()
            .enumerate()
        {
            if col != 0 {
                c.image.color[y * 5 + x] = col;
                c.image.disparity[y * 5 + x] = d;
            }
        }
    }
    c.rect = Some(engine::PixelRect {
        x0: 0,
        y0: 0,
        x1: 5,
        y1: 3,
    });
    let holes = c.image.disparity[1];
    c.fill_cracks();
    // The middle row's crack (x = 1) has near on its left, far on its right: near.
    assert_eq!(c.image.color[5 + 1], near);
    assert_eq!(c.image.disparity[5 + 1], 0.5);
    // The outside column (x = 4) has a drawn pixel on one side only: still a hole; so
    // are the border rows (no pixel above or below them to pair).
    assert_eq!(c.image.color[5 + 4], 0);
    assert_eq!(c.image.color[1], 0);
    assert_eq!(c.image.disparity[1], holes);
}

/// Hard edges: a partly covered pixel of alpha one half or more is drawn opaque, its colour
/// un-premultiplied (the colour the blend covered it with); below one half it becomes a
/// hole; opaque pixels and holes are left as they are.
#[test]
fn hard_edges_make_half_covered_pixels_opaque_and_the_rest_holes() {
    use engine::color::unpack;
    let enc = Encoder::new(ENCODING);
    let mut c = object::Composite::new(Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 1.0, 1.0));
    c.image = Warped::new(4, 1, c.image.camera);
    let hole = c.image.disparity[0];
    // Opaque, three quarters covered, one quarter covered, a hole: the same colour
    // (0.2, 0.4, 0.6) premultiplied by each coverage.
    let at = |a: f32| enc.pack(0.2 * a, 0.4 * a, 0.6 * a, a);
    c.image.color[..3].copy_from_slice(&[at(1.0), at(0.75), at(0.25)]);
    c.image.disparity[..3].copy_from_slice(&[0.5; 3]);
    c.harden();
    assert_eq!(c.image.color[0], at(1.0));
    let p = unpack(ENCODING, c.image.color[1]);
    assert_eq!(p.a, 1.0);
    // Within the 8-bit encoding's rounding of the three-quarter pixel.
    for (got, want) in [(p.r, 0.2), (p.g, 0.4), (p.b, 0.6)] {
        assert!((got - want).abs() < 0.02, "{got} against {want}");
    }
    assert_eq!(c.image.disparity[1], 0.5);
    assert_eq!((c.image.color[2], c.image.disparity[2]), (0, hole));
    assert_eq!((c.image.color[3], c.image.disparity[3]), (0, hole));
}

/// A supersampled capture holds each sample's coverage: a white card in the focal plane
/// whose edges cross the middle of samples (cells a quarter wide, the card's edges at
/// +-0.625) gives those samples alpha one half (two sub-samples of four inside), its
/// corners one quarter, inside one and outside nothing, from every camera; the depth of
/// a partly covered sample is the card's.
#[test]
fn a_supersampled_capture_holds_the_coverage_of_outlines() {
    let mesh = procedural::quad(1.25, 1.25);
    let material = Material::unlit(Rgba::WHITE).double_sided(true);
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    }];
    let lf = LightField::capture_supersampled(&draws, &Lighting::default(), slab(2, 8), 2);
    let alpha = |u, v, s, t| lf.sample(u, v, s, t) >> 24;
    for (u, v) in [(0, 0), (1, 0), (1, 1)] {
        for (s, t, want) in [(3, 3, 255), (1, 3, 128), (6, 4, 128), (1, 1, 64), (0, 3, 0)] {
            assert_eq!(
                alpha(u, v, s, t),
                want,
                "camera ({u}, {v}), sample ({s}, {t})"
            );
        }
        // White, premultiplied (linear): every colour channel equals alpha.
        let c = engine::color::unpack(ENCODING, lf.sample(u, v, 1, 3));
        let near = |x: f32| (x - c.a).abs() < 0.01;
        assert!(near(c.r) && near(c.g) && near(c.b), "{c:?}");
        assert!((lf.depth_at(u, v, 1, 3) - 4.0).abs() < 1e-3);
        assert_eq!(lf.depth_at(u, v, 0, 3), f32::INFINITY);
    }
}
