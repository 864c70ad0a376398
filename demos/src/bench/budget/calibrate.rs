//! Calibrating the planner's cost model ([`ibr::plan::CostModel`]) on this machine: the
//! city at four detail levels with the same silhouettes and distant tori (triangle cost),
//! stacks of
//! screen-filling lit quads and image quads (pixel costs), and
//! batches of impostor rebuilds through the planner's own call (capture cost), and the
//! image passes of depth images, LDIs and light fields (sample cost), each timed as the
//! median of several repeats; the per-unit times are a least-squares fit, the capture and
//! sample costs what the fit leaves unexplained per capture and per sample.

use crate::bench::impostors::frame_camera;
use crate::bench::sweep::CsvRow;
use crate::city::{City, Path as CityPath};
use engine::procedural;
use engine::{Camera, FrameOptions, Material, Mesh, Renderer, Rgba, Target};
use glam::{Mat4, Vec3};
use ibr::depth_images::{self, DepthImageSet};
use ibr::impostor::{self, ImpostorSet};
use ibr::lightfield::LightFieldSet;
use ibr::plan::{CostModel, Representation, Sight};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::FrameView;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// One timed configuration.
#[derive(Clone, Debug, Default)]
pub struct Calibration {
    pub experiment: &'static str,
    pub triangles: u64,
    pub pixels: u64,
    pub image_pixels: u64,
    pub captures: u64,
    /// Image passes, the pixels they cover and the reference samples they read
    /// (predicted).
    pub passes: u64,
    pub pass_pixels: u64,
    pub samples: u64,
    pub ms: f64,
}

impl CsvRow for Calibration {
    const HEADER: &'static str =
        "experiment,triangles,pixels,image_pixels,captures,passes,pass_pixels,samples,ms";

    fn csv(&self) -> String {
        format!(
            "{},{},{},{},{},{},{},{},{:.4}",
            self.experiment,
            self.triangles,
            self.pixels,
            self.image_pixels,
            self.captures,
            self.passes,
            self.pass_pixels,
            self.samples,
            self.ms
        )
    }
}

/// The median of `reps` timings of `f`.
fn median(reps: usize, mut f: impl FnMut()) -> f64 {
    f();
    let mut t: Vec<Duration> = (0..reps.max(1))
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed()
        })
        .collect();
    t.sort();
    t[t.len() / 2].as_secs_f64() * 1e3
}

/// What every experiment shares: the renderer and its target, the camera and light of
/// the synthetic experiments, the size, how many repeats, and the scale of the counts.
struct Lab {
    renderer: Renderer,
    target: Target,
    opts: FrameOptions,
    camera: Camera,
    light: engine::Lighting,
    size: (u32, u32),
    reps: usize,
    scale: f32,
    /// The lit material of every experiment's geometry.
    lit: Arc<Material>,
    /// Tori of 2000 triangles (the far objects and the held ones).
    torus: Arc<Mesh>,
}

impl Lab {
    /// `n` at this lab's scale (at least 1).
    fn count(&self, n: f32) -> usize {
        ((n * self.scale).round() as usize).max(1)
    }
}

/// Times the experiments at `size` (`scale` 1 for the full set, less for a smoke run) and
/// fits the model.
pub fn calibrate(size: (u32, u32), scale: f32, reps: usize) -> (CostModel, Vec<Calibration>) {
    let (w, h) = size;
    let camera = Camera::look_at(
        Vec3::new(0.0, 0.0, 10.0),
        Vec3::ZERO,
        Vec3::Y,
        1.0,
        w as f32 / h as f32,
    )
    .with_depth_range(0.1, 2000.0);
    let mut lab = Lab {
        light: engine::Lighting::white_sun(0.3, Vec3::new(-0.3, -1.0, -0.4)),
        camera,
        renderer: Renderer::new(),
        target: Target::new(w, h),
        opts: FrameOptions::default(),
        size,
        reps,
        scale,
        lit: Arc::new(Material::lit(Rgba::new(0.7, 0.5, 0.3, 1.0))),
        torus: Arc::new(procedural::torus_with_triangles(2000)),
    };
    let mut rows = Vec::new();
    triangles(&mut lab, &mut rows);
    far(&mut lab, &mut rows);
    pixels(&mut lab, &mut rows);
    let fit = fit(&rows);
    let (a, b) = captures(&mut lab, &fit, &mut rows);
    let mut model = CostModel {
        us_per_capture: (a * 1e3).max(0.0) as f32,
        ns_per_capture_texel: (b * 1e6) as f32,
        ..fit
    };
    let first = rows.len();
    passes(&mut lab, &model, &mut rows);
    let [a, b, c] = fit_passes(&rows[first..]);
    model.us_per_pass = (a * 1e3).max(0.0) as f32;
    model.ns_per_pass_pixel = (b * 1e6).max(0.0) as f32;
    model.ns_per_sample = (c * 1e6).max(0.0) as f32;
    (model, rows)
}

