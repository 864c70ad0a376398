//! The `bench lightfield` sweep: a lit torus captured into light slabs and drawn as a
//! light-field object ([`ibr::lightfield::LightFieldObject`]) in the frame loop, against a
//! render of its geometry from the same eye on the same frames.
//!
//! Every error is PSNR and the fraction of visibly wrong pixels (more than 8 levels) over
//! the rectangle either image covers, at six eyes: three between the capture cameras (on
//! the `uv` plane) and three away from them (behind it, between the planes, off to a
//! side). Series:
//!
//! - `density`: `uv` samples per side, for each lookup (nearest, bilinear in `uv`,
//!   quadrilinear, quadrilinear depth-corrected);
//! - `st`: `st` samples per side, for each lookup;
//! - `codebook`: codewords (2x2x2x2 tiles), the quantised light field rendered
//!   quadrilinear and depth-corrected from its codes: error, frame time, training time,
//!   compression in memory and in the file (zstd after VQ);
//! - `tile`: tile shapes at one codebook size, the same measures;
//! - `outline`: the raw base slab, depth-corrected, without and with the outline from
//!   geometry ([`LightFieldObject::proxy_outline`]: coverage and depth rasterised from the
//!   torus through the frame's camera, the light field giving the colour inside);
//! - `sparse`: scattered photographs with depth maps (a hand-held-like wander near the
//!   camera plane) rebinned depth-corrected ([`ibr::lightfield::rebin`]), against the
//!   dense capture of the same slab: error, coverage IoU against the geometry and the
//!   fraction of samples pull-push invented;
//! - `resolution`: frame time against frame size, light field and geometry;
//! - `triangles`: frame time against the object's triangles, light field and geometry;
//! - `geometry`: the geometry's frame time at each eye (the error reference).

mod report;
mod series;

pub use report::{charts, LightfieldSweep};
pub use series::{run, NO_OUTLINE, OUTLINE};

use crate::bench::sweep::{CsvRow, Timing as Frames};
use crate::timing::Summary;
use engine::{
    procedural, Camera, Draw, FrameOptions, Light, Lighting, Material, Mesh, Renderer, Rgba, Target,
};
use glam::{Mat4, Vec3};
use ibr::lightfield::{Interpolation, LightField, LightFieldObject, Lookup, Rect3, Slab};
use ibr::metrics;
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::time::{Duration, Instant};

/// The lookups compared, by name.
pub const LOOKUPS: [(&str, Interpolation, bool); 4] = [
    ("nearest", Interpolation::Nearest, false),
    ("bilinear-uv", Interpolation::BilinearUv, false),
    ("quadrilinear", Interpolation::Quadrilinear, false),
    ("quadrilinear-dc", Interpolation::Quadrilinear, true),
];

/// The eyes: `(class, position)`, all looking at the object's centre.
pub const EYES: [(&str, [f32; 3]); 6] = [
    ("between", [0.13, -0.07, 4.0]),
    ("between", [-0.52, 0.41, 4.0]),
    ("between", [0.71, 0.33, 4.0]),
    ("away", [0.0, 0.0, 6.5]),
    ("away", [0.2, -0.1, 3.3]),
    ("away", [-0.9, -0.6, 5.0]),
];

/// What a run measures.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub size: (u32, u32),
    /// `uv` samples per side for the `density` series, and the `st` samples it uses.
    pub uv: Vec<u32>,
    /// `st` samples per side for the `st` series, and the `uv` samples it uses.
    pub st: Vec<u32>,
    /// The slab of the other series: `uv` and `st` samples per side.
    pub base: (u32, u32),
    pub codewords: Vec<u32>,
    /// Tile shapes of the `tile` series, at `tile_codewords`.
    pub tiles: Vec<[u32; 4]>,
    pub tile_codewords: u32,
    /// Tiles trained on.
    pub training_tiles: usize,
    pub resolutions: Vec<(u32, u32)>,
    /// Object triangles of the `triangles` series (the others use `object_triangles`).
    pub triangles: Vec<u32>,
    pub object_triangles: u32,
    /// Photographs of the `sparse` series, their size, and its slab (`uv`, `st` per side).
    pub photographs: Vec<usize>,
    pub photo_size: u32,
    pub sparse_slab: (u32, u32),
    pub frames: Frames,
}

