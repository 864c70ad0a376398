//! The view from inside a cloud is a fog through which the scene shows; from outside, the
//! cloud draws exactly as its plain billboards did.

use super::super::{Cloud, Subject, FACING};
use super::{coverage, fade_scale, near_fade, screen_share, MAX_FILL, NEAR_FADE};
use crate::core::{Billboard, View};
use engine::{Camera, Draw, FrameOptions, Lighting, Material, Mesh, Renderer, Rgba, Target};
use glam::{Mat4, Vec2, Vec3};

const SKY: Rgba = Rgba::new(0.42, 0.62, 0.86, 1.0);
const W: u32 = 96;
const H: u32 = 54;

/// A cloud the size of the showcase's (200 particles in 13 x 5 x 10), in its sun.
fn cloud() -> Cloud {
    let mut c = Cloud::cumulus(Vec3::ZERO, Vec3::new(13.0, 5.0, 10.0), 200, 5);
    c.relight(
        Vec3::new(-0.45, -0.75, -0.5),
        Rgba::new(1.05, 0.97, 0.86, 1.0),
    );
    c
}

/// An opaque red wall far behind the cloud, over about half of a view down +Z.
fn wall() -> Mesh {
    let mut m = Mesh::default();
    let (x0, x1, y0, y1, z) = (-200.0, 0.0, -120.0, 120.0, 60.0);
    m.positions = vec![
        Vec3::new(x0, y0, z),
        Vec3::new(x1, y0, z),
        Vec3::new(x1, y1, z),
        Vec3::new(x0, y1, z),
    ];
    m.indices = vec![0, 1, 2, 0, 2, 3];
    m
}

fn camera(eye: Vec3, look: Vec3) -> Camera {
    Camera::look_at(eye, look, Vec3::Y, 1.05, 1.0)
        .with_aspect(W, H)
        .with_depth_range(0.1, 250.0)
}

/// Renders the wall and `cloud_draws` over the sky; sRGB bytes.
fn render(cam: &Camera, cloud_draws: Vec<Draw<'_>>) -> Vec<u8> {
    let wall = wall();
    let red = Material::unlit(Rgba::new(0.8, 0.05, 0.05, 1.0)).double_sided(true);
    let mut draws = vec![Draw {
        mesh: &wall,
        material: &red,
        transform: Mat4::IDENTITY,
    }];
    draws.extend(cloud_draws);
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(SKY),
        ..FrameOptions::default()
    };
    Renderer::new().render(draws, cam, &Lighting::default(), &mut target, &opts);
    target.to_rgba8()
}

fn with_fade(cloud: &mut Cloud, cam: &Camera) -> Vec<u8> {
    cloud.prepare(cam, H);
    let mut draws = Vec::new();
    cloud.draws(&mut draws);
    render(cam, draws)
}

/// The cloud as it was drawn before the near fade: every particle's billboard at its full
/// opacity, no fog.
fn plain(cloud: &Cloud, cam: &Camera) -> Vec<u8> {
    render(cam, vec![plain_batch(cloud, cam).draw()])
}

fn plain_batch(cloud: &Cloud, cam: &Camera) -> crate::core::BillboardBatch {
    let view = View::new(cam, H);
    let mut batch = cloud.batch().clone();
    batch.clear();
    for (i, p) in cloud.particles().iter().enumerate() {
        let mut b = Billboard::new(p.position, FACING, Vec2::splat(2.0 * p.radius));
        b.rotation = (i % 256) as f32 * 2.399_963;
        b.tint = cloud.particle_color(i, (view.eye - p.position).normalize_or_zero());
        batch.push(b);
    }
    batch.build(&view);
    batch
}

/// Screens of fragments `draws` shade from `cam` (blended quads: every covered pixel).
fn fill(cam: &Camera, draws: Vec<Draw<'_>>) -> f32 {
    let mut target = Target::new(W, H);
    let stats = Renderer::new().render(
        draws,
        cam,
        &Lighting::default(),
        &mut target,
        &FrameOptions::default(),
    );
    stats.fragments_shaded as f32 / (W * H) as f32
}