/// Triangles: the city at four detail levels, the same silhouettes and pixels.
fn triangles(lab: &mut Lab, rows: &mut Vec<Calibration>) {
    let (size, reps) = (lab.size, lab.reps);
    let ks = [4, 8, 16, 24].map(|k| lab.count(k as f32).max(2) as u32);
    let Lab {
        renderer,
        target,
        opts,
        ..
    } = lab;
    for k in ks {
        let city = City::new(4, k, 7);
        let cam = frame_camera(&city, CityPath::Translate, 0.25, 0, 2, size);
        let mut draws = Vec::new();
        city.buildings.iter().for_each(|b| b.draws(&mut draws));
        let light = &city.lighting;
        let stats = renderer.render(draws.iter().copied(), &cam, light, target, opts);
        let ms = median(reps, || {
            renderer.render(draws.iter().copied(), &cam, light, target, opts);
        });
        rows.push(Calibration {
            experiment: "triangles",
            triangles: stats.triangles_in,
            pixels: stats.fragments_shaded,
            image_pixels: 0,
            captures: 0,
            ms,
            ..Calibration::default()
        });
    }
}

/// Triangles far away: tori of 2000 triangles a few pixels across, as distant objects
/// are (most of a large world's triangles).
fn far(lab: &mut Lab, rows: &mut Vec<Calibration>) {
    let reps = lab.reps;
    let ns = [50.0, 100.0, 200.0, 400.0].map(|n| lab.count(n));
    let Lab {
        renderer,
        target,
        opts,
        camera,
        light,
        lit,
        torus,
        ..
    } = lab;
    for n in ns {
        let placed: Vec<Mat4> = (0..n)
            .map(|k| {
                let (x, y) = ((k % 20) as f32 - 9.5, (k / 20) as f32 - 9.5);
                Mat4::from_translation(Vec3::new(x * 6.0, y * 4.0, -300.0))
            })
            .collect();
        let draws = || {
            placed.iter().map(|&m| engine::Draw {
                mesh: torus,
                material: lit,
                transform: m,
            })
        };
        let stats = renderer.render(draws(), camera, light, target, opts);
        let ms = median(reps, || {
            renderer.render(draws(), camera, light, target, opts);
        });
        rows.push(Calibration {
            experiment: "far",
            triangles: stats.triangles_in,
            pixels: stats.fragments_shaded,
            image_pixels: 0,
            captures: 0,
            ms,
            ..Calibration::default()
        });
    }
}

/// Pixels: stacks of quads filling the view, drawn back to front so each is shaded: lit
/// geometry, then images (textured, blended).
fn pixels(lab: &mut Lab, rows: &mut Vec<Calibration>) {
    let reps = lab.reps;
    let Lab {
        renderer,
        target,
        opts,
        camera,
        light,
        lit,
        ..
    } = lab;
    let quad = Arc::new(quad_mesh());
    let image = Arc::new(impostor::image_material(64, 64, "calibration"));
    for (material, is_image) in [(&*lit, false), (&image, true)] {
        for k in [1usize, 2, 4, 8] {
            let draws = || {
                (0..k).map(|j| engine::Draw {
                    mesh: &quad,
                    material,
                    transform: Mat4::from_translation(Vec3::new(0.0, 0.0, -((k - 1 - j) as f32))),
                })
            };
            let stats = renderer.render(draws(), camera, light, target, opts);
            let ms = median(reps, || {
                renderer.render(draws(), camera, light, target, opts);
            });
            let px = stats.fragments_shaded;
            rows.push(Calibration {
                experiment: if is_image { "images" } else { "pixels" },
                triangles: stats.triangles_in,
                pixels: if is_image { 0 } else { px },
                image_pixels: if is_image { px } else { 0 },
                captures: 0,
                ms,
                ..Calibration::default()
            });
        }
    }
}

