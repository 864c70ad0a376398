//! Levels of detail of the objects the cut draws as geometry: the coarse mesh far, the
//! full one near, chosen from the projected deviation alone (the same frames at any number
//! of threads).

use super::*;
use crate::core::{MeshGroup, Part, Representation};
use crate::plan::tests::{lighting, render, H, W};
use engine::{procedural, Camera, Material, Mesh, Renderer};
use glam::{Mat4, Vec3};
use std::sync::Arc;

/// The coarse torus's declared deviation from the full one, object units.
const DEVIATION: f32 = 0.1;

/// Statues at `z` (one each), a full 3000-triangle torus with a 200-triangle level of
/// detail, and the planner over them with no image representation (all geometry).
fn statues(zs: &[f32]) -> (Hierarchy<MeshGroup>, Arc<Mesh>, Arc<Mesh>) {
    let (objects, full, coarse) = statue_objects(zs);
    let h = Hierarchy::new(TreeConfig::default(), objects, |_| {
        Vec::<Box<dyn Representation<Cluster<MeshGroup>>>>::new()
    });
    (h, full, coarse)
}

/// The statues of [`statues`], and their full and coarse meshes.
fn statue_objects(zs: &[f32]) -> (Vec<MeshGroup>, Arc<Mesh>, Arc<Mesh>) {
    let full = Arc::new(procedural::torus_with_triangles(3000));
    let coarse = Arc::new(procedural::torus_with_triangles(200));
    let material = Arc::new(Material::default());
    let objects = zs
        .iter()
        .map(|&z| {
            let place = Mat4::from_translation(Vec3::new(0.0, 0.0, z));
            let part = Part::new(full.clone(), material.clone(), place)
                .with_lods(vec![(coarse.clone(), DEVIATION)]);
            MeshGroup {
                parts: vec![part],
                version: 0,
            }
        })
        .collect();
    (objects, full, coarse)
}

fn eye_camera() -> Camera {
    Camera::look_at(
        Vec3::new(0.0, 0.0, 6.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::Y,
        1.0,
        1.0,
    )
    .with_depth_range(0.1, 1000.0)
    .with_aspect(W, H)
}

#[test]
fn a_far_object_draws_the_coarse_mesh_and_a_near_one_the_full() {
    // Near: 5 units from the eye (minus the torus's radius, about 1.3), the deviation is
    // 0.1 * ppr / 3.7 pixels; far: 0.1 * ppr / 199. With the 1-radian view H = 192 pixels
    // tall, ppr = 96 / tan(0.5) = 175.9: 4.75 pixels near (over 0.5, full), 0.088 far
    // (within, coarse).
    let ppr = (H as f32 * 0.5) / 0.5f32.tan();
    let (near, far) = (DEVIATION * ppr / 3.7, DEVIATION * ppr / 199.0);
    assert!(near > 0.5 && far < 0.5, "{near} {far}");
    let (mut h, full, coarse) = statues(&[1.0, -194.0]);
    let cam = eye_camera();
    let lights = lighting();
    h.plan(&FrameView::still(&cam, W, H, &lights));
    assert_eq!(h.geometry().len(), 2);
    let mut draws = Vec::new();
    h.draws(&mut draws);
    let by_z = |z: f32| {
        let d = draws
            .iter()
            .find(|d| (d.transform.w_axis.z - z).abs() < 1e-3);
        std::ptr::from_ref(d.expect("drawn").mesh)
    };
    assert_eq!(by_z(1.0), std::ptr::from_ref(&*full));
    assert_eq!(by_z(-194.0), std::ptr::from_ref(&*coarse));
    assert_eq!(h.report.geometry_triangles, 3000 + 200);
    // The reference draws stay full; with no tolerance the frame draws full meshes too.
    let mut all = Vec::new();
    Technique::reference(&h, &mut all);
    assert!(all.iter().all(|d| std::ptr::eq(d.mesh, &*full)));
    h.config.lod_px = 0.0;
    h.plan(&FrameView::still(&cam, W, H, &lights));
    assert_eq!(h.report.geometry_triangles, 6000);
}

#[test]
fn levels_of_detail_make_the_same_pixels_at_one_and_two_threads() {
    let run = || {
        let (mut h, _, _) = statues(&[1.0, -10.0, -40.0, -194.0]);
        let cam = eye_camera();
        let lights = lighting();
        h.plan(&FrameView::still(&cam, W, H, &lights));
        let mut draws = Vec::new();
        h.draws(&mut draws);
        render(draws, &cam, &mut Renderer::new()).to_rgba8()
    };
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let (one, two) = (pool(1).install(run), pool(2).install(run));
    assert!(one.iter().any(|&b| b != 0));
    assert_eq!(one, two);
}

#[test]
fn a_node_image_captures_each_object_at_its_level_within_half_a_texel() {
    // Two statues 40 units apart in one node: its box's diagonal is about 43 units, so at
    // half a texel of a 72-texel image the captures may deviate by 0.3 units (over the
    // coarse torus's 0.1: coarse); at half a texel of 1,024 texels by 0.021 (full). Two
    // statues side by side: a 4.3-unit diagonal, 0.030 units at 72 texels (full).
    let (objects, full, coarse) = statue_objects(&[0.0, -40.0]);
    let objects = Arc::new(objects);
    let members = Arc::new(vec![0u32, 1]);
    let node = |lo: Vec3, hi: Vec3, lod: (f32, u32)| {
        Cluster::new(objects.clone(), members.clone(), 0, 2, (lo, hi), 0)
            .with_capture_lod(lod.0, lod.1)
    };
    let (lo, hi) = (Vec3::new(-1.5, -1.5, -41.5), Vec3::new(1.5, 1.5, 1.5));
    let meshes = |c: &Cluster<MeshGroup>| {
        let mut draws = Vec::new();
        let n = c.captured_triangles(&mut draws);
        let coarse_drawn = draws.iter().filter(|d| std::ptr::eq(d.mesh, &*coarse));
        let full_drawn = draws.iter().filter(|d| std::ptr::eq(d.mesh, &*full));
        (n, coarse_drawn.count(), full_drawn.count())
    };
    assert_eq!(meshes(&node(lo, hi, (0.5, 72))), (400, 2, 0));
    assert_eq!(meshes(&node(lo, hi, (0.5, 1024))), (6000, 0, 2));
    assert_eq!(meshes(&node(lo, hi, (0.0, 0))), (6000, 0, 2));
    assert_eq!(meshes(&node(lo, hi, (0.5, 0))), (6000, 0, 2));
    let near = (Vec3::new(-1.5, -1.5, -0.2), Vec3::new(1.5, 1.5, 0.2));
    assert_eq!(meshes(&node(near.0, near.1, (0.5, 72))), (6000, 0, 2));
    // The triangles the planner counts for it stay the full meshes' (its cost as geometry).
    assert_eq!(node(lo, hi, (0.5, 72)).triangle_count(), 6000);
}
