//! The lens flare is hidden by whatever is drawn in front of the light, not only by what
//! writes depth: an impostor hides it as the geometry it stands for does, and a cloud dims
//! it by its opacity, measured independently in a full-resolution render of the cloud alone.

use engine::{procedural, Camera, Draw, FrameOptions, Lighting, Material, Renderer};
use engine::{Rgba, Target};
use glam::{Mat4, Vec2, Vec3};
use ibr::cloud::Cloud;
use ibr::flare::{self, FlareSource, LensFlare};
use ibr::impostor::{Config, ImpostorSet, Mode};
use ibr::subject::{MeshGroup, Subject};
use std::sync::Arc;

const W: u32 = 320;
const H: u32 = 200;
const EYE: Vec3 = Vec3::new(0.0, 1.5, 16.0);

fn lighting() -> Lighting {
    tests::scenes::sun_lighting()
}

fn camera() -> Camera {
    Camera::look_at(
        EYE,
        Vec3::new(0.0, 4.0, 0.0),
        Vec3::Y,
        1.0,
        W as f32 / H as f32,
    )
    .with_depth_range(0.1, 200.0)
}

/// A 4 x 8 x 3 building standing on the origin.
fn building() -> MeshGroup {
    let mut mesh = procedural::cuboid(Vec3::new(4.0, 8.0, 3.0));
    mesh.colors.clear();
    MeshGroup::new().with(
        Arc::new(mesh),
        Arc::new(Material::lit(Rgba::new(0.6, 0.55, 0.5, 1.0))),
        Mat4::from_translation(Vec3::new(0.0, 4.0, 0.0)),
    )
}

/// The sun in the direction from the eye through `p`.
fn sun_through(p: Vec3) -> FlareSource {
    FlareSource::Directional((p - EYE).normalize())
}

/// Renders `draws` over a sky-coloured clear and measures the flare through them.
fn visibility<'a>(draws: impl Iterator<Item = Draw<'a>> + Clone, sun: FlareSource) -> f32 {
    let cam = camera();
    let mut renderer = Renderer::new();
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.4, 0.6, 0.9, 1.0)),
        ..Default::default()
    };
    renderer.render(draws.clone(), &cam, &lighting(), &mut target, &opts);
    let mut flare = LensFlare::default();
    flare.update_with_blended(&cam, &target, sun, f32::INFINITY, &lighting(), draws);
    flare.measured()
}

#[test]
fn the_sun_behind_an_impostor_is_hidden_as_behind_its_geometry() {
    let cam = camera();
    let mut subjects = [building()];
    let mut set = ImpostorSet::new(Config::default(), 1);
    set.update(&mut subjects, &cam, H, &lighting());
    assert_eq!(set.impostors[0].mode, Mode::Image, "drawn as an impostor");
    let mut impostor = Vec::new();
    set.draws(&subjects, &mut impostor);
    let mut geometry = Vec::new();
    subjects[0].draws(&mut geometry);

    // Behind the middle of the wall, on its silhouette (half hidden), above its roof and
    // beside it in the open sky.
    let cases = [
        (Vec3::new(0.0, 4.0, 1.5), 0.0..0.01),
        (Vec3::new(2.0, 5.0, 1.5), 0.2..0.8),
        (Vec3::new(-2.0, 7.0, 1.5), 0.2..0.8),
        (Vec3::new(0.5, 11.0, 1.5), 0.99..1.01),
        (Vec3::new(6.0, 4.0, 1.5), 0.99..1.01),
    ];
    for (p, expect) in cases {
        let sun = sun_through(p);
        let geo = visibility(geometry.iter().copied(), sun);
        let imp = visibility(impostor.iter().copied(), sun);
        assert!(expect.contains(&geo), "through {p}: geometry {geo}");
        assert!(
            (geo - imp).abs() <= 0.05,
            "through {p}: geometry {geo}, impostor {imp}"
        );
    }
    // The impostor writes depth where its image is more than half covered, so the depth
    // buffer alone now hides the sun too (before, it wrote none and never did).
    let depth_only = {
        let mut target = Target::new(W, H);
        Renderer::new().render(
            impostor.iter().copied(),
            &cam,
            &lighting(),
            &mut target,
            &FrameOptions::default(),
        );
        let mut f = LensFlare::default();
        f.update(&cam, &target, sun_through(Vec3::new(0.0, 4.0, 1.5)), 1.0);
        f.measured()
    };
    assert!(
        depth_only <= 0.01,
        "the depth buffer alone sees the impostor: {depth_only}"
    );
}

/// The light let through by `draws` around the sun's pixel: the same taps as the flare's, on
/// the alpha of a full-resolution render of `draws` alone over a transparent background.
fn reference_transmittance<'a>(draws: impl Iterator<Item = Draw<'a>>, sun: FlareSource) -> f32 {
    let cam = camera();
    let mut alone = Target::with_encoding(W, H, engine::Encoding::Unorm);
    let opts = FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    };
    Renderer::new().render(draws, &cam, &lighting(), &mut alone, &opts);
    let sky = Target::new(W, H); // depth 0: nothing opaque anywhere
    let light = flare::project(&cam, sun, W, H).expect("in view");
    let f = LensFlare::default();
    flare::occlusion_through(&sky, &light, f.samples, f.radius_px, |p: Vec2| {
        1.0 - alone
            .color_linear(p.x as u32, p.y as u32)
            .map_or(0.0, |c| c.a)
    })
}

#[test]
fn a_cloud_dims_the_sun_by_its_opacity_drawn_as_particles_or_as_an_impostor() {
    let cam = camera();
    let centre = Vec3::new(0.0, 6.0, -10.0);
    let mut seen = Vec::new();
    for (count, size) in [
        (6, Vec3::new(5.0, 2.0, 3.0)),
        (2000, Vec3::new(6.0, 3.0, 4.0)),
    ] {
        let mut clouds = [Cloud::cumulus(centre, size, count, 7)];
        clouds[0].relight(Vec3::new(-0.3, -1.0, -0.5).normalize(), Rgba::WHITE);
        clouds[0].prepare(&cam, H);
        let mut particles = Vec::new();
        clouds[0].draws(&mut particles);
        // The blobs sit on the cloud's flat base: their cores are below the box centre.
        let core = centre - Vec3::Y * 0.25 * size.y;
        let at_core = reference_transmittance(particles.iter().copied(), sun_through(core));
        for p in [core, core + Vec3::new(1.2, 0.8, 0.0)] {
            let sun = sun_through(p);
            let reference = reference_transmittance(particles.iter().copied(), sun);
            let v = visibility(particles.iter().copied(), sun);
            let tol = 0.1 * reference + 0.01;
            assert!(
                (v - reference).abs() <= tol,
                "{count} puffs: {v} vs {reference}"
            );
            seen.push(reference);
        }
        let mut set = ImpostorSet::new(Config::default(), 1);
        set.update(&mut clouds, &cam, H, &lighting());
        assert_eq!(set.impostors[0].mode, Mode::Image);
        let mut imp = Vec::new();
        set.draws(&clouds, &mut imp);
        let v = visibility(imp.iter().copied(), sun_through(core));
        assert!(
            (v - at_core).abs() <= 0.1,
            "{count} puffs as impostor: {v} vs {at_core}"
        );
    }
    // The thin cloud dims and the thick one hides: the cases differ.
    assert!(seen.iter().any(|&t| (0.15..0.85).contains(&t)), "{seen:?}");
    assert!(seen.iter().any(|&t| t < 0.05), "{seen:?}");
}
