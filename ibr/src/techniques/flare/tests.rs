use super::*;
use engine::{FrameOptions, Lighting, Renderer};

const W: u32 = 96;
const H: u32 = 64;
const EYE: Vec3 = Vec3::new(0.0, 0.0, 5.0);
/// In view, up and to the right of the centre, 15 units from the eye.
const LIGHT: Vec3 = Vec3::new(6.0, 3.0, -10.0);

fn camera() -> Camera {
    Camera::look_at(EYE, Vec3::ZERO, Vec3::Y, 1.0, W as f32 / H as f32).with_depth_range(0.1, 100.0)
}

/// An opaque wall in the plane `z`, spanning `x` in `[-50, x_max]` and `y` in `[-50, 50]`.
fn wall(x_max: f32, z: f32) -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-50.0, -50.0, z),
            Vec3::new(x_max, -50.0, z),
            Vec3::new(x_max, 50.0, z),
            Vec3::new(-50.0, 50.0, z),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Default::default()
    }
}

/// The opaque pass: `meshes` in grey over a black clear.
fn scene(meshes: &[Mesh], camera: &Camera, w: u32, h: u32) -> Target {
    let material = Material::unlit(Rgba::new(0.2, 0.2, 0.2, 1.0)).double_sided(true);
    let draws = meshes.iter().map(|mesh| Draw {
        mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    });
    let mut target = Target::new(w, h);
    Renderer::new().render(
        draws,
        camera,
        &Lighting::default(),
        &mut target,
        &FrameOptions::default(),
    );
    target
}

/// `target` with the flare drawn over it (no clear).
fn composite(target: &Target, flare: &LensFlare, camera: &Camera) -> Target {
    let mut out = target.clone();
    Renderer::new().render(
        [flare.draw()],
        camera,
        &Lighting::default(),
        &mut out,
        &FrameOptions {
            clear: None,
            ..Default::default()
        },
    );
    out
}

fn luminance(t: &Target, p: Vec2) -> f32 {
    let c = t.color_linear(p.x as u32, p.y as u32).expect("on screen");
    c.r + c.g + c.b
}

fn along(light: Vec2, t: f32) -> Vec2 {
    light + (Vec2::new(W as f32, H as f32) * 0.5 - light) * t
}

fn assert_sane(flare: &LensFlare) {
    let s = flare.state;
    assert!((0.0..=1.0).contains(&s.measured), "{s:?}");
    assert!((0.0..=1.0).contains(&s.displayed), "{s:?}");
    assert!(flare.mesh().positions.iter().all(|p| p.is_finite()));
    assert!(flare.mesh().colors.iter().all(|c| c.a.is_finite()));
}

#[test]
fn unoccluded_light_is_fully_visible_and_brightens_the_line() {
    let cam = camera();
    let target = scene(&[], &cam, W, H);
    let mut flare = LensFlare::default();
    let vis = flare.update(&cam, &target, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.measured(), 1.0);
    assert_eq!(vis, 1.0);
    assert_eq!(flare.quad_count(), flare.elements.len());
    assert_sane(&flare);

    // Every quad lands centred on its intended pixel when drawn with the same camera.
    let light = flare.state.light.expect("projected").pixel;
    for (i, e) in flare.elements.iter().enumerate() {
        let q = &flare.mesh().positions[i * 4..i * 4 + 4];
        let mid = q.iter().sum::<Vec3>() / 4.0;
        let clip = cam.clip_from_world() * mid.extend(1.0);
        let px = Vec2::new(
            (clip.x / clip.w * 0.5 + 0.5) * W as f32,
            (0.5 - clip.y / clip.w * 0.5) * H as f32,
        );
        assert!(px.distance(along(light, e.position)) < 0.01, "{i}: {px}");
        let side = q[0].distance(q[1]) / q[1].distance(q[2]);
        assert!((side - 1.0).abs() < 1e-3, "square sprites");
    }

    let lit = composite(&target, &flare, &cam);
    for t in [0.0, 0.45, 0.7, 1.25, 1.8] {
        let p = along(light, t);
        assert!(
            luminance(&lit, p) > luminance(&target, p) + 0.01,
            "position {t} at {p} not brighter"
        );
    }
}

