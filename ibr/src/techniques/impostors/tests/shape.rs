//! The shapes an image is drawn on ([`Shape`]) against their subject's geometry: depth,
//! occlusion of nearer geometry, and outlines.

use super::*;

/// A box of `size` centred at `at`, turned `yaw` about the vertical, lit in `color`.
pub(super) fn block(size: Vec3, at: Vec3, yaw: f32, color: Rgba) -> MeshGroup {
    MeshGroup::new().with(
        Arc::new(procedural::cuboid(size)),
        Arc::new(Material::lit(color)),
        Mat4::from_translation(at) * Mat4::from_rotation_y(yaw),
    )
}

/// The frame and the eye-space depth image of `draws` from `cam` (`f32::INFINITY` where
/// nothing was drawn).
fn frame(draws: Vec<Draw<'_>>, cam: &Camera, (w, h): (u32, u32)) -> (Target, Vec<f32>) {
    let mut t = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    Renderer::new().render(draws, cam, &lighting(), &mut t, &opts);
    let depth = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| match t.depth_reversed(x, y) {
            Some(d) if d > 0.0 => cam.view_depth_from_reversed(d),
            _ => f32::INFINITY,
        })
        .collect();
    (t, depth)
}

/// How many pixels of `image` are far from `truth`'s colour (a wrong surface, not
/// resampling).
fn wrong_pixels(image: &Target, truth: &Target) -> usize {
    let (w, h) = (image.width(), image.height());
    let far = |x: u32, y: u32| {
        let (p, q) = (image.pixel(x, y).unwrap(), truth.pixel(x, y).unwrap());
        let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
        (0..4).any(|k| p[k].abs_diff(q[k]) > 60)
    };
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| far(x, y))
        .count()
}

/// `subject` captured from `capture` as one impostor drawn on `shape` (alpha cut at 0.5),
/// then drawn from `cam` with `beside` as geometry: the frame and its depth image.
fn shape_frame(
    subject: &[MeshGroup],
    shape: Shape,
    capture: &Camera,
    cam: &Camera,
    beside: Option<&MeshGroup>,
    size: (u32, u32),
) -> (Target, Vec<f32>) {
    let mut subjects = subject.to_vec();
    let mut imps = set(1, 1);
    imps.shape = shape;
    imps.density = 2.0;
    imps.update(&mut subjects, capture, size.1, &lighting());
    let slot = imps.impostors[0].slot.expect("captured");
    imps.pool
        .set_alpha(slot, engine::AlphaMode::Mask { cutoff: 0.5 });
    let mut draws = Vec::new();
    imps.draws_near(&subjects, cam.eye(), &mut draws);
    assert_eq!(draws.len(), 1, "drawn as its image");
    if let Some(g) = beside {
        g.draws(&mut draws);
    }
    frame(draws, cam, size)
}

