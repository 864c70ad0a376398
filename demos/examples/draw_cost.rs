//! Predicted against measured draw time: the city of `bench budget` (16 buildings of 1,000
//! triangles), each building drawn alone and all together as geometry, the default cost
//! model's prediction (`Geometry`'s estimate: triangles and the pixels of the bounding
//! sphere's disc) beside the measured time less an empty frame's, and the renderer's own
//! counters (triangles in, fragments shaded); then each building as each image
//! representation the planner draws by quads (runtime impostors, image layers, billboards),
//! rebuilt from this view: predicted and measured.
//!
//! `cargo run --release -p demos --example draw_cost`

use demos::bench::impostors::frame_camera;
use demos::city::{City, Path as CityPath};
use engine::{Draw, FrameOptions, Renderer, Target};
use ibr::billboard::BillboardSet;
use ibr::impostor::{self, ImpostorSet};
use ibr::layers::{self, LayerSet};
use ibr::plan::{CostModel, Geometry, Representation, Sight};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::FrameView;
use std::time::Instant;

fn median(reps: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[reps / 2]
}

fn main() {
    let size = (640u32, 360u32);
    let city = City::new(4, 10, 7);
    let cam = frame_camera(&city, CityPath::Translate, 0.25, 0, 24, size);
    let model = CostModel::default();
    let (mut renderer, mut target) = (Renderer::new(), Target::new(size.0, size.1));
    let opts = FrameOptions::default();
    let mut frame = |draws: &[Draw<'_>]| {
        renderer.render(
            draws.iter().copied(),
            &cam,
            &city.lighting,
            &mut target,
            &opts,
        )
    };
    let empty = median(31, || {
        frame(&[]);
    });
    // The renderer's counters of `draws` and their median time less an empty frame's.
    let mut measure = |draws: &[Draw<'_>]| {
        let stats = frame(draws);
        let ms = median(31, || {
            frame(draws);
        });
        (stats, ms - empty)
    };
    println!("empty frame {empty:.3} ms");
    println!("building  triangles_in  fragments  disc_px  predicted_ms  measured_ms");
    let (mut all_pred, mut all) = (0.0, Vec::new());
    for (i, b) in city.buildings.iter().enumerate() {
        let sight = Sight::new(&cam, size.0, size.1, b.bounds());
        let e = Representation::<MeshGroup>::estimate(&Geometry, i, b, &sight).unwrap();
        let pred = model.ms(e.draw);
        all_pred += pred;
        let mut draws = Vec::new();
        b.draws(&mut draws);
        all.extend(draws.iter().copied());
        let (stats, ms) = measure(&draws);
        let (tris, frags) = (stats.triangles_in, stats.fragments_shaded);
        let disc = sight.pixels;
        println!("{i:8}  {tris:12}  {frags:9}  {disc:7.0}  {pred:12.3}  {ms:11.3}");
    }
    let (stats, ms) = measure(&all);
    let (tris, frags) = (stats.triangles_in, stats.fragments_shaded);
    println!("all       {tris:12}  {frags:9}           {all_pred:12.3}  {ms:11.3}");

    // Each building as each image representation, rebuilt from this view.
    let n = city.buildings.len();
    let mut subjects = city.buildings.clone();
    let view = FrameView::still(&cam, size.0, size.1, &city.lighting);
    let mut reps: Vec<Box<dyn Representation<MeshGroup>>> = vec![
        Box::new(ImpostorSet::new(impostor::Config::default(), n)),
        Box::new(LayerSet::new(layers::Config::default(), n)),
        Box::new(BillboardSet::new(n, 64)),
    ];
    let all: Vec<usize> = (0..n).collect();
    println!("building  representation  fragments  predicted_ms  measured_ms");
    for rep in &mut reps {
        rep.rebuild(&all, &mut subjects, &view);
        rep.prepare(&all, &subjects, &view);
        let (mut all_pred, mut every) = (0.0, Vec::new());
        for (i, b) in subjects.iter().enumerate() {
            let sight = Sight::new(&cam, size.0, size.1, b.bounds());
            let Some(e) = rep.estimate(i, b, &sight) else {
                continue;
            };
            let pred = model.ms(e.draw);
            all_pred += pred;
            let mut draws = Vec::new();
            rep.draw(i, b, cam.eye(), &mut draws);
            every.extend(draws.iter().copied());
            let (stats, ms) = measure(&draws);
            let (name, frags) = (rep.name(), stats.fragments_shaded);
            println!("{i:8}  {name:>14}  {frags:9}  {pred:12.3}  {ms:11.3}");
        }
        let (stats, ms) = measure(&every);
        let (name, frags) = (rep.name(), stats.fragments_shaded);
        println!("all       {name:>14}  {frags:9}  {all_pred:12.3}  {ms:11.3}");
    }
}