#[test]
fn light_behind_an_occluder_shows_nothing() {
    let cam = camera();
    let target = scene(&[wall(50.0, 0.0)], &cam, W, H);
    let mut flare = LensFlare::default();
    flare.update(&cam, &target, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.measured(), 0.0);
    assert_eq!(flare.visibility(), 0.0);
    assert_eq!(flare.quad_count(), 0);
    assert_eq!(composite(&target, &flare, &cam), target);
}

#[test]
fn light_behind_its_own_far_wall_is_visible() {
    // A wall behind the light (farther from the eye) must not hide it.
    let cam = camera();
    let target = scene(&[wall(50.0, -20.0)], &cam, W, H);
    let mut flare = LensFlare::default();
    flare.update(&cam, &target, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.measured(), 1.0);
}

#[test]
fn half_hidden_light_measures_about_half_and_the_fade_converges() {
    let cam = camera();
    // The wall's edge x = 2 at z = 0 lies on the line from the eye to the light.
    let target = scene(&[wall(2.0, 0.0)], &cam, W, H);
    let mut flare = LensFlare::default();
    flare.update(&cam, &target, FlareSource::Point(LIGHT), 0.0);
    let m = flare.measured();
    assert!((0.35..=0.65).contains(&m), "measured {m}");
    assert_eq!(flare.visibility(), 0.0, "dt = 0 leaves the fade");
    let mut last = 0.0;
    for _ in 0..20 {
        let v = flare.update(&cam, &target, FlareSource::Point(LIGHT), 1.0 / 60.0);
        assert!(v >= last && v <= m);
        last = v;
    }
    assert_eq!(flare.visibility(), m);
    assert!(flare.quad_count() > 0);
    assert_sane(&flare);
}

#[test]
fn light_behind_the_camera_is_absent() {
    let cam = camera();
    let target = scene(&[], &cam, W, H);
    let mut flare = LensFlare::default();
    flare.update(&cam, &target, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.visibility(), 1.0);
    for p in [Vec3::new(0.0, 0.0, 10.0), Vec3::new(6.0, 3.0, 20.0)] {
        flare.update(&cam, &target, FlareSource::Point(p), 1.0 / 60.0);
        assert!(flare.state.light.is_none());
        assert_eq!(flare.visibility(), 0.0);
        assert_eq!(flare.measured(), 0.0);
        assert_eq!(flare.quad_count(), 0);
        assert_sane(&flare);
    }
    // Beyond the far plane.
    let far = EYE + (LIGHT - EYE) * 10.0;
    flare.update(&cam, &target, FlareSource::Point(far), f32::INFINITY);
    assert_eq!(flare.quad_count(), 0);
}

#[test]
fn off_screen_light_is_hidden_and_an_edge_light_is_half_visible() {
    let cam = camera();
    let target = scene(&[], &cam, W, H);
    let mut flare = LensFlare::default();
    flare.update(
        &cam,
        &target,
        FlareSource::Point(Vec3::new(40.0, 0.0, -10.0)),
        f32::INFINITY,
    );
    assert!(flare.state.light.expect("projected").pixel.x > W as f32);
    assert_eq!(flare.measured(), 0.0);
    assert_eq!(flare.quad_count(), 0);
    assert_sane(&flare);

    // Exactly on the right edge of the image: x = tan(fov / 2) * aspect * distance.
    let x = (0.5f32).tan() * 1.5 * 15.0;
    flare.update(
        &cam,
        &target,
        FlareSource::Point(Vec3::new(x, 0.0, -10.0)),
        f32::INFINITY,
    );
    let px = flare.state.light.expect("projected").pixel;
    assert!((px.x - W as f32).abs() < 0.01, "{px}");
    let m = flare.measured();
    assert!((0.35..=0.65).contains(&m), "measured {m}");
    // Elements are still placed along the line, partly off screen.
    assert_eq!(flare.quad_count(), flare.elements.len());
    assert_sane(&flare);
    let lit = composite(&target, &flare, &cam);
    let p = along(px, 1.25);
    assert!(luminance(&lit, p) > luminance(&target, p));
}