#[test]
fn reliefs_and_boxes_stand_at_their_subjects_depth_and_let_nearer_geometry_show() {
    // A box turned 45 degrees, one vertical edge toward the eye, and a pole in front of
    // its right face but behind that edge: a quad at the nearest edge would cover the
    // pole; the box's own geometry does not.
    let orange = Rgba::new(0.8, 0.5, 0.2, 1.0);
    let subject = [block(Vec3::new(2.0, 3.0, 2.0), Vec3::ZERO, 0.785, orange)];
    let blue = Rgba::new(0.1, 0.3, 0.9, 1.0);
    let pole = block(
        Vec3::new(0.25, 4.0, 0.25),
        Vec3::new(1.0, 0.0, 0.8),
        0.0,
        blue,
    );
    let size = (192, 144);
    let cam_at = |eye: Vec3| {
        Camera::look_at(eye, Vec3::new(0.3, 0.0, 0.0), Vec3::Y, 0.5, 4.0 / 3.0)
            .with_depth_range(0.1, 100.0)
    };
    let capture_eye = Vec3::new(0.0, 1.0, 12.0);
    // Seen a little to the side of the capture eye (about a degree of parallax).
    let cam = cam_at(capture_eye + Vec3::new(0.15, 0.05, 0.0));
    let mut truth_draws = Vec::new();
    subject[0].draws(&mut truth_draws);
    pole.draws(&mut truth_draws);
    let (truth, truth_depth) = frame(truth_draws, &cam, size);
    let mut shown = Vec::new();
    for shape in [Shape::Quad, Shape::Relief] {
        let capture = cam_at(capture_eye);
        let (image, depth) = shape_frame(&subject, shape, &capture, &cam, Some(&pole), size);
        // Mean depth error over the subject's pixels both draw (the pole's excluded: it is
        // geometry in both).
        let (mut sum, mut n) = (0.0f64, 0usize);
        for (i, (&a, &b)) in depth.iter().zip(&truth_depth).enumerate() {
            let (x, y) = (i as u32 % size.0, i as u32 / size.0);
            let pole_px = image.pixel(x, y) == truth.pixel(x, y) && a == b;
            if a.is_finite() && b.is_finite() && !pole_px {
                sum += (a - b).abs() as f64;
                n += 1;
            }
        }
        shown.push((wrong_pixels(&image, &truth), sum / n.max(1) as f64, n));
    }
    let [(wrong_flat, depth_flat, n), (wrong_relief, depth_relief, _)] = shown[..] else {
        unreachable!()
    };
    assert!(n > 2000, "{shown:?}");
    // The box's faces recede up to 1.4 units behind its nearest edge: the flat quad's mean
    // depth error is a good part of that, the relief's a few hundredths.
    assert!(depth_relief < 0.05 && depth_flat > 0.4, "{shown:?}");
    // The quad hides the pole where it stands in front of the face; the relief does not
    // (what differs is a pixel or so of outline).
    assert!(
        wrong_flat > 150 && wrong_relief * 4 < wrong_flat,
        "{shown:?}"
    );
}

/// A box subject (filling its box, as [`Shape::Box`] asks: not turned) drawn as its
/// geometry, as a [`Shape::Relief`] and as a [`Shape::Box`] (cutouts) from `eye`,
/// captured from `capture_eye`: the pixels it covers, and those far from its geometry's
/// colour in each.
fn box_against_relief(capture_eye: Vec3, eye: Vec3) -> (usize, usize, usize) {
    let color = Rgba::new(0.8, 0.5, 0.2, 1.0);
    let subject = [block(Vec3::new(2.0, 3.0, 1.5), Vec3::ZERO, 0.0, color)];
    let size = (192, 144);
    let cam_at = |eye: Vec3| {
        Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.5, 4.0 / 3.0).with_depth_range(0.1, 100.0)
    };
    let cam = cam_at(eye);
    let mut draws = Vec::new();
    subject[0].draws(&mut draws);
    let truth = frame(draws, &cam, size).0;
    let covered = wrong_pixels(&truth, &frame(Vec::new(), &cam, size).0);
    let mut wrong = [0; 2];
    for (k, shape) in [Shape::Relief, Shape::Box].into_iter().enumerate() {
        let capture = cam_at(capture_eye);
        let image = shape_frame(&subject, shape, &capture, &cam, None, size).0;
        wrong[k] = wrong_pixels(&image, &truth);
    }
    (covered, wrong[0], wrong[1])
}

#[test]
fn a_box_shows_its_subjects_outline_where_a_cutout_misses_pixels_along_it() {
    // From the capture eye and from eyes moved up to about two degrees round the subject,
    // the cutout's outline is the filtered coverage's, a fraction of a pixel off: some of
    // the outline's pixels are wrong. The box's outline is the geometry's own.
    let capture_eye = Vec3::new(5.0, 3.0, 8.5);
    let (mut relief, mut boxed) = (0, 0);
    for moved in [
        Vec3::ZERO,
        Vec3::new(0.2, 0.1, 0.0),
        Vec3::new(-0.3, -0.2, 0.3),
    ] {
        let (covered, r, b) = box_against_relief(capture_eye, capture_eye + moved);
        assert!(covered > 2000, "{covered}");
        assert!(b <= 3, "{moved} box {b} relief {r} of {covered}");
        (relief, boxed) = (relief + r, boxed + b);
    }
    assert!(
        relief >= 10 && boxed * 5 <= relief,
        "box {boxed} relief {relief}"
    );
}

