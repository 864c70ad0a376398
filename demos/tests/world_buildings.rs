//! The world's buildings drawn as geometry through their level of detail of the same surface
//! ([`merged_building`], issue 41): the same pixels as the full `k` x `k` mesh from near
//! and far, in 24% to 41% of its triangles; and the planner's geometry in the world
//! draws them, so its triangles fall while its frame stays that of all the geometry. Where
//! a cell is under half a pixel the building is its box ([`boxed_building`], 10
//! triangles), the same outline in the faces' mean colours.
//! Counters (triangles, pixels) against the full mesh and the full objects.

use demos::city::{building, daylight};
use demos::world::{boxed_building, cell_side, merged_building, tree_planner, TreePlan, World};
use engine::{Camera, Draw, FrameOptions, Material, Renderer, Rgba, Shading, Target};
use glam::{Mat4, Vec3};
use ibr::subject::Subject;
use ibr::technique::FrameView;

/// `mesh` lit as the world's buildings, seen from `eye` looking at the building's middle,
/// at 240 x 180: the target's 8-bit pixels.
fn picture(mesh: &engine::Mesh, eye: Vec3, mid: Vec3) -> Vec<u8> {
    let material = Material {
        shading: Shading::Lit {
            specular: 0.1,
            shininess: 16.0,
        },
        ..Material::default()
    };
    let (w, h) = (240, 180);
    let camera =
        Camera::look_at(eye, mid, Vec3::Y, 1.0, w as f32 / h as f32).with_depth_range(0.1, 200.0);
    let draws = vec![Draw {
        mesh,
        material: &material,
        transform: Mat4::from_rotation_y(0.4),
    }];
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.55, 0.65, 0.8, 1.0)),
        ..FrameOptions::default()
    };
    Renderer::new().render(draws, &camera, &daylight(), &mut target, &opts);
    target.to_rgba8()
}

/// The world's three buildings (`k` cells a face, their size, the full mesh), as
/// `World` builds them.
fn buildings() -> Vec<(u32, Vec3, engine::Mesh)> {
    [
        (6, Rgba::new(0.7, 0.6, 0.5, 1.0)),
        (8, Rgba::new(0.55, 0.6, 0.68, 1.0)),
        (10, Rgba::new(0.72, 0.52, 0.42, 1.0)),
    ]
    .into_iter()
    .map(|(k, wall)| {
        let size = Vec3::new(3.2, 7.0 + k as f32, 3.0);
        (k, size, building(size, k, wall))
    })
    .collect()
}

/// 12 eyes around `mid`, above it and close by: the `e`-th at 6, 14 or 40 units (`e % 3`),
/// three heights (`e / 4`).
fn eyes(mid: Vec3) -> impl Iterator<Item = (usize, Vec3)> {
    (0..12).map(move |e| {
        let angle = e as f32 * 0.53;
        let distance = [6.0, 14.0, 40.0][e % 3];
        let up = [0.3, 0.8, 1.6][e / 4];
        (e, mid + Vec3::new(angle.cos(), up, angle.sin()) * distance)
    })
}

/// Each of the world's three buildings merged has 24 `k` + 2 triangles (41%, 30% and 24%
/// of 10 `k`^2 at `k` = 6, 8, 10) and, seen from 12 eyes around, above and close by, draws the full
/// mesh's pixels: at most 0.02 levels of mean difference and under 0.05% of the pixels
/// over 2 levels, the building's pixels (those not the sky's) the same count within 0.05%.
#[test]
fn a_merged_building_draws_the_full_buildings_pixels_in_fewer_triangles() {
    for (k, size, full) in buildings() {
        let merged = merged_building(&full, k);
        assert!(merged.validate().is_ok());
        assert_eq!(merged.triangle_count(), 24 * k as usize + 2, "k {k}");
        assert_eq!(full.triangle_count(), 10 * (k * k) as usize);
        let mid = Vec3::new(0.0, size.y * 0.5, 0.0);
        let (mut sum, mut over, mut pixels, mut drawn) = (0u64, 0usize, 0usize, [0usize; 2]);
        for (_, eye) in eyes(mid) {
            let (a, b) = (picture(&full, eye, mid), picture(&merged, eye, mid));
            let sky = &a[..4].to_vec();
            for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
                let d: u32 = (0..3).map(|c| u32::from(p[c].abs_diff(q[c]))).sum();
                sum += u64::from(d);
                over += usize::from(d > 6);
                pixels += 1;
                drawn[0] += usize::from(p != &sky[..]);
                drawn[1] += usize::from(q != &sky[..]);
            }
        }
        let mean = sum as f64 / 3.0 / pixels as f64;
        assert!(mean < 0.02, "k {k}: mean {mean}");
        assert!(
            over * 2000 < pixels,
            "k {k}: {over} of {pixels} over 2 levels"
        );
        assert!(drawn[0] > pixels / 20, "k {k}: the building is in view");
        let apart = drawn[0].abs_diff(drawn[1]);
        assert!(apart * 2000 < pixels, "k {k}: drawn {drawn:?}");
    }
}