impl Settings {
    pub fn full() -> Settings {
        Settings {
            size: (1280, 720),
            uv: vec![4, 8, 16, 32],
            st: vec![64, 128, 256, 512],
            base: (32, 256),
            codewords: vec![256, 1024, 4096, 16384],
            tiles: vec![
                [1, 1, 2, 2],
                [2, 2, 1, 1],
                [2, 2, 2, 2],
                [1, 1, 4, 4],
                [2, 2, 4, 4],
            ],
            tile_codewords: 4096,
            training_tiles: 1 << 18,
            resolutions: vec![(320, 180), (640, 360), (1280, 720), (1920, 1080)],
            triangles: vec![1_000, 10_000, 100_000, 1_000_000],
            object_triangles: 20_000,
            photographs: vec![16, 64, 128, 256],
            photo_size: 256,
            sparse_slab: (16, 128),
            frames: Frames {
                warmup: 1,
                frames: 8,
                time_limit: Duration::from_millis(800),
            },
        }
    }

    /// Every point, fewer frames and training tiles.
    pub fn quick() -> Settings {
        Settings {
            training_tiles: 1 << 16,
            frames: Frames {
                warmup: 1,
                frames: 3,
                time_limit: Duration::from_millis(200),
            },
            ..Settings::full()
        }
    }

    /// Seconds: small slabs and frames.
    pub fn tiny() -> Settings {
        Settings {
            size: (128, 72),
            uv: vec![2, 4],
            st: vec![16, 32],
            base: (4, 32),
            codewords: vec![16, 64],
            tiles: vec![[1, 1, 2, 2], [2, 2, 2, 2]],
            tile_codewords: 32,
            training_tiles: 1 << 10,
            resolutions: vec![(64, 36), (128, 72)],
            triangles: vec![500, 2_000],
            object_triangles: 2_000,
            photographs: vec![8],
            photo_size: 32,
            sparse_slab: (4, 16),
            frames: Frames {
                warmup: 0,
                frames: 2,
                time_limit: Duration::ZERO,
            },
        }
    }
}

/// One measured point.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// `density`, `st`, `codebook`, `tile`, `resolution`, `triangles` or `geometry`.
    pub series: &'static str,
    /// A lookup of [`LOOKUPS`], or `geometry`.
    pub method: &'static str,
    /// `between` or `away`, and the eye's index in [`EYES`].
    pub eye_class: &'static str,
    pub eye: usize,
    pub uv: u32,
    pub st: u32,
    /// Codewords and tile shape (quantised rows), else 0 and empty.
    pub codewords: u32,
    pub tile: String,
    pub triangles: u32,
    pub width: u32,
    pub height: u32,
    pub time: Summary,
    /// Against the geometry (geometry rows: none).
    pub error: Option<metrics::ImageError>,
    /// Coverage against the geometry's: pixels both cover over pixels either covers
    /// (alpha above 0; geometry rows: none).
    pub iou: Option<f64>,
    /// The light field's rays, samples read and pixels written in the last frame.
    pub rays: u64,
    pub taps: u64,
    pub pixels: u64,
    /// Bytes of the samples in memory, and the raw light field's.
    pub bytes: u64,
    pub raw_bytes: u64,
    /// Bytes of the light field's file, and of the raw one's.
    pub file_bytes: u64,
    pub raw_file_bytes: u64,
    /// Seconds to capture, and to train and encode (quantised rows).
    pub capture_s: f64,
    pub quantise_s: f64,
    /// Sparse rows: the photographs rebinned (0: the dense capture) and the fraction of
    /// samples pull-push invented.
    pub photographs: usize,
    pub invented: f64,
}

