//! The sweep's trees (meshes, baked sprites, billboards) and the `trees_mesh`,
//! `trees_billboard` and `trees_nailboard` forest series (the last's forest in
//! `nailboards.rs`).

use super::nailboards::NailboardForest;
use super::particles::measure;
use super::{Row, Settings};
use crate::bench::raster::count_name;
use engine::procedural::{self, TreeKind, XorShift};
use engine::{AlphaMode, Camera, Draw, Lighting, Material, Mesh, Renderer, Rgba, Target};
use glam::{Mat4, Vec3};
use ibr::metrics::{self, Options};
use ibr::sprites::{self, BakedSprite};
use ibr::technique::Technique;
use ibr::{Billboard, BillboardBatch, Facing, Size};

/// The trees of the sweep, standing on the origin and 5 units tall: a pine and a broadleaf.
pub(super) fn tree_meshes() -> [Mesh; 2] {
    [
        procedural::tree(TreeKind::Pine, 5.0, 11),
        procedural::tree(TreeKind::Broadleaf, 5.0, 12),
    ]
}

/// The trees' material: lit, vertex-coloured.
pub(super) fn tree_material() -> Material {
    Material::lit(Rgba::WHITE)
}

/// The alpha-tested material of billboard trees showing `sprite`.
pub(super) fn sprite_material(sprite: &BakedSprite) -> Material {
    Material {
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        ..Material::unlit(Rgba::WHITE).with_texture(sprite.texture.clone())
    }
}

/// An upright billboard standing on `position` showing `sprite`'s side view at `scale`.
pub(super) fn tree_billboard(
    sprite: &BakedSprite,
    position: Vec3,
    scale: f32,
    facing: Facing,
) -> Billboard {
    Billboard {
        position,
        facing,
        size: Size::World(sprite.size * scale),
        pivot: sprite.pivot,
        rotation: 0.0,
        tint: Rgba::WHITE,
        region: sprite.side,
    }
}

/// A forest of `n` trees (pines and broadleaves, 0.6 to 1.4 times 5 units tall) on the
/// square x in [-100, 100], z in [-190, 10]: positions, kinds (0 pine, 1 broadleaf) and
/// scales.
fn forest(n: usize, seed: u64) -> Vec<(Vec3, usize, f32)> {
    let mut rng = XorShift::new(seed);
    (0..n)
        .map(|_| {
            let p = Vec3::new(rng.range(-100.0, 100.0), 0.0, rng.range(-190.0, 10.0));
            let kind = (rng.next_u64() % 2) as usize;
            (p, kind, rng.range(0.6, 1.4))
        })
        .collect()
}

/// The forest camera: 12 units up at z = 20, looking down 15 degrees along -Z.
pub fn forest_camera(width: u32, height: u32) -> Camera {
    let eye = Vec3::new(0.0, 12.0, 20.0);
    let target = eye + Vec3::new(0.0, -(15f32.to_radians().tan()), -1.0);
    Camera::look_at(eye, target, Vec3::Y, 60f32.to_radians(), 1.0)
        .with_aspect(width, height)
        .with_depth_range(0.5, 400.0)
}

/// Appends `mesh` moved by `m` (normals rotated) to `out`.
fn append_transformed(out: &mut Mesh, mesh: &Mesh, m: Mat4) {
    let mut copy = mesh.clone();
    for p in &mut copy.positions {
        *p = m.transform_point3(*p);
    }
    let n = Mat4::from_mat3(glam::Mat3::from_mat4(m).inverse().transpose());
    for v in &mut copy.normals {
        *v = n.transform_vector3(*v).normalize_or(Vec3::Y);
    }
    out.append(&copy);
}

