//! The views moment at small sizes: the panorama is captured again past its tolerance and
//! fills what the near scene leaves, and the morph keeps shape where the plain morph does
//! not.

use super::*;
use crate::showcase::Showcase;
use std::sync::OnceLock;

const W: u32 = 96;
const H: u32 = 64;

/// The showcase's scene posed at time 0, built once for all the tests.
fn scene() -> Scene {
    static SCENE: OnceLock<Scene> = OnceLock::new();
    SCENE
        .get_or_init(|| {
            let mut show = Showcase::new();
            show.animate(0.0);
            show.scene
        })
        .clone()
}

/// The sky part's frames along its walk, `n` of them, and whether each frame image is
/// opaque everywhere.
fn sky_walk(n: usize) -> Vec<(SkyFrame, bool)> {
    let mut tour = ViewsTour::new(scene(), W, H);
    (0..n)
        .map(|k| {
            let opaque = tour
                .render_part(Part::Sky, k as f32 / (n - 1) as f32)
                .expect("the sky always renders")
                .rgba
                .chunks(4)
                .all(|p| p[3] == 255);
            assert!(tour.readout().starts_with("PANORAMA SKY"));
            match tour.last() {
                Shown::Sky(f) => (f, opaque),
                other => panic!("showed {other:?}"),
            }
        })
        .collect()
}

#[test]
fn the_sky_fills_what_the_near_scene_leaves_and_its_error_is_measured() {
    for (k, (f, opaque)) in sky_walk(4).into_iter().enumerate() {
        assert!(opaque, "frame {k} has empty pixels");
        // What the geometry shows and the frame does not: what the moved eye sees that
        // the panorama's centre did not. (Measured: at most 33 of 6,144 pixels.)
        assert!(f.unfilled * 100 < (W * H) as u64, "frame {k}: {f:?}");
        let e = f.error.expect("the far scene is in view");
        assert!(
            e.psnr_db.is_finite() && e.psnr_db > 10.0,
            "frame {k}: {e:?}"
        );
        // The far land's band along the horizon.
        assert!(f.far_share > 0.02 && f.far_share < 0.3, "frame {k}: {f:?}");
    }
}

#[test]
fn the_morph_keeps_shape_where_the_plain_morph_does_not() {
    let mut tour = ViewsTour::new(scene(), W, H);
    let frame = tour.render_part(Part::Morph, 0.5).expect("morphable");
    assert_eq!((frame.width, frame.height), (W, H));
    let Shown::Morph(f) = tour.last() else {
        panic!("showed {:?}", tour.last());
    };
    let ((good, seen), (bad, plain_seen)) = (f.error.expect("measured"), f.plain.expect("too"));
    eprintln!("{f:?}\n{}", tour.readout());
    // (Measured at 96x64: 23.5 dB over 99% of the geometry's pixels against 20.5 dB over
    // 76%; at 640x360 27.9 against 20.3 dB.)
    assert!(good.psnr_db.is_finite() && bad.psnr_db.is_finite());
    assert!(good.psnr_db > bad.psnr_db + 2.0, "{good:?} against {bad:?}");
    assert!(
        seen > 0.95 && seen > plain_seen + 0.1,
        "{seen} against {plain_seen}"
    );
    assert!(f.stats.from_left > 0 && f.stats.from_right > 0, "{f:?}");
    assert!(tour.readout().starts_with("VIEW MORPH S 0.50"));
    // Only the columns the postwarp reads (with a margin) of the rows it reads are
    // morphed: the canvas is as wide as about 1.7 frames (the views captured 1.3 times
    // as wide, prewarped to a pair 1.3 times that), the frame reads about one.
    assert!(f.canvas_px >= f.frame_px / 2, "{f:?}");
    assert!(f.canvas_px * 10 < f.band_px * 8, "{f:?}");
}