impl CsvRow for Row {
    const HEADER: &'static str = "series,method,eye_class,eye,uv,st,codewords,tile,triangles,width,height,frames,median_ms,min_ms,p90_ms,psnr_db,mse,compared,mean_abs,frac_over,rays,taps,pixels,bytes,raw_bytes,file_bytes,raw_file_bytes,capture_s,quantise_s,photographs,invented,iou";

    fn csv(&self) -> String {
        let e = self.error;
        let f = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{:.4},{},{},{},{},{},{},{},{},{},{},{},{},{:.3},{:.3},{},{:.4},{}",
            self.series,
            self.method,
            self.eye_class,
            self.eye,
            self.uv,
            self.st,
            self.codewords,
            self.tile,
            self.triangles,
            self.width,
            self.height,
            self.time.frames,
            self.time.median_ms,
            self.time.min_ms,
            self.time.p90_ms,
            f(e.map(|e| e.psnr_capped(99.0))),
            f(e.map(|e| e.mse)),
            e.map_or(String::new(), |e| e.pixels.to_string()),
            f(e.map(|e| e.mean_abs)),
            f(e.map(|e| e.frac_over)),
            self.rays,
            self.taps,
            self.pixels,
            self.bytes,
            self.raw_bytes,
            self.file_bytes,
            self.raw_file_bytes,
            self.capture_s,
            self.quantise_s,
            self.photographs,
            self.invented,
            f(self.iou),
        )
    }
}

/// The captured object: a lit torus, tilted, centred in the focal plane.
#[derive(Debug)]
pub struct Object {
    pub mesh: Mesh,
    pub material: Material,
    pub lighting: Lighting,
}

impl Object {
    pub fn torus(triangles: u32) -> Object {
        Object {
            mesh: procedural::torus_with_triangles(triangles),
            material: Material::lit(Rgba::new(0.8, 0.5, 0.3, 1.0)),
            lighting: lighting(),
        }
    }

    pub fn draw(&self) -> Draw<'_> {
        Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: Mat4::from_rotation_x(1.0) * Mat4::from_scale(Vec3::splat(0.75)),
        }
    }
}

/// The slab around the object: a 2.4-unit `uv` square at z = 4 and a 2.4-unit `st` square
/// through the object's centre, `uv` and `st` samples per side.
pub fn slab(uv: u32, st: u32) -> Slab {
    let square = |z: f32| Rect3::centered(Vec3::new(0.0, 0.0, z), Vec3::X * 2.4, Vec3::NEG_Y * 2.4);
    Slab::new(square(4.0), square(0.0), [uv, uv, st, st], 0.5, 20.0).expect("a valid slab")
}

/// The render-speed case (`examples/lightfield_frame.rs`, `benches/lightfield.rs`): a lit
/// torus (9,216 triangles) captured into a 32x32x256x256 slab (`uv` a 2-unit square 4 units
/// in front of it, `st` a 2.4-unit square through it), and a 1280x720 camera between the
/// capture cameras from which the slab fills most of the frame.
pub fn frame_case() -> (LightField, Camera) {
    let mesh = procedural::torus(0.7, 0.3, 96, 48);
    let material = Material::lit(Rgba::new(0.8, 0.5, 0.3, 1.0));
    let draws = [Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::from_rotation_x(1.0),
    }];
    let lighting = lighting();
    let square = |z: f32, size: f32| {
        Rect3::centered(Vec3::new(0.0, 0.0, z), Vec3::X * size, Vec3::NEG_Y * size)
    };
    let slab = Slab::new(
        square(4.0, 2.0),
        square(0.0, 2.4),
        [32, 32, 256, 256],
        0.5,
        20.0,
    )
    .expect("a valid slab");
    let (w, h) = FRAME_SIZE;
    let camera = Camera::look_at(
        Vec3::new(0.13, -0.07, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        0.62,
        w as f32 / h as f32,
    )
    .with_depth_range(0.1, 30.0);
    (LightField::capture(&draws, &lighting, slab), camera)
}