/// Captures: batches of rebuilds of one small object's images through the planner's
/// call, far (16 to 32 texels a side) and near (64), so that what the `fit` leaves
/// unexplained splits into a cost per capture and one per captured texel: those two (ms).
fn captures(lab: &mut Lab, fit: &CostModel, rows: &mut Vec<Calibration>) -> (f64, f64) {
    let ((w, h), reps) = (lab.size, lab.reps);
    let n = lab.count(128.0);
    let (camera, light, lit) = (&lab.camera, &lab.light, &lab.lit);
    let small = Arc::new(procedural::torus_with_triangles(200));
    let view = FrameView::still(camera, w, h, light);
    let all: Vec<usize> = (0..n).collect();
    let mut left = Vec::new();
    for z in [-60.0, -20.0] {
        let objects: Vec<MeshGroup> = (0..n)
            .map(|k| {
                let spread = -z / 60.0;
                let at = Vec3::new(
                    ((k % 16) as f32 * 3.0 - 22.5) * spread,
                    ((k / 16) as f32 * 3.0 - 12.0) * spread,
                    z,
                );
                MeshGroup::new().with(small.clone(), lit.clone(), Mat4::from_translation(at))
            })
            .collect();
        let mut subjects = objects.clone();
        let mut set = ImpostorSet::new(impostor::Config::default(), n);
        let mut done = ibr::plan::Work::default();
        let ms = median(reps, || {
            done = Representation::<MeshGroup>::rebuild(&mut set, &all, &mut subjects, &view);
        });
        rows.push(Calibration {
            experiment: "captures",
            triangles: done.triangles,
            pixels: done.pixels,
            image_pixels: 0,
            captures: done.captures,
            ms,
            ..Calibration::default()
        });
        left.push((done, ms - fit.ms(done) as f64));
    }
    // Two batches, two unknowns: `left = a captures + b texels` (ms); a texel cost below
    // zero is noise, and then the captures take all that is left.
    match left[..] {
        [(d0, l0), (d1, l1)] => {
            let m = [
                [d0.captures as f64, d0.pixels as f64],
                [d1.captures as f64, d1.pixels as f64],
            ];
            match solve(m, [l0, l1]) {
                Some([a, b]) if b >= 0.0 => (a, b),
                _ => ((l0 + l1) / (d0.captures + d1.captures).max(1) as f64, 0.0),
            }
        }
        _ => (0.0, 0.0),
    }
}

/// Image passes: objects held as depth images, LDIs and light fields (4 x 4 tori of
/// 2000 triangles, at three distances), prepared and composited; what the `model` so far
/// leaves of each time is the passes' own.
fn passes(lab: &mut Lab, model: &CostModel, rows: &mut Vec<Calibration>) {
    let ((w, h), reps) = (lab.size, lab.reps);
    let grid = lab.count(16.0).min(16);
    let Lab {
        target,
        camera,
        light,
        lit,
        torus,
        ..
    } = lab;
    let view = FrameView::still(camera, w, h, light);
    for z in [-7.0, -14.0, -28.0] {
        let spread = -z / 14.0;
        let held: Vec<MeshGroup> = (0..grid)
            .map(|k| {
                let x = (k % 4) as f32 * 3.0 - 4.5;
                let y = (k / 4) as f32 * 2.4 - 3.6;
                let at = Vec3::new(x * spread, y * spread, z);
                MeshGroup::new().with(torus.clone(), lit.clone(), Mat4::from_translation(at))
            })
            .collect();
        let ldi = depth_images::Config {
            layers: 3,
            ..depth_images::Config::default()
        };
        let held_by: [(&'static str, Box<dyn Representation<MeshGroup>>); 3] = [
            (
                "warps",
                Box::new(DepthImageSet::new(Default::default(), grid)),
            ),
            ("ldi warps", Box::new(DepthImageSet::new(ldi, grid))),
            ("fields", Box::new(LightFieldSet::new(grid, 8, 32))),
        ];
        for (experiment, mut rep) in held_by {
            let mut subjects = held.clone();
            let all: Vec<usize> = (0..grid).collect();
            rep.rebuild(&all, &mut subjects, &view);
            let mut work = ibr::plan::Work::default();
            for (i, s) in subjects.iter().enumerate() {
                let sight = Sight::new(camera, w, h, s.bounds());
                work += rep
                    .estimate(i, s, &sight)
                    .map(|e| e.draw)
                    .unwrap_or_default();
            }
            let ms = median(reps, || {
                rep.prepare(&all, &subjects, &view);
                rep.passes(&view, target);
            });
            rows.push(Calibration {
                experiment,
                passes: work.passes,
                pass_pixels: work.pass_pixels,
                samples: work.samples,
                // Time besides the passes' own work (none for these representations).
                ms: ms
                    - model.ms(ibr::plan::Work {
                        passes: 0,
                        pass_pixels: 0,
                        samples: 0,
                        ..work
                    }) as f64,
                ..Calibration::default()
            });
        }
    }
}

/// Least squares of `ms = a triangles + b pixels + c image_pixels + d` over the frame rows
/// (`d`, a frame's fixed cost, is not per object and is left out of the model).
fn fit(rows: &[Calibration]) -> CostModel {
    let mut m = [[0.0f64; 4]; 4];
    let mut v = [0.0f64; 4];
    for r in rows.iter().filter(|r| r.captures == 0) {
        let x = [
            r.triangles as f64,
            r.pixels as f64,
            r.image_pixels as f64,
            1.0,
        ];
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] += x[i] * x[j];
            }
            v[i] += x[i] * r.ms;
        }
    }
    let s = solve(m, v).unwrap_or([0.0; 4]);
    CostModel {
        ns_per_triangle: (s[0] * 1e6).max(0.0) as f32,
        ns_per_pixel: (s[1] * 1e6).max(0.0) as f32,
        ns_per_image_pixel: (s[2] * 1e6).max(0.0) as f32,
        // Fitted apart (see `calibrate`).
        us_per_capture: 0.0,
        ..CostModel::default()
    }
}