/// Pixels of `image` more than 8 levels off `truth`'s colour in some channel.
fn off_pixels(image: &Target, truth: &Target) -> usize {
    let (w, h) = (image.width(), image.height());
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (p, q) = (image.pixel(x, y).unwrap(), truth.pixel(x, y).unwrap());
            let (p, q) = (p.to_le_bytes(), q.to_le_bytes());
            (0..4).any(|k| p[k].abs_diff(q[k]) > 8)
        })
        .count()
}

#[test]
fn a_box_face_the_capture_eye_saw_edge_on_is_taken_again_once_seen_at_an_angle() {
    // A box captured square-on to its front face, level with its centre: its sides and
    // top edge-on, no texel across them. The level tolerance is out of reach, so only the
    // faces' texels can invalidate the image.
    let color = Rgba::new(0.8, 0.5, 0.2, 1.0);
    let mut subjects = [block(Vec3::new(2.0, 3.0, 1.5), Vec3::ZERO, 0.0, color)];
    let size = (192, 144);
    let cam_at = |eye: Vec3| {
        Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.5, 4.0 / 3.0).with_depth_range(0.1, 100.0)
    };
    let mut imps = set(1, 1);
    imps.config.tolerance.levels = Some(f32::MAX);
    imps.config.fallback_ratio = f32::INFINITY;
    imps.shape = Shape::Box;
    imps.density = 2.0;
    let front = Vec3::new(0.0, 0.0, 10.0);
    imps.update(&mut subjects, &cam_at(front), size.1, &lighting());
    assert_eq!(imps.impostors[0].refreshes, 1);
    // Nearer along the same line: no face turns toward the eye; the image is kept.
    let nearer = cam_at(Vec3::new(0.0, 0.0, 9.0));
    let r = imps.update(&mut subjects, &nearer, size.1, &lighting());
    assert_eq!(r.refreshes, 0);
    // Twenty degrees round: the right face shows about 0.34 of its width (0.5 units, some
    // 14 pixels) where the image has no texel of it. Drawn stale, those pixels repeat the
    // front face's edge; the image is taken again, and then matches the geometry.
    let side = cam_at(Vec3::new(3.42, 0.0, 9.4));
    let mut truth_draws = Vec::new();
    subjects[0].draws(&mut truth_draws);
    let truth = frame(truth_draws, &side, size).0;
    // Drawn as a cutout, as the city draws its boxes.
    let drawn = |imps: &mut ImpostorSet, subjects: &[MeshGroup]| {
        let slot = imps.impostors[0].slot.expect("captured");
        imps.pool
            .set_alpha(slot, engine::AlphaMode::Mask { cutoff: 0.5 });
        let mut draws = Vec::new();
        imps.draws_near(subjects, side.eye(), &mut draws);
        assert_eq!(draws.len(), 1, "drawn as its image");
        frame(draws, &side, size).0
    };
    let stale = off_pixels(&drawn(&mut imps, &subjects), &truth);
    let r = imps.update(&mut subjects, &side, size.1, &lighting());
    assert_eq!(r.refreshes, 1, "the edge-on face invalidates the image");
    assert_eq!(imps.impostors[0].mode, Mode::Image);
    let fresh = off_pixels(&drawn(&mut imps, &subjects), &truth);
    assert!(
        stale >= 100 && fresh * 4 <= stale,
        "stale {stale} fresh {fresh}"
    );
}