/// The torus's light: an ambient term and a directional light from above.
fn lighting() -> Lighting {
    Lighting {
        ambient: Rgba::new(0.3, 0.3, 0.3, 1.0),
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.4, -1.0, -0.6).normalize(),
            color: Rgba::new(0.9, 0.9, 0.9, 1.0),
        }],
    }
}

/// The size of [`frame_case`]'s frame.
pub const FRAME_SIZE: (u32, u32) = (1280, 720);

/// The camera at eye `k` of [`EYES`] for a `w` x `h` frame.
pub fn camera(k: usize, (w, h): (u32, u32)) -> Camera {
    Camera::look_at(Vec3::from(EYES[k].1), Vec3::ZERO, Vec3::Y, 0.62, 1.0)
        .with_aspect(w, h)
        .with_depth_range(0.1, 30.0)
}

fn clear() -> FrameOptions {
    FrameOptions {
        clear: Some(Rgba::TRANSPARENT),
        ..Default::default()
    }
}

/// Renders one frame: the object's geometry (`object` None) or the light field.
fn frame(
    draw: Draw<'_>,
    object: Option<&mut LightFieldObject>,
    cam: &Camera,
    lighting: &Lighting,
    renderer: &mut Renderer,
    frames: &mut FrameLoop,
    target: &mut Target,
) {
    let view = FrameView::still(cam, target.width(), target.height(), lighting);
    match object {
        Some(o) => {
            let mut list: [&mut dyn Technique; 1] = [o];
            frames.render(renderer, [], &mut list, &view, target, &clear());
        }
        None => {
            frames.render(renderer, [draw], &mut [], &view, target, &clear());
        }
    }
}

/// Measures frames; shared by every series.
struct Bench<'p> {
    settings: &'p Settings,
    renderer: Renderer,
    frames: FrameLoop,
}

/// What a measured point knows besides its frames.
#[derive(Clone, Default)]
struct Setting {
    uv: u32,
    st: u32,
    codewords: u32,
    tile: String,
    triangles: u32,
    raw_bytes: u64,
    file_bytes: u64,
    raw_file_bytes: u64,
    capture_s: f64,
    quantise_s: f64,
    photographs: usize,
    invented: f64,
}

