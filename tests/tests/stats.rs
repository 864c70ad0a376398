//! Frame statistics count what the conventions say happened: culled back faces, clipped
//! triangles, and fragments tested / shaded / written, against the reference's coverage.

use engine::{
    AlphaMode, Camera, Cull, Encoding, FrameOptions, FrameStats, Material, Renderer, Rgba, Scene,
    Target,
};
use glam::{Mat4, Vec3};
use tests::reference::Raster;
use tests::scenes::{pixel_camera, px, render, soup};

const W: u32 = 80;
const H: u32 = 60;

fn stats_of(tris: &[[Vec3; 3]], mat: Material, cam: &Camera, cull: Cull) -> FrameStats {
    let mut scene = Scene::default();
    for t in tris {
        scene.add(soup(&[*t]), mat.clone(), Mat4::IDENTITY);
    }
    render(&scene, cam, W, H, Encoding::Unorm, cull).1
}

/// Pixels the reference says `t` covers.
fn coverage(t: [Vec3; 3]) -> u64 {
    Raster::new(&pixel_camera(W, H), W, H)
        .counts(&[t], false)
        .counts
        .iter()
        .map(|&c| c as u64)
        .sum()
}

/// Front (counter-clockwise in NDC) and back versions of one triangle under each culling
/// mode and sidedness.
fn check_culling(front: [Vec3; 3]) {
    let back = [front[0], front[2], front[1]];
    let cam = pixel_camera(W, H);
    let raster = Raster::new(&cam, W, H);
    assert!(raster.screen_tri(front).expect("on screen").is_front());
    let n = coverage(front);
    assert!(n > 0);
    for (tri, is_front) in [(front, true), (back, false)] {
        for double_sided in [false, true] {
            for cull in [Cull::PerMaterial, Cull::None, Cull::Back] {
                let s = stats_of(
                    &[tri],
                    Material::default().double_sided(double_sided),
                    &cam,
                    cull,
                );
                let culled = !is_front
                    && (cull == Cull::Back || (cull == Cull::PerMaterial && !double_sided));
                let what =
                    format!("front {is_front}, double-sided {double_sided}, {cull:?}: {s:?}");
                assert_eq!(s.triangles_culled, culled as u64, "{what}");
                assert_eq!(s.triangles_set_up, !culled as u64, "{what}");
                assert_eq!(s.fragments_tested, if culled { 0 } else { n }, "{what}");
                assert_eq!(s.fragments_written, if culled { 0 } else { n }, "{what}");
                assert_eq!(
                    (
                        s.draws,
                        s.triangles_in,
                        s.triangles_clipped,
                        s.triangles_rejected
                    ),
                    (1, 1, 0, 0),
                    "{what}"
                );
            }
        }
    }
}

#[test]
fn back_faces_are_culled_and_counted() {
    // Counter-clockwise on the screen as seen (y down: going right, then up-left).
    check_culling([px(5.0, 50.0), px(70.0, 45.0), px(30.0, 4.0)]);
    check_culling([px(60.5, 10.5), px(10.5, 10.5), px(40.25, 55.75)]);
}

#[test]
fn near_crossing_triangles_are_counted_as_clipped() {
    let cam = Camera::look_at(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y, 1.0, 1.0).with_aspect(W, H);
    let v = Vec3::new;
    let crossing = [v(-1.0, -1.0, 1.0), v(1.0, -1.0, -3.0), v(0.0, 1.0, -3.0)];
    let s = stats_of(
        &[crossing],
        Material::default().double_sided(true),
        &cam,
        Cull::None,
    );
    assert_eq!(
        (
            s.triangles_clipped,
            s.triangles_rejected,
            s.triangles_culled
        ),
        (1, 0, 0),
        "{s:?}"
    );
    assert!(s.triangles_set_up >= 1 && s.fragments_written > 0, "{s:?}");
    // Wholly inside: not clipped. Wholly behind: rejected, not clipped.
    let inside = [v(-1.0, -1.0, -3.0), v(1.0, -1.0, -3.0), v(0.0, 1.0, -3.0)];
    let behind = [v(-1.0, -1.0, 3.0), v(1.0, -1.0, 3.0), v(0.0, 1.0, 3.0)];
    let s = stats_of(
        &[inside, behind],
        Material::default().double_sided(true),
        &cam,
        Cull::None,
    );
    assert_eq!(
        (
            s.draws,
            s.triangles_in,
            s.triangles_clipped,
            s.triangles_rejected,
            s.triangles_set_up
        ),
        (2, 2, 0, 1, 1),
        "{s:?}"
    );
}