#[test]
fn the_frames_are_shared_out_among_the_parts_in_order() {
    let n = 7;
    let shown: Vec<(Part, f32)> = (0..n).map(|i| Part::at(i, n)).collect();
    assert_eq!(
        shown.iter().map(|s| s.0).collect::<Vec<_>>(),
        [
            [Part::Layers; 3].as_slice(),
            &[Part::Sky; 2],
            &[Part::Morph; 2]
        ]
        .concat()
    );
    let ts: Vec<f32> = shown.iter().map(|s| s.1).collect();
    assert_eq!(ts, [0.0, 0.5, 1.0, 0.0, 1.0, 0.0, 1.0]);
    // Fewer frames than parts: each part still shows, halfway, from one frame.
    assert_eq!(Part::at(0, 1), (Part::Layers, 0.5));
    assert_eq!(Part::at(2, 3), (Part::Morph, 0.5));
    assert_eq!(Part::at(9, 3), Part::at(2, 3));
}

/// The per-stage times of `views_times.csv`: each frame fills only its own part's
/// stages (the others zero), and its row has a value per column.
#[test]
fn each_frame_times_only_its_own_parts_stages() {
    let mut tour = ViewsTour::new(scene(), 48, 32);
    let zero = Duration::ZERO;
    for i in 0..6 {
        let frame = tour.render(i, 6).expect("renders");
        let s = frame.stages;
        let others = match Part::at(i, 6).0 {
            Part::Layers => [s.sky, s.canvas, s.postwarp],
            Part::Sky => [s.layers, s.canvas, s.postwarp],
            Part::Morph => [s.layers, s.sky, s.geometry],
        };
        assert_eq!(others, [zero; 3], "frame {i}: {s:?}");
        assert_eq!(s.row(frame.measure).len(), Stages::COLUMNS.len());
    }
}

#[test]
fn the_summary_has_a_line_per_part_shown() {
    let mut tour = ViewsTour::new(scene(), 48, 32);
    assert!(tour.summary().is_empty());
    assert_eq!(tour.readout(), "VIEWS");
    for i in 0..6 {
        tour.render(i, 6).expect("renders");
    }
    let lines = tour.summary();
    assert_eq!(lines.len(), 3, "{lines:?}");
    assert!(
        lines[0].starts_with("layered background: 2 frames"),
        "{lines:?}"
    );
    assert!(lines[1].starts_with("panorama sky: 2 frames"), "{lines:?}");
    assert!(lines[2].starts_with("view morph: 2 frames"), "{lines:?}");
    assert!(!lines.concat().contains("NaN"), "{lines:?}");
    assert!(tour.captures() >= 1);
}

#[test]
fn the_layered_background_warps_most_layers_and_stays_near_the_geometry() {
    let mut tour = ViewsTour::new(scene(), 160, 96);
    let mut frames = Vec::new();
    // The first eighth of the stroll, frame by frame as the window would show it.
    for k in 0..8 {
        tour.render_part(Part::Layers, k as f32 / 64.0)
            .expect("layers always render");
        assert!(tour.readout().starts_with("LAYERED BACKGROUND"));
        match tour.last() {
            Shown::Layers(f) => frames.push(f),
            other => panic!("showed {other:?}"),
        }
    }
    let part = tour.layers.as_ref().expect("built");
    assert!(
        part.layers.subjects.len() > 40,
        "{}",
        part.layers.subjects.len()
    );
    let triangles = |gs: &[ibr::subject::MeshGroup]| {
        gs.iter()
            .map(ibr::subject::Subject::triangle_count)
            .sum::<usize>()
    };
    let scene_triangles: usize = scene().draws().map(|d| d.mesh.triangle_count()).sum();
    assert_eq!(
        triangles(&part.layers.subjects) + triangles(&part.near),
        scene_triangles,
        "every object a layer or near geometry"
    );
    // The first view's images were made ahead (as loading): every frame warps most.
    let later: usize = frames.iter().map(|f| f.refreshes).sum();
    assert!(later < 7 * LAYERS_BUDGET, "{frames:?}");
    for f in &frames {
        assert!(f.max_px <= LAYERS_TOLERANCE_PX + 1e-3, "{f:?}");
        let e = f.error.expect("same size");
        assert!(e.psnr_db > 25.0 && e.frac_over < 0.05, "{}", f.line());
    }
}