#[test]
fn the_fade_scale_is_the_least_that_keeps_the_fill_within_the_budget() {
    // Within budget (the one inside its own radius never counts): the plain fade.
    assert_eq!(
        fade_scale(&mut [(0.5, 1.0), (2.0, 1.0), (4.0, 1.0)], 2.0),
        1.0
    );
    assert_eq!(fade_scale(&mut [], 2.0), 1.0);
    // 1 + 1 + 0.5 + 0.25 = 2.75 screens beyond one radius; dropping the two nearest (out
    // of order as given) leaves 0.75 <= 1, dropping one leaves 1.75.
    let mut near = [(6.0, 0.25), (1.5, 1.0), (4.0, 0.5), (2.0, 1.0)];
    assert_eq!(fade_scale(&mut near, 1.0), 2.0);
    assert_eq!(near[0], (1.5, 1.0), "sorted by distance");
    // Ties go together: both at 2 radii are dropped, never one of them.
    assert_eq!(
        fade_scale(&mut [(2.0, 1.0), (2.0, 1.0), (5.0, 0.1)], 1.5),
        2.0
    );
    // Nothing fits: everything is dropped.
    assert_eq!(fade_scale(&mut [(2.0, 1.0), (3.0, 1.0)], 0.0), 3.0);
    // The view's share: whole when the quad reaches the eye's plane, none behind it, and
    // a quarter of the height (and 1/4 / 2 of the width at aspect 2) at four times its
    // reach.
    assert_eq!(screen_share(1.0, 0.5, 1.0, 1.0), 1.0);
    assert_eq!(screen_share(1.0, -1.5, 1.0, 1.0), 0.0);
    assert!((screen_share(1.0, 4.0, 1.0, 2.0) - 0.25 * 0.125).abs() < 1e-7);
}

/// From the cloud's centre, its particles shade at most [`MAX_FILL`] screens of
/// fragments (the renderer's count; plus the fog's one screen and a tenth for the estimate's
/// error at the view's edges), where its plain billboards shade many times that; from
/// outside the fade is the plain one.
#[test]
fn inside_a_cloud_the_particles_fill_at_most_their_budget() {
    let mut c = cloud();
    let ps = c.particles();
    let centre = ps.iter().map(|p| p.position).sum::<Vec3>() / ps.len() as f32;
    for look in [Vec3::Z, Vec3::X, Vec3::NEG_Z] {
        let cam = camera(centre, centre + look);
        c.prepare(&cam, H);
        assert!(c.fade_scale() > 1.0, "{}", c.fade_scale());
        let mut draws = Vec::new();
        c.draws(&mut draws);
        let capped = fill(&cam, draws);
        let plain = fill(&cam, vec![plain_batch(&c, &cam).draw()]);
        assert!(capped <= MAX_FILL + 1.1, "{capped} screens, look {look}");
        assert!(plain > 4.0 * capped, "{plain} against {capped} screens");
    }
    let far = camera(Vec3::new(0.0, 2.0, 60.0), Vec3::ZERO);
    c.prepare(&far, H);
    assert_eq!(c.fade_scale(), 1.0);
}

fn luminance(px: &[u8]) -> f32 {
    (px[0] as f32 + px[1] as f32 + px[2] as f32) / 3.0
}

#[test]
fn fade_and_coverage_are_smooth_and_bounded() {
    assert_eq!(near_fade(0.0), 0.0);
    assert_eq!(near_fade(1.0), 0.0);
    assert_eq!(near_fade(NEAR_FADE), 1.0);
    assert_eq!(near_fade(f32::INFINITY), 1.0);
    assert_eq!(near_fade(f32::NAN), 1.0);
    assert_eq!(coverage(0.5), 1.0);
    assert_eq!(coverage(1.0), 1.0);
    assert!((coverage(2.0) - 0.25).abs() < 1e-6);
    let mut last = 0.0;
    for k in 0..=100 {
        let f = near_fade(k as f32 * 0.04);
        assert!(f >= last && (0.0..=1.0).contains(&f));
        last = f;
    }
}

