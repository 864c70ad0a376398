//! Predicted against measured rebuild time: 32 tori (200 or 2,000 triangles, near or far)
//! rebuilt at once by each baked or captured representation, its estimate's rebuild work
//! turned into milliseconds by the default cost model (`CostModel::rebuild_ms`) beside the
//! time the rebuild took, on its first call (memory fresh) and its second (reused).
//!
//! `cargo run --release -p demos --example rebuild_cost`

use engine::{procedural, Camera, Lighting, Material, Rgba};
use glam::{Mat4, Vec3};
use ibr::billboard::BillboardSet;
use ibr::impostor::{self, ImpostorSet};
use ibr::lightfield::LightFieldSet;
use ibr::octahedral::{Layout, OctahedralSet};
use ibr::plan::{CostModel, Representation, Sight};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::FrameView;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let (w, h) = (1280u32, 720u32);
    let light = Lighting::white_sun(0.3, Vec3::new(-0.3, -1.0, -0.4));
    let camera = Camera::look_at(
        Vec3::new(0.0, 5.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        1.0,
        w as f32 / h as f32,
    )
    .with_depth_range(0.1, 2000.0);
    let lit = Arc::new(Material::lit(Rgba::new(0.7, 0.5, 0.3, 1.0)));
    let model = CostModel::default();
    let n = 32;
    let all: Vec<usize> = (0..n).collect();
    let view = FrameView::still(&camera, w, h, &light);
    println!("triangles  z  representation  predicted ms  first ms  second ms");
    for triangles in [200u32, 2000] {
        let torus = Arc::new(procedural::torus_with_triangles(triangles));
        for z in [-20.0f32, -60.0] {
            let objects: Vec<MeshGroup> = (0..n)
                .map(|k| {
                    let x = (k % 8) as f32 * 3.0 - 10.5;
                    let y = (k / 8) as f32 * 3.0 - 4.5;
                    let at = Mat4::from_translation(Vec3::new(x, y, z));
                    MeshGroup::new().with(torus.clone(), lit.clone(), at)
                })
                .collect();
            let reps: Vec<(&str, Box<dyn Representation<MeshGroup>>)> = vec![
                (
                    "impostors",
                    Box::new(ImpostorSet::new(impostor::Config::default(), n)),
                ),
                (
                    "octahedral",
                    Box::new(OctahedralSet::new(n, 8, 32, Layout::Hemi)),
                ),
                ("billboards", Box::new(BillboardSet::new(n, 64))),
                ("light fields", Box::new(LightFieldSet::new(n, 8, 32))),
            ];
            for (name, mut rep) in reps {
                let mut subjects = objects.clone();
                let predicted: f32 = subjects
                    .iter()
                    .enumerate()
                    .filter_map(|(i, s)| {
                        let sight = Sight::new(&camera, w, h, s.bounds());
                        rep.estimate(i, s, &sight)
                    })
                    .map(|e| model.rebuild_ms(e.rebuild))
                    .sum();
                let mut timed = || {
                    let t = Instant::now();
                    rep.rebuild(&all, &mut subjects, &view);
                    t.elapsed().as_secs_f64() * 1e3
                };
                let (first, second) = (timed(), timed());
                println!(
                    "{triangles:9} {z:3} {name:14} {predicted:13.2} {first:9.2} {second:10.2}"
                );
            }
        }
    }
}