/// A slow pan, as the window plays the stroll (20 s at 30 frames a second: t moves 1/600 a
/// frame, 1 cm, and the view turns 0.07 degrees): the images of the first view are made
/// ahead, and after that a layer is re-rendered only when its predicted error passes the
/// tolerance. A layer 10 units away or farther moves at most `focal x 0.01 / 10` pixels a
/// frame by parallax (0.3 px at 320 wide; the turn the perspective warp follows exactly),
/// so it passes a pixel no sooner than every third frame: a third of the images a frame at
/// most, on average, and far below the per-frame cap.
#[test]
fn on_a_slow_pan_few_layers_are_re_rendered_and_every_frame_is_within_tolerance() {
    let mut tour = ViewsTour::new(scene(), 320, 180);
    let n = 30;
    let (mut refreshes, mut images) = (0, 0);
    for k in 0..n {
        tour.render_part(Part::Layers, k as f32 / 600.0)
            .expect("layers always render");
        let Shown::Layers(f) = tour.last() else {
            panic!("showed {:?}", tour.last());
        };
        eprintln!("{k}: {}", f.line());
        if k == 0 {
            assert_eq!(f.refreshes, 0, "made ahead: {f:?}");
        }
        assert!(f.max_px <= LAYERS_TOLERANCE_PX, "frame {k}: {f:?}");
        assert!(f.refreshes <= LAYERS_BUDGET / 2, "frame {k}: {f:?}");
        assert_eq!(
            f.geometry, 0,
            "frame {k}: every layer in view an image: {f:?}"
        );
        refreshes += f.refreshes;
        images += f.images;
    }
    assert!(
        3 * refreshes <= images,
        "{refreshes} re-rendered for {images} drawn"
    );
}

#[test]
fn the_layered_background_is_within_its_tolerance_at_the_headless_runs_steps() {
    // Four frames over the whole stroll, as `showcase --headless` (120 frames) shows it:
    // steps that put most layers past a pixel each frame, more than the budget re-renders.
    // (Before: 1.83 to 1.95 px drawn on frames 1 to 3 at 1280x720.)
    let mut tour = ViewsTour::new(scene(), 160, 96);
    for k in 0..4 {
        tour.render_part(Part::Layers, k as f32 / 3.0)
            .expect("layers always render");
        let Shown::Layers(f) = tour.last() else {
            panic!("showed {:?}", tour.last());
        };
        eprintln!("{k}: {}", f.line());
        assert!(f.max_px <= LAYERS_TOLERANCE_PX, "frame {k}: {f:?}");
        assert!(f.refreshes <= LAYERS_BUDGET, "frame {k}: {f:?}");
        assert!(f.images > 0, "frame {k}: {f:?}");
        // Against the render of all the geometry from the same eye: the worst-frame
        // goal. (Measured at 160x96: 50.6, 33.6, 38.9, 31.7 dB.)
        let e = f.error.expect("same size");
        assert!(
            e.psnr_db >= 25.0 && e.frac_over < 0.05,
            "frame {k}: {}",
            f.line()
        );
    }
}

/// Building the parts ahead ([`ViewsTour::prepare`]) changes nothing a frame shows, makes
/// the panorama's first capture before any frame, and a second call builds nothing more.
#[test]
fn parts_built_ahead_show_the_same_frames() {
    let n = 12;
    let mut lazy = ViewsTour::new(scene(), W, H);
    let mut ahead = ViewsTour::new(scene(), W, H);
    assert_eq!(ahead.captures(), 0);
    ahead.prepare().expect("the parts build");
    let captured = ahead.captures();
    assert!(captured >= 1, "{captured}");
    ahead.prepare().expect("already built");
    assert_eq!(ahead.captures(), captured);
    for i in 0..n {
        let a = lazy.render(i, n).expect("lazy").rgba.clone();
        let b = ahead.render(i, n).expect("ahead").rgba.clone();
        assert!(a == b, "frame {i} differs");
    }
}