/// Least squares of `ms = a passes + b pass_pixels + c samples` over `rows`.
fn fit_passes(rows: &[Calibration]) -> [f64; 3] {
    let mut m = [[0.0f64; 3]; 3];
    let mut v = [0.0f64; 3];
    for r in rows {
        let x = [r.passes as f64, r.pass_pixels as f64, r.samples as f64];
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += x[i] * x[j];
            }
            v[i] += x[i] * r.ms;
        }
    }
    solve(m, v).unwrap_or([0.0; 3])
}

/// `m x = v` by Gaussian elimination with partial pivoting.
fn solve<const N: usize>(mut m: [[f64; N]; N], mut v: [f64; N]) -> Option<[f64; N]> {
    for c in 0..N {
        let p = (c..N).max_by(|&a, &b| m[a][c].abs().total_cmp(&m[b][c].abs()))?;
        if m[p][c].abs() < 1e-12 {
            return None;
        }
        m.swap(c, p);
        v.swap(c, p);
        for r in c + 1..N {
            let f = m[r][c] / m[c][c];
            for k in c..N {
                m[r][k] -= f * m[c][k];
            }
            v[r] -= f * v[c];
        }
    }
    let mut x = [0.0; N];
    for r in (0..N).rev() {
        let s: f64 = (r + 1..N).map(|k| m[r][k] * x[k]).sum();
        x[r] = (v[r] - s) / m[r][r];
    }
    Some(x)
}

/// A quad far larger than the view, facing +Z, at z = 0.
fn quad_mesh() -> Mesh {
    let mut m = procedural::plane(400.0, 400.0, 1, 1);
    m.colors.clear();
    // The plane lies in XZ facing +Y: stand it up to face the camera.
    let r = Mat4::from_rotation_x(std::f32::consts::FRAC_PI_2);
    for p in &mut m.positions {
        *p = r.transform_point3(*p);
    }
    for n in &mut m.normals {
        *n = r.transform_vector3(*n);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fit_recovers_known_per_unit_costs() {
        let points = [
            (1000u64, 10u64, 0u64),
            (5000, 200, 0),
            (20000, 50, 0),
            (3000, 900000, 0),
            (2, 0, 400000),
            (2, 0, 100000),
        ];
        let rows: Vec<Calibration> = points
            .iter()
            .map(|&(t, p, i)| Calibration {
                experiment: "synthetic",
                triangles: t,
                pixels: p,
                image_pixels: i,
                ms: (t as f64 * 40.0 + p as f64 * 3.0 + i as f64 * 5.0) * 1e-6 + 0.2,
                ..Calibration::default()
            })
            .collect();
        let m = fit(&rows);
        assert!((m.ns_per_triangle - 40.0).abs() < 1e-2, "{m:?}");
        assert!((m.ns_per_pixel - 3.0).abs() < 1e-3, "{m:?}");
        assert!((m.ns_per_image_pixel - 5.0).abs() < 1e-3, "{m:?}");
    }

    #[test]
    fn the_pass_fit_recovers_known_per_unit_costs() {
        let rows: Vec<Calibration> = [
            (16u64, 60000u64, 20000u64),
            (16, 30000, 130000),
            (16, 6000, 60000),
            (8, 15000, 5000),
        ]
        .iter()
        .map(|&(n, px, s)| Calibration {
            experiment: "synthetic",
            passes: n,
            pass_pixels: px,
            samples: s,
            ms: n as f64 * 0.04 + (px as f64 * 58.0 + s as f64 * 4.0) * 1e-6,
            ..Calibration::default()
        })
        .collect();
        let [a, b, c] = fit_passes(&rows);
        assert!(
            (a - 0.04).abs() < 1e-6 && (b * 1e6 - 58.0).abs() < 1e-3,
            "{a} {b}"
        );
        assert!((c * 1e6 - 4.0).abs() < 1e-3, "{c}");
    }
}