#[test]
fn fragments_tested_shaded_written_follow_depth_and_alpha_tests() {
    let cam = pixel_camera(W, H);
    // A near triangle drawn first, then a farther one overlapping it.
    let near = [px(5.0, 5.0), px(60.0, 8.0), px(10.0, 50.0)].map(|p| Vec3::new(p.x, p.y, -2.0));
    let far = [px(20.0, 10.0), px(75.0, 20.0), px(30.0, 58.0)].map(|p| Vec3::new(p.x, p.y, -5.0));
    let raster = Raster::new(&cam, W, H);
    let cn = raster.counts(&[near], false);
    let cf = raster.counts(&[far], false);
    let both = cn
        .counts
        .iter()
        .zip(&cf.counts)
        .filter(|(a, b)| **a > 0 && **b > 0)
        .count() as u64;
    let (n_near, n_far) = (coverage(near), coverage(far));
    assert!(both > 100, "the triangles should overlap");
    // Far first within one draw (the renderer keeps a draw's triangle order). In one
    // pass every covered pixel is tested, shaded and written.
    let mut one = Scene::default();
    let mat = Material::default().double_sided(true);
    one.add(soup(&[far, near]), mat, Mat4::IDENTITY);
    let s = render(&one, &cam, W, H, Encoding::Unorm, Cull::None).1;
    assert_eq!(
        (s.fragments_tested, s.fragments_shaded, s.fragments_written),
        (n_near + n_far, n_near + n_far, n_near + n_far),
        "{s:?}"
    );
    // With the visibility pre-pass only the seen pixels are shaded and written; the far
    // triangle's are tested (a block at a time may be rejected before the per-pixel count,
    // so `tested` is only bounded).
    let mut target = Target::new(W, H);
    let opts = FrameOptions {
        clear: Some(Rgba::BLACK),
        cull: Cull::None,
    };
    let mut prepass = Renderer::new();
    prepass.set_visibility_prepass(true);
    let s = prepass.render_scene(&one, &cam, &mut target, &opts);
    assert_eq!(s.fragments_shaded, n_near + n_far - both, "{s:?}");
    assert_eq!(s.fragments_written, s.fragments_shaded, "{s:?}");
    assert!(
        s.fragments_tested >= s.fragments_shaded && s.fragments_tested <= n_near + n_far,
        "{s:?}"
    );
    // Near first: the far triangle's hidden pixels fail the depth test. (They may be
    // rejected a block at a time before reaching the per-pixel count, so `tested` is only
    // bounded.)
    let s = stats_of(
        &[near, far],
        Material::default().double_sided(true),
        &cam,
        Cull::None,
    );
    assert_eq!(s.fragments_shaded, n_near + n_far - both, "{s:?}");
    assert_eq!(s.fragments_written, s.fragments_shaded, "{s:?}");
    assert!(
        s.fragments_tested >= s.fragments_shaded && s.fragments_tested <= n_near + n_far,
        "{s:?}"
    );
    // Far first as two draws: opaque draws are sorted near to far, so the same.
    let far_first = stats_of(
        &[far, near],
        Material::default().double_sided(true),
        &cam,
        Cull::None,
    );
    assert_eq!(far_first, s);
    // Alpha-tested away entirely: shaded but not written.
    let mat = Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..Material::unlit(Rgba::new(1.0, 1.0, 1.0, 0.25)).double_sided(true)
    };
    let s = stats_of(&[near], mat, &cam, Cull::None);
    assert_eq!(
        (s.fragments_tested, s.fragments_shaded, s.fragments_written),
        (n_near, n_near, 0),
        "{s:?}"
    );
}