/// Over the left tenth of two `w`-wide RGBA8 images: the mean absolute difference (8-bit
/// levels, RGB) and the share of pixels off by more than 32 levels.
fn left_edge_error(a: &[u8], b: &[u8], w: usize) -> (f64, f64) {
    let strip = (w / 10).max(1);
    let (mut sum, mut over, mut n) = (0.0, 0usize, 0usize);
    for (i, (p, q)) in a.chunks(4).zip(b.chunks(4)).enumerate() {
        if i % w < strip {
            let d = (0..3)
                .map(|c| (p[c] as f64 - q[c] as f64).abs())
                .sum::<f64>()
                / 3.0;
            (sum, over, n) = (sum + d, over + (d > 32.0) as usize, n + 1);
        }
    }
    (sum / n.max(1) as f64, over as f64 / n.max(1) as f64)
}

#[test]
fn the_morphs_left_edge_shows_what_the_geometry_shows() {
    // Issue 39: with views captured only as wide as the frame, the turned in-between views
    // showed a strip at the frame's left edge neither view saw, filled along its rows from
    // each row's first mapped pixel (grey and green streaks beside the house at s 0.33 and
    // 0.67). The views are now captured wider: against the geometry from the same eye, the
    // frame's left tenth is nearer than the morph of views as wide as the frame, with
    // fewer pixels far off. (Measured at 160x96: 6.25 against 6.85 levels, 5.3% against
    // 6.6% of pixels over 32 levels at s 0.33; 5.77 against 6.29, 4.9% against 6.6% at
    // s 0.67.)
    let (w, h) = (160u32, 96u32);
    let scene = scene();
    let draws: Vec<Draw<'_>> = scene.draws().collect();
    let cameras = MORPH_EYES.map(|eye| crate::showcase::camera(eye, MORPH_TARGET, w, h));
    let narrow = ibr::capture::capture_batch(&draws, &cameras, &scene.lighting, w, h);
    let depth = ibr::morph::Correspondence::Depth;
    let as_wide = ibr::morph::ViewMorph::new(&narrow[0], &narrow[1], depth).expect("morphable");
    let mut tour = ViewsTour::new(scene.clone(), w, h);
    for s in [1.0 / 3.0, 2.0 / 3.0] {
        tour.render_part(Part::Morph, s).expect("morphable");
        let (shown, truth, _) = tour.renders().expect("a morph frame");
        let mut before = Vec::new();
        over_sky(&as_wide.view(s).0, &mut before);
        let now = left_edge_error(&shown, &truth, w as usize);
        let then = left_edge_error(&before, &truth, w as usize);
        eprintln!("s {s:.2}: left tenth off by {now:?} (mean, share over 32), {then:?} before");
        assert!(
            now.0 < then.0 && now.1 <= then.1,
            "s {s:.2}: {now:?} against {then:?}"
        );
    }
}

/// The sky part alone at `w` x `h` with tolerance `tolerance_px`, its `n` frames along the
/// walk.
fn sky_part_walk(w: u32, h: u32, tolerance_px: f32, n: usize) -> Vec<SkyFrame> {
    let scene = scene();
    let draws: Vec<Draw<'_>> = scene.draws().collect();
    let mut part = SkyPart::with_tolerance(&scene.lighting, w, h, tolerance_px);
    let mut frame = Frame::default();
    (0..n)
        .map(|k| {
            part.frame(
                &draws,
                &scene.lighting,
                k as f32 / (n - 1) as f32,
                &mut frame,
            )
        })
        .collect()
}