/// Each of the world's three buildings as its box has 10 triangles and, seen from the
/// same 12 eyes, covers the full mesh's pixels (the count within 0.05%), and its pixels'
/// mean colour in linear light, from the far eyes (40 units, where the perspective
/// weighs a face's rows about alike), is the full mesh's within 2%: its faces are the
/// full faces' mean colours, what the windows average to where they are under a pixel. Its
/// deviation ([`cell_side`]) is a cell's largest side.
#[test]
fn a_boxed_building_covers_the_full_buildings_pixels_in_their_mean_colour() {
    for (k, size, full) in buildings() {
        let boxed = boxed_building(&full, k);
        assert!(boxed.validate().is_ok());
        assert_eq!(boxed.triangle_count(), 10, "k {k}");
        assert!((cell_side(&full, k) - size.y / k as f32).abs() < 1e-4);
        let mid = Vec3::new(0.0, size.y * 0.5, 0.0);
        let (mut pixels, mut drawn, mut sums) = (0usize, [0usize; 2], [[0f64; 3]; 2]);
        let mut far = [0usize; 2];
        let linear = |b: u8| {
            let c = f64::from(b) / 255.0;
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        for (e, eye) in eyes(mid) {
            let pictures = [picture(&full, eye, mid), picture(&boxed, eye, mid)];
            let sky = pictures[0][..4].to_vec();
            for (m, p) in pictures.iter().enumerate() {
                for q in p.chunks_exact(4).filter(|q| q != &&sky[..]) {
                    drawn[m] += 1;
                    far[m] += usize::from(e % 3 == 2);
                    for c in (0..3).filter(|_| e % 3 == 2) {
                        sums[m][c] += linear(q[c]);
                    }
                }
            }
            pixels += pictures[0].len() / 4;
        }
        assert!(drawn[0] > pixels / 20, "k {k}: the building is in view");
        let apart = drawn[0].abs_diff(drawn[1]);
        assert!(apart * 2000 < pixels, "k {k}: drawn {drawn:?}");
        for c in 0..3 {
            let mean = |m: usize| sums[m][c] / far[m] as f64;
            let (a, b) = (mean(0), mean(1));
            assert!(
                (a - b).abs() < 0.02 * a,
                "k {k} channel {c}: {a} against {b}"
            );
        }
    }
}

/// In the world (32 x 32 lots) at 640x360, the planner's objects drawn as geometry after
/// its loading frames take at most 60% of the triangles their full meshes have (the
/// buildings merged, the statues at their levels), and their buildings are merged, or
/// boxed where a cell projects within the half-pixel tolerance.
#[test]
fn the_worlds_geometry_draws_the_merged_buildings() {
    let world = World::new(32, 11);
    let (w, h) = (640, 360);
    let mut planner = tree_planner(world.objects.clone(), TreePlan::for_tests(&world, h));
    let camera = world.camera(0.1, (w, h));
    for _ in 0..5 {
        planner.plan(&FrameView::still(&camera, w, h, &world.lighting));
    }
    let geometry = planner.geometry();
    let full: usize = geometry
        .iter()
        .map(|&i| world.objects[i as usize].triangle_count())
        .sum();
    let drawn = planner.report.geometry_triangles;
    assert!(geometry.len() > 20, "{:?}", planner.report);
    assert!(drawn * 10 <= full * 6, "drawn {drawn} of {full}");
    let eye = camera.eye();
    let (mut draws, mut buildings) = (Vec::new(), 0);
    for &i in geometry {
        let object = &world.objects[i as usize];
        let full = object.triangle_count();
        let vertices = object.parts[0].mesh.positions.len();
        let building = |k: &usize| full == 10 * k * k && vertices == 5 * (k + 1) * (k + 1);
        let Some(k) = [6, 8, 10].into_iter().find(building) else {
            continue;
        };
        draws.clear();
        let part = &object.parts[0];
        let ppr = ibr::plan::Sight::new(&camera, w, h, part.bounds()).px_per_radian;
        object.draws_seen(eye, ppr, 0.5, &mut draws);
        let t = part.transform;
        let scale = [t.x_axis, t.y_axis, t.z_axis].map(|a| a.truncate().length());
        let scale = scale.into_iter().fold(0.0, f32::max);
        let distance = part.bounds().center.distance(eye) - part.bounds().radius;
        let cell_px = cell_side(&part.mesh, k as u32) * scale * ppr / distance;
        let expected = if cell_px <= 0.5 { 10 } else { 24 * k + 2 };
        assert_eq!(
            draws[0].mesh.triangle_count(),
            expected,
            "cell {cell_px} px"
        );
        draws.clear();
        object.draws_seen(eye, 1.0, 0.0, &mut draws);
        assert_eq!(
            draws[0].mesh.triangle_count(),
            full,
            "a tolerance of 0: full"
        );
        buildings += 1;
    }
    assert!(buildings > 5, "{buildings} buildings as geometry");
}