/// From the cloud's centre of mass (15 particles contain it), looking toward the sun's
/// side (forward scattering: the brightest view) at a red wall far behind the cloud: the
/// frame is a fog, not a white wall, and the wall shows through it.
#[test]
fn inside_a_cloud_is_a_fog_the_scene_shows_through() {
    let mut c = cloud();
    let ps = c.particles();
    let centre = ps.iter().map(|p| p.position).sum::<Vec3>() / ps.len() as f32;
    let cam = camera(centre, centre + Vec3::Z);
    let clear = render(&cam, Vec::new());
    // The wall's pixels, from the scene without the cloud.
    let on_wall: Vec<bool> = clear.chunks(4).map(|p| p[0] > p[2]).collect();
    let walled = on_wall.iter().filter(|&&w| w).count();
    assert!(walled > 1000 && walled < 4000, "{walled} wall pixels");
    let stats = |img: &[u8]| {
        let l: Vec<f32> = img.chunks(4).map(luminance).collect();
        let mean = l.iter().sum::<f32>() / l.len() as f32;
        let white = l.iter().filter(|&&v| v >= 250.0).count() as f32 / l.len() as f32;
        let spread = (l.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / l.len() as f32).sqrt();
        // Redness (red minus blue) on the wall against the sky.
        let (mut s, mut n) = ([0.0f32; 2], [0usize; 2]);
        for (px, &w) in img.chunks(4).zip(&on_wall) {
            s[w as usize] += px[0] as f32 - px[2] as f32;
            n[w as usize] += 1;
        }
        (mean, spread, white, s[1] / n[1] as f32 - s[0] / n[0] as f32)
    };
    let (old_mean, old_spread, old_white, old_red) = stats(&plain(&c, &cam));
    let (mean, spread, white, red) = stats(&with_fade(&mut c, &cam));
    let (clear_mean, _, _, clear_red) = stats(&clear);
    println!("without the cloud: mean {clear_mean:.1}, wall {clear_red:.1}");
    println!(
        "plain billboards: mean {old_mean:.1}, spread {old_spread:.1}, white {old_white:.3}, \
         wall {old_red:.1}"
    );
    println!("faded with fog: mean {mean:.1}, spread {spread:.1}, white {white:.3}, wall {red:.1}");
    // Measured: plain billboards mean 247.3, 60% of pixels at 250 or more, the wall's
    // redness 9.7 over the sky's (234 without the cloud); faded with fog 231.9, 4%, 36.5.
    assert!(white < 0.1, "saturated white pixels: {white}");
    assert!(mean < 240.0, "mean luminance {mean}");
    assert!(spread > 5.0, "colour varies over the fog: spread {spread}");
    assert!(red > 20.0, "the red wall shows through the fog: {red}");
    // Still inside a cloud: brighter than the scene without it, the wall veiled.
    assert!(mean > clear_mean + 20.0 && red < 0.8 * clear_red);
}

/// From outside, beyond [`NEAR_FADE`] radii of every particle, the cloud draws exactly as
/// its plain billboards; closer in, still within a couple of grey levels on average.
#[test]
fn outside_a_cloud_looks_as_before() {
    let mut c = cloud();
    let b = c.bounds();
    for (dist, yaw) in [
        (2.2, 0.0f32),
        (1.5, 2.0),
        (1.5, 4.0),
        (1.1, 1.0),
        (1.02, 5.0),
    ] {
        let eye = b.center + Vec3::new(yaw.sin(), 0.2, yaw.cos()) * b.radius * dist;
        let cam = camera(eye, b.center);
        let old = plain(&c, &cam);
        let new = with_fade(&mut c, &cam);
        let diffs: Vec<f32> = old
            .iter()
            .zip(&new)
            .map(|(a, b)| (*a as f32 - *b as f32).abs())
            .collect();
        let mean = diffs.iter().sum::<f32>() / diffs.len() as f32;
        let max = diffs.iter().copied().fold(0.0, f32::max);
        println!("{dist} radii: mean diff {mean:.3}, max {max}");
        let far = c
            .particles()
            .iter()
            .all(|p| p.position.distance(eye) >= NEAR_FADE * p.radius);
        if far {
            assert_eq!(old, new, "{dist} radii out");
        } else {
            assert!(mean < 2.0, "{dist} radii out: mean difference {mean}");
        }
    }
}