impl Bench<'_> {
    /// Frame time and error of `field` (or of the geometry, `None`) at eye `k`.
    #[allow(clippy::too_many_arguments)]
    fn point(
        &mut self,
        series: &'static str,
        object: &Object,
        field: Option<(&'static str, &mut LightFieldObject)>,
        k: usize,
        size: (u32, u32),
        setting: &Setting,
    ) -> Row {
        let cam = camera(k, size);
        let draw = object.draw();
        let mut truth = Target::new(size.0, size.1);
        let (renderer, frames) = (&mut self.renderer, &mut self.frames);
        frame(
            draw,
            None,
            &cam,
            &object.lighting,
            renderer,
            frames,
            &mut truth,
        );
        let (method, mut field) = match field {
            Some((m, f)) => (m, Some(f)),
            None => ("geometry", None),
        };
        let mut target = Target::new(size.0, size.1);
        let times = self.settings.frames.run(|| {
            let t = Instant::now();
            frame(
                draw,
                field.as_deref_mut(),
                &cam,
                &object.lighting,
                renderer,
                frames,
                &mut target,
            );
            t.elapsed()
        });
        let (error, iou, last, bytes) = match &field {
            Some(f) => {
                let e = metrics::compare_covered(&target, &truth).expect("same size");
                (
                    Some(e),
                    Some(coverage_iou(&target, &truth)),
                    f.last(),
                    f.bytes() as u64,
                )
            }
            None => (None, None, Default::default(), 0),
        };
        Row {
            series,
            method,
            eye_class: EYES[k].0,
            eye: k,
            uv: setting.uv,
            st: setting.st,
            codewords: setting.codewords,
            tile: setting.tile.clone(),
            triangles: setting.triangles,
            width: size.0,
            height: size.1,
            time: Summary::of(&times),
            error,
            iou,
            rays: last.rays,
            taps: last.taps,
            pixels: last.pixels,
            bytes,
            raw_bytes: setting.raw_bytes,
            file_bytes: setting.file_bytes,
            raw_file_bytes: setting.raw_file_bytes,
            capture_s: setting.capture_s,
            quantise_s: setting.quantise_s,
            photographs: setting.photographs,
            invented: setting.invented,
        }
    }

    /// `field` drawn quadrilinear and depth-corrected at every eye.
    fn every_eye(
        &mut self,
        series: &'static str,
        object: &Object,
        field: LightField,
        setting: &Setting,
    ) -> Vec<Row> {
        let mut o = LightFieldObject::new("torus", field);
        o.lookup = Lookup::default();
        (0..EYES.len())
            .map(|k| {
                let m = Some(("quadrilinear-dc", &mut o));
                self.point(series, object, m, k, self.settings.size, setting)
            })
            .collect()
    }

    /// Every lookup at every eye.
    fn lookups(
        &mut self,
        series: &'static str,
        object: &Object,
        field: LightField,
        setting: &Setting,
    ) -> Vec<Row> {
        let mut o = LightFieldObject::new("torus", field);
        let mut rows = Vec::new();
        for (name, interpolation, depth_correction) in LOOKUPS {
            o.lookup = Lookup {
                interpolation,
                depth_correction,
            };
            for k in 0..EYES.len() {
                let size = self.settings.size;
                rows.push(self.point(series, object, Some((name, &mut o)), k, size, setting));
            }
        }
        rows
    }
}

/// Pixels both frames cover (alpha above 0) over pixels either covers (1 when neither
/// covers any).
pub fn coverage_iou(a: &Target, b: &Target) -> f64 {
    let (a, b) = (a.to_rgba8_premultiplied(), b.to_rgba8_premultiplied());
    let (mut both, mut either) = (0u64, 0u64);
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let (x, y) = (p[3] > 0, q[3] > 0);
        both += u64::from(x && y);
        either += u64::from(x || y);
    }
    if either == 0 {
        1.0
    } else {
        both as f64 / either as f64
    }
}

/// Photograph `k` of `n` of the sparse capture: a hand-held-like wander over and around
/// the camera plane (a spiral out to its edges, drifting toward and away from the
/// object), looking at the object's centre.
fn wander(k: usize, n: usize) -> Camera {
    let f = k as f32 / n.max(1) as f32;
    let a = k as f32 * 2.399_963; // the golden angle: evenly spread
    let r = 1.3 * f.sqrt();
    let eye = Vec3::new(r * a.cos(), r * a.sin(), 4.0 + 0.5 * (a * 0.37).sin());
    Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.8, 1.0).with_depth_range(0.1, 30.0)
}

/// Captures `object` through `slab`, timed.
fn capture(object: &Object, slab: Slab) -> (LightField, f64) {
    let start = Instant::now();
    let lf = LightField::capture(&[object.draw()], &object.lighting, slab);
    (lf, start.elapsed().as_secs_f64())
}

/// The size of `lf` saved, in a scratch folder.
fn file_size(lf: &LightField, name: &str) -> u64 {
    let dir = std::env::temp_dir().join(format!("parallax-bench-lf-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(name);
    let size = lf
        .save(&path)
        .ok()
        .and_then(|()| std::fs::metadata(&path).ok())
        .map_or(0, |m| m.len());
    let _ = std::fs::remove_file(&path);
    size
}
