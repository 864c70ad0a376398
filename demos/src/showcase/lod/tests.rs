//! Tests of the tour's levels of detail: patches that are the terrain's triangles, culled
//! outside the view with the same picture, coarse patches without cracks, and levels
//! picked by distance within the pixel error.

use super::*;
use crate::showcase::{camera, Showcase, SKY};
use engine::{FrameOptions, FrameStats, Renderer, Target};

/// Renders `scene`'s draws alone (no image-based layer) from `eye` toward `at`.
fn render(scene: &Scene, eye: Vec3, at: Vec3) -> (Vec<u8>, FrameStats) {
    let (w, h) = (192, 108);
    let cam = camera(eye, at, w, h);
    let mut target = Target::new(w, h);
    target.clear(SKY);
    let stats = Renderer::new().render(
        scene.draws(),
        &cam,
        &scene.lighting,
        &mut target,
        &FrameOptions::default(),
    );
    (target.to_rgba8(), stats)
}

/// Triangles of `mesh` as sorted position triples (bit patterns), for comparing sets.
fn triangles(mesh: &Mesh) -> Vec<[[u32; 3]; 3]> {
    let mut out: Vec<[[u32; 3]; 3]> = mesh
        .indices
        .chunks_exact(3)
        .map(|t| [0, 1, 2].map(|k| mesh.positions[t[k] as usize].to_array().map(f32::to_bits)))
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn full_patches_hold_the_terrains_triangles() {
    let show = Showcase::new();
    let whole = &show.scene.meshes[show.scene.instances[0].mesh];
    let patches = terrain_patches(whole, show.terrain.cells);
    assert_eq!(patches.len(), (PATCHES * PATCHES) as usize);
    let mut all = Mesh::default();
    for levels in &patches {
        let (m, err) = &levels[0];
        assert_eq!(*err, 0.0);
        let base = all.positions.len() as u32;
        all.positions.extend(&m.positions);
        all.indices.extend(m.indices.iter().map(|i| i + base));
    }
    assert_eq!(all.triangle_count(), whole.triangle_count());
    assert_eq!(triangles(&all), triangles(whole));
}

#[test]
fn coarse_patches_keep_their_border_and_cover_the_patch_once() {
    let show = Showcase::new();
    let whole = &show.scene.meshes[show.scene.instances[0].mesh];
    let side = show.terrain.cells / PATCHES;
    let cell = show.terrain.size / show.terrain.cells as f32;
    for levels in terrain_patches(whole, show.terrain.cells).iter().step_by(7) {
        let (full, _) = &levels[0];
        let (lo, hi) = full.bounding_box().unwrap();
        let on_border = |p: &Vec3| {
            [p.x - lo.x, hi.x - p.x, p.z - lo.z, hi.z - p.z]
                .iter()
                .any(|d| d.abs() < 1e-4)
        };
        let border = |m: &Mesh| {
            let mut v: Vec<[u32; 3]> = m
                .indices
                .iter()
                .map(|&i| m.positions[i as usize])
                .filter(on_border)
                .map(|p| p.to_array().map(f32::to_bits))
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        };
        assert_eq!(border(full).len(), 4 * side as usize);
        for (m, err) in &levels[1..] {
            assert!(m.triangle_count() < full.triangle_count() / 2);
            assert_eq!(border(m), border(full), "a crack: border vertices differ");
            assert!(err.is_finite() && *err >= 0.0 && *err < 3.0, "{err}");
            // Every triangle faces up, and their areas in plan add up to the patch's.
            let area: f32 = m
                .indices
                .chunks_exact(3)
                .map(|t| {
                    let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
                    let n = (b - a).cross(c - a);
                    assert!(n.y > 0.0, "a triangle faces down or stands on edge");
                    0.5 * n.y
                })
                .sum();
            let want = (side as f32 * cell).powi(2);
            assert!((area - want).abs() < 1e-3 * want, "{area} vs {want}");
        }
    }
}

#[test]
fn patches_outside_the_view_are_culled_and_the_picture_is_the_same() {
    let show = Showcase::new();
    let (eye, at) = (Vec3::new(20.0, 14.0, 20.0), Vec3::new(45.0, 4.0, 40.0));
    let (old, old_stats) = render(&show.scene, eye, at);
    let mut scene = show.scene.clone();
    let mut lod = show.lod.clone();
    lod.set_max_error_px(0.0);
    lod.apply(&mut scene, &camera(eye, at, 192, 108), 108);
    assert_eq!(lod.patch_count(), (PATCHES * PATCHES) as usize);
    assert!(lod.picked().iter().all(|&k| k == 0));
    let (new, new_stats) = render(&scene, eye, at);
    let patches = lod.patch_count() as u64;
    assert_eq!(new_stats.draws, old_stats.draws + patches - 1);
    assert!(
        new_stats.draws_culled >= old_stats.draws_culled + patches * 3 / 4,
        "{old_stats:?}\n{new_stats:?}"
    );
    assert!(new_stats.vertices_transformed < old_stats.vertices_transformed / 2);
    let differ = old.iter().zip(&new).filter(|(a, b)| a != b).count();
    assert_eq!(
        differ, 0,
        "bytes differ from the one-draw terrain's picture"
    );
}

#[test]
fn after_a_render_the_scene_is_the_one_draw_scene_again() {
    let mut show = Showcase::new();
    let before = show.scene.clone();
    let cam = camera(Vec3::new(60.0, 30.0, 0.0), Vec3::ZERO, 160, 90);
    let mut target = Target::new(160, 90);
    let opts = FrameOptions::default();
    show.render(&mut Renderer::new(), &cam, &mut target, &opts);
    assert!(show.lod.installed());
    assert!(
        show.lod.picked()[show.lod.patch_count()] > 0,
        "the far torus coarse"
    );
    assert_eq!(show.scene.instances, before.instances);
    assert_eq!(show.scene.lighting, before.lighting);
    let meshes = |s: &Scene| s.draws().map(|d| d.mesh.clone()).collect::<Vec<_>>();
    assert_eq!(meshes(&show.scene), meshes(&before));
}

#[test]
fn far_meshes_are_coarser_within_half_a_pixel() {
    let show = Showcase::new();
    let mut scene = show.scene.clone();
    let mut lod = show.lod.clone();
    let look = Vec3::new(0.0, 2.0, 0.0);
    let mut last = 0;
    for d in [4.0, 17.0, 60.0, 200.0] {
        let eye = Vec3::new(d, 3.0, 0.0);
        let cam = camera(eye, look, 640, 360);
        lod.apply(&mut scene, &cam, 360);
        let torus = lod.picked()[lod.patch_count()];
        assert!(torus >= last, "{d}: level {torus} after {last}");
        last = torus;
        let focal = 180.0 / (0.5 * crate::showcase::FOV_Y).tan();
        for (c, &k) in lod.chains.iter().zip(lod.picked()) {
            let inst = &scene.instances[c.instance];
            assert_eq!(inst.mesh, c.levels[k].0);
            let dist = distance_to_box(object_eye(inst.transform, eye), c.bounds);
            assert!(k == 0 || c.levels[k].1 * focal <= 0.5 * dist * 1.001);
        }
    }
    assert_eq!(lod.picked()[lod.patch_count()], last);
    assert!(last >= 4, "the torus 200 units away at level {last}");
    let near = camera(Vec3::new(3.0, 2.0, 0.0), look, 640, 360);
    lod.apply(&mut scene, &near, 360);
    assert!(lod.picked()[lod.patch_count()] <= 2);
}

#[test]
fn along_the_tour_far_patches_are_coarser() {
    let show = Showcase::new();
    let mut scene = show.scene.clone();
    let mut lod = show.lod.clone();
    let n = 120;
    let (mut levels, mut tris, mut torus) = ([0usize; 3], [0usize; 2], [0usize; 7]);
    for i in (0..n).step_by(10) {
        let (eye, at) = show.path(i, n);
        lod.apply(&mut scene, &camera(eye, at, 640, 360), 360);
        for (c, &k) in lod.chains[..lod.patch_count()].iter().zip(lod.picked()) {
            levels[k] += 1;
            tris[0] += scene.meshes[c.levels[0].0].triangle_count();
            tris[1] += scene.meshes[c.levels[k].0].triangle_count();
        }
        torus[lod.picked()[lod.patch_count()]] += 1;
    }
    eprintln!(
        "patches at each level along the tour: {levels:?}; triangles full {} picked {}",
        tris[0], tris[1]
    );
    assert!(levels[1] + levels[2] > 0, "{levels:?}");
    assert!(tris[1] < tris[0]);
}