/// The `trees_mesh` and `trees_billboard` rows for each tree count.
pub(super) fn trees(
    settings: &Settings,
    renderer: &mut Renderer,
    progress: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let lighting = Lighting::default();
    let material = tree_material();
    let kinds = tree_meshes();
    let sprites: Vec<BakedSprite> = kinds
        .iter()
        .map(|mesh| sprites::bake_upright(mesh, &material, &lighting, Vec3::Z, 128))
        .collect();
    let ground = procedural::plane(240.0, 240.0, 1, 1);
    let ground_material = Material::lit(Rgba::from_srgb8(90, 120, 60));
    let ground_at = Mat4::from_translation(Vec3::new(0.0, 0.0, -90.0));
    let (w, h) = settings.tree_size;
    let camera = forest_camera(w, h);
    let mut target = Target::new(w, h);
    let time = |renderer: &mut Renderer,
                target: &mut Target,
                fixed: &[Draw],
                techniques: &mut [&mut dyn Technique]| {
        measure(
            renderer, target, &camera, &lighting, fixed, techniques, settings,
        )
    };
    // The nailboards' views are baked once for every count (as a game loads them).
    let mut nailboards: Option<NailboardForest> = None;
    for &n in &settings.tree_counts {
        let trees = forest(n, 5);
        // Meshes: one merged mesh per kind (static batching).
        progress(format!("trees_mesh {}", count_name(n as u64)));
        let mut merged = [Mesh::default(), Mesh::default()];
        let mut rng = XorShift::new(9);
        for &(p, kind, scale) in &trees {
            let m = Mat4::from_translation(p)
                * Mat4::from_rotation_y(rng.range(0.0, std::f32::consts::TAU))
                * Mat4::from_scale(Vec3::splat(scale));
            append_transformed(&mut merged[kind], &kinds[kind], m);
        }
        let mut fixed = vec![Draw {
            mesh: &ground,
            material: &ground_material,
            transform: ground_at,
        }];
        fixed.extend(merged.iter().map(|mesh| Draw {
            mesh,
            material: &material,
            transform: Mat4::IDENTITY,
        }));
        let triangles = fixed.iter().map(|d| d.mesh.triangle_count() as u64).sum();
        let measured = time(renderer, &mut target, &fixed, &mut []);
        let row = |series, triangles, measured| {
            Row::timed(
                series,
                "trees",
                n as f64,
                (w, h),
                n as u64,
                triangles,
                measured,
            )
        };
        // The mesh forest is the ground truth of the billboard forest, on the same frame.
        let truth = target.clone();
        let mut mesh_row = row("trees_mesh", triangles, measured);
        mesh_row.error = metrics::compare(&truth, &truth, &Options::default()).ok();
        rows.push(mesh_row);
        drop(fixed);
        drop(merged);

        // Billboards: one alpha-tested batch per kind.
        progress(format!("trees_billboard {}", count_name(n as u64)));
        let mut batches: Vec<BillboardBatch> = sprites
            .iter()
            .map(|s| BillboardBatch::new(sprite_material(s)))
            .collect();
        for &(p, kind, scale) in &trees {
            batches[kind].push(tree_billboard(&sprites[kind], p, scale, Facing::UPRIGHT));
        }
        let fixed = [Draw {
            mesh: &ground,
            material: &ground_material,
            transform: ground_at,
        }];
        let mut techniques: Vec<&mut dyn Technique> = batches
            .iter_mut()
            .map(|b| b as &mut dyn Technique)
            .collect();
        let measured = time(renderer, &mut target, &fixed, &mut techniques);
        let triangles = ground.triangle_count() as u64
            + batches
                .iter()
                .map(|b| b.mesh().triangle_count() as u64)
                .sum::<u64>();
        let mut billboard_row = row("trees_billboard", triangles, measured);
        billboard_row.error = metrics::compare(&target, &truth, &Options::default()).ok();
        rows.push(billboard_row);

        // Nailboards: the showcase forest's technique, one mesh of outlines per kind.
        progress(format!("trees_nailboard {}", count_name(n as u64)));
        let forest = nailboards.get_or_insert_with(|| {
            NailboardForest::new(&kinds, &material, &lighting, settings.bake_px)
        });
        forest.plant(&trees);
        let measured = time(renderer, &mut target, &fixed, &mut [forest]);
        let triangles = ground.triangle_count() as u64 + forest.triangles();
        let mut nailboard_row = row("trees_nailboard", triangles, measured);
        nailboard_row.error = metrics::compare(&target, &truth, &Options::default()).ok();
        rows.push(nailboard_row);
    }
}