#[test]
fn temporal_fade_is_gradual_snaps_on_large_dt_and_stays_in_range() {
    let cam = camera();
    let open = scene(&[], &cam, W, H);
    let closed = scene(&[wall(50.0, 0.0)], &cam, W, H);
    let src = FlareSource::Point(LIGHT);
    let mut flare = LensFlare {
        fade_per_second: 4.0,
        ..LensFlare::default()
    };
    assert_eq!(flare.update(&cam, &open, src, 0.0), 0.0);
    assert_eq!(flare.measured(), 1.0);
    let v1 = flare.update(&cam, &open, src, 0.05);
    assert!((v1 - 0.2).abs() < 1e-6, "{v1}");
    let v2 = flare.update(&cam, &open, src, 0.05);
    assert!((v2 - 0.4).abs() < 1e-6, "{v2}");
    assert_eq!(flare.update(&cam, &open, src, 1e9), 1.0);
    let v3 = flare.update(&cam, &closed, src, 0.05);
    assert!((v3 - 0.8).abs() < 1e-6, "{v3}");
    // The dimmed sprites carry the displayed visibility in their alpha.
    let e = flare.elements[0];
    assert!((flare.mesh().colors[0].a - e.tint.a * v3).abs() < 1e-6);
    assert_eq!(flare.update(&cam, &closed, src, f32::NAN), v3);
    assert_eq!(flare.update(&cam, &closed, src, -1.0), v3);
    assert_eq!(flare.update(&cam, &closed, src, f32::INFINITY), 0.0);
    assert_eq!(flare.quad_count(), 0);

    for (d, t, rate, dt) in [
        (0.5, 1.0, 4.0, 0.1),
        (0.5, 0.0, 4.0, 0.1),
        (2.0, 5.0, 4.0, 0.1),
        (f32::NAN, 1.0, 4.0, 0.1),
        (0.5, f32::NAN, 4.0, 10.0),
        (0.5, 1.0, f32::NAN, 0.1),
        (0.5, 1.0, 0.0, 0.1),
        (0.5, 1.0, f32::INFINITY, 0.0),
    ] {
        let v = approach(d, t, rate, dt);
        assert!((0.0..=1.0).contains(&v), "{d} {t} {rate} {dt} -> {v}");
    }
    assert!((approach(0.5, 1.0, 4.0, 0.1) - 0.9).abs() < 1e-6);
    assert!((approach(0.5, 0.0, 4.0, 0.1) - 0.1).abs() < 1e-6);
    assert_eq!(approach(0.5, 1.0, 0.0, 0.1), 1.0, "no fade rate snaps");
}

#[test]
fn directional_sun_over_a_cleared_sky_and_behind_a_wall() {
    let cam = camera();
    let sun = FlareSource::Directional(Vec3::new(0.3, 0.2, -1.0));
    let sky = scene(&[], &cam, W, H);
    let mut flare = LensFlare::default();
    flare.update(&cam, &sky, sun, f32::INFINITY);
    assert_eq!(flare.measured(), 1.0);
    assert_eq!(flare.quad_count(), flare.elements.len());
    let px = flare.state.light.expect("projected").pixel;
    let lit = composite(&sky, &flare, &cam);
    assert!(luminance(&lit, px) > luminance(&sky, px) + 0.1);

    // Anything drawn there, however far, hides the sun.
    let walled = scene(&[wall(50.0, -90.0)], &cam, W, H);
    flare.update(&cam, &walled, sun, f32::INFINITY);
    assert_eq!(flare.measured(), 0.0);
    assert_eq!(flare.quad_count(), 0);

    // Behind the camera.
    flare.update(&cam, &sky, FlareSource::Directional(Vec3::Z), f32::INFINITY);
    assert!(flare.state.light.is_none());
    assert_eq!(flare.quad_count(), 0);
}

#[test]
fn odd_inputs_do_not_panic_and_draw_nothing() {
    let cam = camera();
    let target = scene(&[], &cam, W, H);
    let empty = Target::new(0, 0);
    let mut flare = LensFlare::default();
    let nan = Vec3::splat(f32::NAN);
    for src in [
        FlareSource::Point(nan),
        FlareSource::Point(Vec3::splat(f32::INFINITY)),
        FlareSource::Point(EYE),
        FlareSource::Directional(nan),
        FlareSource::Directional(Vec3::ZERO),
    ] {
        let v = flare.update(&cam, &target, src, f32::INFINITY);
        assert_eq!(v, 0.0, "{src:?}");
        assert_eq!(flare.quad_count(), 0, "{src:?}");
        assert_sane(&flare);
    }
    flare.update(&cam, &empty, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.visibility(), 0.0);
    assert_eq!(flare.quad_count(), 0);
    let nan_cam = Camera {
        view: Mat4::from_cols_array(&[f32::NAN; 16]),
        ..cam
    };
    flare.update(&nan_cam, &target, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.quad_count(), 0);

    // Odd settings and elements: no panic, only finite quads.
    flare.samples = 0;
    flare.radius_px = f32::NAN;
    flare.elements.push(FlareElement::new(
        f32::NAN,
        0.1,
        Rgba::WHITE,
        FlareShape::Ghost,
    ));
    flare.elements.push(FlareElement::new(
        0.5,
        f32::INFINITY,
        Rgba::WHITE,
        FlareShape::Ring,
    ));
    flare
        .elements
        .push(FlareElement::new(0.5, 0.0, Rgba::WHITE, FlareShape::Ring));
    flare.update(&cam, &target, FlareSource::Point(LIGHT), f32::INFINITY);
    assert_eq!(flare.measured(), 1.0);
    assert_eq!(flare.quad_count(), flare.elements.len() - 3);
    assert_sane(&flare);
    let _ = composite(&target, &flare, &cam);
}