/// Along eight frames of the walk (a tenth of a pixel's tolerance at this size walks as far
/// as 3 px at 640x360): the re-capture begins a frame before the held panorama passes
/// its tolerance (four faces to render: the top and bottom faces see none of the far land
/// and are left empty), takes two faces a frame and no more, and is swapped in whole at
/// the frame where it passes, the only frame the readout says so; never drawn past it.
#[test]
fn the_sky_re_captures_two_faces_a_frame_and_swaps_where_it_passes_its_tolerance() {
    let tolerance = 0.3;
    let frames = sky_part_walk(W, H, tolerance, 8);
    let faces: Vec<usize> = frames.iter().map(|f| f.faces).collect();
    for (k, f) in frames.iter().enumerate() {
        eprintln!("{k}: {f:?}");
        assert!(f.faces <= 2, "frame {k}: {f:?}");
        assert_eq!(f.recaptured, f.before_px > tolerance, "frame {k}: {f:?}");
        assert!(f.predicted_px <= tolerance, "frame {k}: {f:?}");
        assert_eq!(
            f.line().contains("RE-CAPTURED"),
            f.recaptured,
            "{}",
            f.line()
        );
        let shown = format!("PARALLAX {:.1} PX", f.before_px);
        assert!(f.line().contains(&shown), "frame {k}: {}", f.line());
    }
    // The eye moves on at an even pace: 1.25 tolerances over the walk, past it at 7/8.
    assert_eq!(faces, [0, 0, 0, 0, 0, 2, 2, 0], "{frames:?}");
    assert!(frames[6].recaptured && frames[6].predicted_px < 1e-2);
    assert_eq!(frames[7].captures, 2);
}

/// The headless run's four sky frames: the re-capture's four faces (the far land's; the
/// top and bottom faces hold none) spread over the last two, swapped at the last, where
/// the held panorama passes its tolerance; no frame takes more than two faces, and the
/// first two sky frames render none. Of each face only the rows round the horizon that
/// the far land can cover are rendered: under a third of the two faces' pixels a frame.
#[test]
fn the_sky_at_the_headless_runs_steps_spreads_its_re_capture() {
    let frames = sky_part_walk(W, H, 0.3, 4);
    let faces: Vec<usize> = frames.iter().map(|f| f.faces).collect();
    assert_eq!(faces, [0, 0, 2, 2], "{frames:?}");
    let side = SkyPart::with_tolerance(&scene().lighting, W, H, 0.3)
        .sky
        .size as u64;
    let pixels: Vec<u64> = frames.iter().map(|f| f.face_px).collect();
    assert!(pixels[..2] == [0, 0], "{pixels:?}");
    for p in &pixels[2..] {
        assert!(
            *p > 0 && 3 * p < 2 * side * side,
            "{pixels:?} of faces {side} px"
        );
    }
    assert!(frames[2].line().contains("MPX"), "{}", frames[2].line());
    let swaps: Vec<bool> = frames.iter().map(|f| f.recaptured).collect();
    assert_eq!(swaps, [false, false, false, true], "{frames:?}");
    assert!(
        frames[3].before_px > 0.3 && frames[2].before_px <= 0.3,
        "{frames:?}"
    );
}

/// The panorama of the far land right where it was captured, at 320x180, against the
/// whole geometry drawn from the same eye (an independent render: the ring's triangles
/// rasterized in the view, not resampled from the cube's faces), over the pixels it
/// fills: near the attraction's goals. (Measured: 29.6 dB over 1,316 pixels; what is left
/// is on the ridges' outlines against the sky, resampled from a face of about a texel
/// per pixel.)
#[test]
fn the_sky_fresh_from_its_capture_is_within_the_goals_against_the_geometry() {
    let frames = sky_part_walk(320, 180, SKY_TOLERANCE_PX, 2);
    let e = frames[0].error.expect("the far land is in view");
    assert!(
        frames[0].before_px < 1e-3 && frames[0].far_share > 0.02,
        "{frames:?}"
    );
    assert!(e.psnr_db > 28.0, "{e:?}");
}