#[test]
fn atlas_cells_have_transparent_gutters_and_distinct_shapes() {
    let cell = CELL_PX;
    let tex = atlas(cell);
    assert_eq!(
        (tex.width(), tex.height()),
        (cell * ATLAS_COLS, cell * ATLAS_ROWS)
    );
    let level = &tex.levels()[0];
    let alpha = |x: u32, y: u32| level.texels[(y * level.width + x) as usize] >> 24;
    for shape in FlareShape::ALL {
        let (cx, cy) = (
            (shape.index() % ATLAS_COLS) * cell,
            (shape.index() / ATLAS_COLS) * cell,
        );
        let mut sum = 0u32;
        for y in 0..cell {
            for x in 0..cell {
                let a = alpha(cx + x, cy + y);
                let border = x < GUTTER || y < GUTTER || x >= cell - GUTTER || y >= cell - GUTTER;
                assert!(!border || a == 0, "{shape:?} gutter texel {x},{y} = {a}");
                sum += a;
            }
        }
        assert!(sum > 255 * 20, "{shape:?} is nearly empty");
        let r = region(shape, cell);
        let c = UvRect::cell(ATLAS_COLS, ATLAS_ROWS, shape.index());
        assert!(r.min.cmpgt(c.min).all() && r.max.cmplt(c.max).all());
    }
    // The glow is bright in the middle, the rings are dark there.
    let mid = |s: FlareShape| s.alpha(Vec2::ZERO);
    assert!(mid(FlareShape::Glow) > 0.9 && mid(FlareShape::Starburst) > 0.9);
    assert!(mid(FlareShape::Ring) < 0.01 && mid(FlareShape::Halo) < 0.01);
    for s in FlareShape::ALL {
        assert_eq!(s.alpha(Vec2::new(1.0, 0.0)), 0.0);
        assert_eq!(s.alpha(Vec2::new(0.8, 0.8)), 0.0);
    }
}

/// A blended sheet in the plane `z` covering the whole view, of opacity `alpha`.
fn sheet(z: f32) -> Mesh {
    wall(50.0, z)
}

fn sheet_material(alpha: f32, blend: BlendMode) -> Material {
    Material::unlit(Rgba::new(0.9, 0.9, 0.9, alpha))
        .blended(blend)
        .double_sided(true)
}

/// Updates `flare` for `source` with `sheets` (mesh, material) drawn blended over the
/// opaque `meshes`, as a frame would.
fn update_blended(
    flare: &mut LensFlare,
    meshes: &[Mesh],
    sheets: &[(Mesh, Material)],
    source: FlareSource,
) -> f32 {
    let cam = camera();
    let target = scene(meshes, &cam, W, H);
    let draws = sheets.iter().map(|(mesh, material)| Draw {
        mesh,
        material,
        transform: Mat4::IDENTITY,
    });
    let lighting = Lighting::default();
    flare.update_with_blended(&cam, &target, source, f32::INFINITY, &lighting, draws);
    assert_sane(flare);
    flare.measured()
}

#[test]
fn blended_sheets_dim_the_light_by_their_opacity() {
    let sun = FlareSource::Directional(Vec3::new(0.3, 0.2, -1.0));
    let mut flare = LensFlare::default();
    for alpha in [0.0, 0.25, 0.5, 0.8, 1.0] {
        let sheets = [(sheet(-20.0), sheet_material(alpha, BlendMode::Alpha))];
        let v = update_blended(&mut flare, &[], &sheets, sun);
        // Opacity is quantised to 8 bits in the probe.
        assert!((v - (1.0 - alpha)).abs() < 0.01, "alpha {alpha}: {v}");
    }
    // Two sheets stack: transmittance multiplies.
    let sheets = [
        (sheet(-20.0), sheet_material(0.3, BlendMode::Alpha)),
        (sheet(-30.0), sheet_material(0.6, BlendMode::Alpha)),
    ];
    let v = update_blended(&mut flare, &[], &sheets, sun);
    assert!((v - 0.7 * 0.4).abs() < 0.01, "{v}");
    // Additive sheets emit light and hide nothing.
    let sheets = [(sheet(-20.0), sheet_material(0.9, BlendMode::Additive))];
    assert_eq!(update_blended(&mut flare, &[], &sheets, sun), 1.0);
    // An opaque wall still hides it, with or without sheets.
    let sheets = [(sheet(-20.0), sheet_material(0.5, BlendMode::Alpha))];
    assert_eq!(
        update_blended(&mut flare, &[wall(50.0, -90.0)], &sheets, sun),
        0.0
    );
}

#[test]
fn only_sheets_in_front_of_a_point_light_dim_it() {
    let light = FlareSource::Point(LIGHT);
    let mut flare = LensFlare::default();
    let behind = [(sheet(-15.0), sheet_material(0.7, BlendMode::Alpha))];
    assert_eq!(update_blended(&mut flare, &[], &behind, light), 1.0);
    let front = [(sheet(-5.0), sheet_material(0.7, BlendMode::Alpha))];
    let v = update_blended(&mut flare, &[], &front, light);
    assert!((v - 0.3).abs() < 0.01, "{v}");
}

#[test]
fn a_half_covering_sheet_dims_half_the_taps() {
    // A wall in z = -5 ending where the eye's ray to the light crosses it (x = 4): about half
    // the disc is behind it.
    let cam = camera();
    let sun = FlareSource::Point(LIGHT);
    let light = project(&cam, sun, W, H).expect("in view");
    let mut flare = LensFlare::default();
    let opaque = update_blended(&mut flare, &[wall(LIGHT.x * 2.0 / 3.0, -5.0)], &[], sun);
    let sheets = [(
        wall(LIGHT.x * 2.0 / 3.0, -5.0),
        sheet_material(1.0, BlendMode::Alpha),
    )];
    let blended = update_blended(&mut flare, &[], &sheets, sun);
    assert!(
        (0.3..0.7).contains(&opaque),
        "{opaque} at {:?}",
        light.pixel
    );
    assert!((opaque - blended).abs() < 0.05, "{opaque} vs {blended}");
}

/// Mean sRGB byte of a pixel's three channels, as a viewer sees it.
fn encoded_level(t: &Target, p: Vec2) -> f32 {
    let px = t.to_rgba8();
    let i = (p.y as usize * t.width() as usize + p.x as usize) * 4;
    (px[i] as f32 + px[i + 1] as f32 + px[i + 2] as f32) / 3.0
}

#[test]
fn the_sun_preset_stands_out_over_a_pale_sky() {
    // Over the showcase's pale blue sky the additive sprites near saturation; every ghost
    // must still be plain to see at full visibility: at least 25 of 255 levels brighter at
    // its centre than the sky, and the glow at the light at least 40.
    let cam = camera();
    let mut sky = Target::new(W, H);
    Renderer::new().render(
        std::iter::empty(),
        &cam,
        &Lighting::default(),
        &mut sky,
        &FrameOptions {
            clear: Some(Rgba::new(0.42, 0.62, 0.86, 1.0)),
            ..Default::default()
        },
    );
    let mut flare = LensFlare::default();
    flare.update(&cam, &sky, FlareSource::Point(LIGHT), f32::INFINITY);
    let lit = composite(&sky, &flare, &cam);
    let light = flare.state.light.expect("projected").pixel;
    let rise = |t: f32| encoded_level(&lit, along(light, t)) - encoded_level(&sky, along(light, t));
    assert!(rise(0.0) >= 40.0, "glow {}", rise(0.0));
    for e in flare
        .elements
        .iter()
        .filter(|e| e.shape == FlareShape::Ghost)
    {
        assert!(
            rise(e.position) >= 25.0,
            "ghost at {}: {}",
            e.position,
            rise(e.position)
        );
    }
}