#[test]
fn over_sky_packs_eight_pixels_as_it_packs_one() {
    // Colours over the whole range and past it (negative, above 1, partly covered), in an
    // image whose size is neither a multiple of 8 nor of the pool's chunks: the 8-lane path
    // and the one-pixel path give the same bytes.
    let (w, h) = (4099u32, 3u32);
    let camera = crate::showcase::camera(glam::Vec3::ZERO, glam::Vec3::NEG_Z, w, h);
    let mut image = DepthImage::new(w, h, camera);
    let mut seed = 7u32;
    let mut next = || {
        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (seed >> 8) as f32 / (1 << 24) as f32 * 1.4 - 0.2
    };
    for c in image.color.iter_mut() {
        let a = next().clamp(0.0, 1.0);
        *c = Premul {
            r: next() * a,
            g: next() * a,
            b: next() * a,
            a,
        };
    }
    let mut out = Vec::new();
    over_sky(&image, &mut out);
    let (sky, encoder) = (SKY.premultiply(), Encoder::new(Encoding::Srgb));
    let one: Vec<u8> = (image.color.iter())
        .flat_map(|&c| over_sky_pixel(&encoder, sky, c).to_le_bytes())
        .collect();
    assert_eq!(out.len(), one.len());
    let differ = out.iter().zip(&one).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{differ} bytes differ");
}

#[test]
fn the_draws_out_of_view_cover_no_pixel_of_it() {
    // The sky's and the layers' near scenes draw only what their view's frustum reaches
    // (a draw's bounding sphere): the same pixels, colour and depth, as all the draws.
    let scene = scene();
    let draws: Vec<Draw<'_>> = scene.draws().collect();
    let spheres = world_spheres(&draws);
    let mut capturer = ibr::capture::Capturer::new();
    let look = |eye: glam::Vec3, dir: glam::Vec3| crate::showcase::camera(eye, eye + dir, W, H);
    let cameras = [
        look(SKY_CENTRE, glam::Vec3::new(0.3, -0.1, -1.0)),
        look(
            glam::Vec3::new(-3.0, 2.2, 5.0),
            glam::Vec3::new(-0.34, -0.12, -0.94),
        ),
        look(
            glam::Vec3::new(3.0, 2.6, 5.0),
            glam::Vec3::new(0.34, -0.12, -0.94),
        ),
    ];
    for camera in cameras {
        let mut near = Vec::new();
        in_view(&draws, &spheres, &camera, &mut near);
        eprintln!(
            "{} of {} draws in view, {} of {} triangles",
            near.len(),
            draws.len(),
            triangles(&near),
            triangles(&draws)
        );
        assert!(!near.is_empty() && near.len() * 10 < draws.len() * 9);
        let empty = DepthImage::new(0, 0, camera);
        let (mut all, mut seen) = (empty.clone(), empty);
        let lighting = &scene.lighting;
        capturer.capture(draws.iter().copied(), &camera, lighting, W, H, &mut all);
        capturer.capture(near.iter().copied(), &camera, lighting, W, H, &mut seen);
        assert_eq!(all, seen);
    }
}

/// The sky frame's one pass over the engine's bytes ([`sky::over_panorama`]) makes the
/// bytes of the float path it replaced (the near scene read back to linear floats, the
/// panorama behind its empty pixels, [`over_sky`]) at three eyes along the walk, on one
/// thread and on the pool; and it tells the near scene, the panorama and neither apart.
#[test]
fn the_panorama_pass_makes_the_float_paths_bytes() {
    let scene = scene();
    let draws: Vec<Draw<'_>> = scene.draws().collect();
    let part = SkyPart::with_tolerance(&scene.lighting, W, H, SKY_TOLERANCE_PX);
    let mut capturer = ibr::capture::Capturer::new();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool of one thread");
    for t in [0.0, 0.5, 1.0] {
        let (eye, at) = part.pose(t);
        let camera = crate::showcase::camera(eye, at, W, H);
        let target = capturer.render(
            draws.iter().copied(),
            &camera,
            &scene.lighting,
            W,
            H,
            Encoding::Srgb,
        );
        let mut image = DepthImage::from_target(target, &camera);
        part.sky.map.behind(&mut image);
        let mut floats = Vec::new();
        over_sky(&image, &mut floats);
        let pass = || {
            let (mut out, mut kinds) = (Vec::new(), Vec::new());
            let behind = part.sky.map.behind_view(&camera, (W, H));
            let lookups = sky::over_panorama(target, &behind, &mut out, &mut kinds);
            (out, kinds, lookups)
        };
        let (out, kinds, lookups) = pass();
        assert_eq!(
            one.install(pass),
            (out.clone(), kinds.clone(), lookups),
            "t {t}"
        );
        let differ = out.iter().zip(&floats).filter(|(a, b)| a != b).count();
        assert!(
            out.len() == floats.len() && differ == 0,
            "t {t}: {differ} bytes differ"
        );
        let count = |k: u8| kinds.iter().filter(|&&x| x == k).count();
        let (near, far, nothing) = (count(sky::NEAR), count(sky::FAR), count(sky::NOTHING));
        eprintln!("t {t}: near {near}, far {far}, nothing {nothing} px, {lookups} looked up");
        assert!(near > 0 && far > 0 && nothing > 0, "t {t}");
        // Every pixel the panorama fills was looked up; not every empty one.
        assert!(
            lookups >= far as u64 && lookups < (far + nothing) as u64,
            "t {t}"
        );
        // The float path's image after the panorama: empty exactly where neither shows.
        for (k, c) in kinds.iter().zip(&image.color) {
            assert_eq!(*k == sky::NOTHING, c.a <= 0.0, "t {t}");
        }
    }
}

/// The layers frame's bytes ([`Target::write_rgba8`]) are the stored premultiplied bytes
/// unpremultiplied one pixel at a time (the reference below), for opaque, empty and partly
/// covered pixels (a half-transparent quad over the scene's edge against
/// the empty sky), into a kept buffer of another size, on one thread and on the pool.
#[test]
fn the_layers_bytes_are_each_pixels_straight_alpha_at_any_thread_count() {
    let scene = scene();
    let mut draws: Vec<Draw<'_>> = scene.draws().collect();
    let quad = engine::Mesh {
        positions: [(-1.5, 2.0), (1.5, 2.0), (1.5, 4.5), (-1.5, 4.5)]
            .map(|(x, y)| glam::Vec3::new(x, y, 4.0))
            .to_vec(),
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    };
    let glass = engine::Material::unlit(engine::Rgba::new(0.2, 0.6, 0.9, 0.5))
        .blended(engine::BlendMode::Alpha)
        .double_sided(true);
    draws.push(Draw {
        mesh: &quad,
        material: &glass,
        transform: glam::Mat4::IDENTITY,
    });
    let camera = crate::showcase::camera(SKY_CENTRE, SKY_CENTRE + glam::Vec3::NEG_Z, W, H);
    let mut capturer = ibr::capture::Capturer::new();
    let lighting = &scene.lighting;
    let target = capturer.render(draws, &camera, lighting, W, H, Encoding::Srgb);
    let encoder = Encoder::new(Encoding::Srgb);
    let want: Vec<u8> = target
        .to_rgba8_premultiplied()
        .chunks_exact(4)
        .flat_map(|px| {
            let p = u32::from_le_bytes([px[0], px[1], px[2], px[3]]);
            if px[3] == 0 || px[3] == 255 {
                return p.to_le_bytes();
            }
            let s = engine::color::unpack(Encoding::Srgb, p).unpremultiply();
            encoder.pack(s.r, s.g, s.b, s.a).to_le_bytes()
        })
        .collect();
    assert!(target.to_rgba8() == want, "to_rgba8's bytes differ");
    let count = |keep: fn(u8) -> bool| want.chunks_exact(4).filter(|p| keep(p[3])).count();
    let (empty, opaque) = (count(|a| a == 0), count(|a| a == 255));
    let partly = count(|a| a != 0 && a != 255);
    eprintln!("{empty} empty, {partly} partly covered, {opaque} opaque pixels");
    assert!(empty > 0 && partly > 0 && opaque > 0);
    let mut out = vec![7u8; 5];
    target.write_rgba8(&mut out);
    assert!(out == want, "the bytes differ");
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a pool of one thread");
    let mut again = vec![0u8; want.len() + 8];
    one.install(|| target.write_rgba8(&mut again));
    assert!(again == want, "the bytes differ on one thread");
}
