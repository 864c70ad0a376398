//! The showcase's light-field statue: a bronze urn on a column at the edge of the plaza,
//! captured at start-up into five light slabs on a cube around it (every side and the
//! top) and drawn from them ([`ibr::lightfield::LightFieldObject`]) with its outline and
//! depth from its geometry ([`LightFieldObject::proxy_outline`]: the light field gives the
//! colour inside, the geometry's coverage the outline, the light field's error before);
//! where no slab sees it whole (the eye too near)
//! or it is smaller on screen than [`MIN_PX`] (too far) its geometry is drawn instead,
//! and the readout says so. The readout gives its memory,
//! its compression ratio and its error against a render of its geometry from the same eye
//! ([`Statue::measure`]).
//!
//! A light field is a static object's light: the statue is captured under the scene's
//! static lights (the sun and the ambient term), so the orbiting lamp does not light it,
//! and its geometry, when drawn, is lit the same way.

use super::ibr_layer::bake_lighting;
use engine::procedural;
use engine::{Camera, FrameOptions, Lighting, Material, Mesh, Renderer, Rgba, Shading};
use engine::{Draw, Target};
use glam::{Mat4, Vec2, Vec3};
use ibr::lightfield::{LightField, LightFieldObject, Showing, Slab, TileShape, VqSettings};
use ibr::metrics::{self, ImageError};
use ibr::subject::{MeshGroup, Subject};
use ibr::technique::{FrameLoop, FrameView, Technique};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Where the statue stands (the centre of its base).
pub const STATUE_AT: Vec3 = Vec3::new(1.9, 0.0, -4.4);
/// Samples of each slab: `uv` cameras per side and `st` samples per side. With the outline
/// from geometry, measured over the tour at 640x360 (the showcase's measure, BENCHMARKS.md
/// "the light-field statue (issue 39, session 11)"), raw slabs: `uv` 4, 6, 8, 16 gave
/// 32.7 / 30.1, 33.2 / 27.9, 33.9 / 30.6, 33.9 / 30.5 dB mean / worst (16, 37, 66, 262
/// MB): 8, the most that gains. (Without the outline, `st` 96 gave 20.3 dB mean at 320 x
/// 180, 160 21.7.)
pub const UV: u32 = 8;
pub const ST: u32 = 160;
/// Codewords of the statue's vector quantiser (one codebook per slab) when it is quantised
/// ([`StatueSettings::codewords`]; the showcase keeps its 8 x 8 slabs raw, 66 MB, with no
/// quantiser at start-up), and the tiles it trains on. Measured over the tour at 640x360
/// with the outline from geometry, 16 x 16 slabs: 4096 codewords on 65,536 tiles 31.9 /
/// 27.5 dB (6.7 MB, the quantiser 5 s quiet), 1024 on 16,384 30.7 / 27.0; without it
/// (session 10, "light-field statue's error by cause"): raw 23.1 / 20.1, 4096 21.9 /
/// 19.7.
pub const CODEWORDS: u32 = 4096;
/// Tiles the quantiser trains on.
pub const TRAINING_TILES: usize = 1 << 16;
/// Under this many pixels of projected diameter the statue is drawn as its geometry
/// ([`LightFieldObject::min_px`]): its `ST` samples are then more than six to a pixel
/// and its outline most of it (at 320x180 the tour's worst frame, the statue 12 pixels
/// tall at the frame's edge, measured 15.9 dB), for a few hundred triangles.
pub const MIN_PX: f32 = 24.0;

/// The light-field statue, its geometry and what it measured.
#[derive(Debug)]
pub struct Statue {
    pub object: LightFieldObject,
    /// The static lighting it was captured under (its geometry is drawn under it too).
    pub lighting: Lighting,
    /// Bytes the five slabs' raw samples (colour and depth) would take.
    pub raw_bytes: usize,
    /// Codewords it was quantised to (`None`: raw samples).
    pub codewords: Option<u32>,
    /// Time spent capturing and quantising at start-up.
    pub capture: Duration,
    pub quantise: Duration,
    /// The last measured error against geometry, and all of them so far.
    pub error: Option<ImageError>,
    pub errors: Vec<ImageError>,
    measure: Measure,
}

/// The memory [`Statue::measure`] renders with, reused.
#[derive(Debug)]
struct Measure {
    renderer: Renderer,
    frames: FrameLoop,
    truth: Target,
    image: Target,
}

/// How the statue's light field is sampled and stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StatueSettings {
    /// `uv` cameras per side of each slab.
    pub uv: u32,
    /// `st` samples per side of each slab.
    pub st: u32,
    /// Codewords of the vector quantiser; `None` (the showcase's) keeps the raw samples.
    pub codewords: Option<u32>,
    /// The quantiser's tile (samples along `u, v, s, t` a codeword holds).
    pub tile: TileShape,
    /// Tiles the quantiser trains on, and its Lloyd iterations.
    pub training_tiles: usize,
    pub iterations: u32,
    /// Sub-samples per `st` sample along each side at capture (the coverage of outlines,
    /// [`LightField::capture_supersampled`]); above 1 the light field is drawn with hard
    /// edges ([`LightFieldObject::hard_edges`]). Raw slabs gain from it (23.1 / 20.1 dB
    /// without, 25.3 / 20.8 with 4 x 4 at sixteen times the capture), quantised ones do
    /// not (the codewords blur the coverage: with 1024 codewords 21.2 / 18.6 at 4 x 4,
    /// 21.1 / 18.7 without): 1.
    pub supersample: u32,
    /// The outline from geometry ([`LightFieldObject::proxy_outline`]).
    pub outline: bool,
}

impl Default for StatueSettings {
    fn default() -> Self {
        StatueSettings {
            uv: UV,
            st: ST,
            codewords: None,
            tile: TileShape::LEVOY,
            training_tiles: TRAINING_TILES,
            iterations: 4,
            supersample: 1,
            outline: true,
        }
    }
}

impl Statue {
    /// Captures the statue under the static part of `lighting` (directional lights and the
    /// ambient term) and quantises it.
    pub fn new(lighting: &Lighting) -> Statue {
        Statue::with_settings(lighting, StatueSettings::default())
    }

    /// [`Statue::new`] sampled and stored as `settings` says.
    pub fn with_settings(lighting: &Lighting, settings: StatueSettings) -> Statue {
        let StatueSettings {
            uv,
            st,
            codewords,
            tile,
            training_tiles,
            iterations,
            supersample,
            outline,
        } = settings;
        // Captured once, so under the lights that do not move, as the forest's views are.
        let lighting = bake_lighting(lighting);
        let geometry = urn(STATUE_AT);
        let bounds = geometry.bounds();
        let start = Instant::now();
        let mut draws = Vec::new();
        geometry.draws(&mut draws);
        let slabs = Slab::cube(bounds.center, bounds.radius, [uv, uv, st, st])
            .expect("a sphere of positive radius");
        // No slab from below: the eye never goes under the plaza.
        let raw: Vec<LightField> = slabs
            .iter()
            .filter(|s| s.forward().y < 0.5)
            .map(|s| LightField::capture_supersampled(&draws, &lighting, *s, supersample))
            .collect();
        let capture = start.elapsed();
        let raw_bytes = raw.iter().map(LightField::bytes).sum();
        let start = Instant::now();
        let slabs: Vec<LightField> = match codewords {
            Some(codewords) => {
                let settings = VqSettings {
                    tile,
                    codewords,
                    training_tiles,
                    iterations,
                };
                raw.iter()
                    .map(|f| f.quantise(&settings).expect("valid settings").0)
                    .collect()
            }
            None => raw,
        };
        let quantise = start.elapsed();
        let mut object = LightFieldObject::with_slabs("light-field statue", slabs, bounds);
        object.reference = Some(geometry);
        // Depth correction leaves one-pixel cracks where one surface passes in front of
        // another (no camera finds the surface there): filled from the nearer side (on the
        // armillary sphere this replaced, 20.4 / 18.5 dB mean / worst over the tour at
        // 640x360 against 19.8 / 18.0 unfilled).
        object.fill_cracks = true;
        object.hard_edges = supersample > 1;
        object.min_px = MIN_PX;
        object.proxy_outline = outline;
        Statue {
            object,
            lighting,
            raw_bytes,
            codewords,
            capture,
            quantise,
            error: None,
            errors: Vec::new(),
            measure: Measure {
                renderer: Renderer::new(),
                frames: FrameLoop::new(),
                truth: Target::new(0, 0),
                image: Target::new(0, 0),
            },
        }
    }

    /// How it is stored and how long that took at start-up, for the summary: "vector-quantised
    /// (N codewords) in S s" or "kept raw".
    pub fn storage(&self) -> String {
        match self.codewords {
            Some(n) => format!(
                "vector-quantised ({n} codewords) in {:.2} s",
                self.quantise.as_secs_f64()
            ),
            None => "kept raw (no quantiser)".to_string(),
        }
    }

    /// Memory the light field holds now (raw samples, or codebooks and indices).
    pub fn bytes(&self) -> usize {
        self.object.bytes()
    }

    /// Raw samples over what is held.
    pub fn ratio(&self) -> f64 {
        self.raw_bytes as f64 / self.bytes().max(1) as f64
    }

    /// Measures the last frame's light-field image against its geometry from the same
    /// eye: both rendered alone into the screen rectangle the image covered (a crop of
    /// `camera`'s `width` x `height` view) and compared over the pixels either covers.
    /// `None` (and nothing measured) when the last frame showed no light field.
    pub fn measure(&mut self, camera: &Camera, width: u32, height: u32) -> Option<ImageError> {
        self.error = None;
        let rect = self.object.rect()?;
        let (w, h) = (rect.x1 - rect.x0, rect.y1 - rect.y0);
        let lo = Vec2::new(rect.x0 as f32, rect.y0 as f32);
        let hi = Vec2::new(rect.x1 as f32, rect.y1 as f32);
        let crop = camera.crop(lo, hi, width, height);
        let view = FrameView::still(&crop, w, h, &self.lighting);
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..Default::default()
        };
        let m = &mut self.measure;
        for t in [&mut m.truth, &mut m.image] {
            if t.width() != w || t.height() != h {
                *t = Target::new(w, h);
            }
        }
        let mut draws: Vec<Draw<'_>> = Vec::new();
        self.object.reference(&mut draws);
        m.frames
            .render(&mut m.renderer, draws, &mut [], &view, &mut m.truth, &opts);
        let mut list: [&mut dyn Technique; 1] = [&mut self.object];
        m.frames
            .render(&mut m.renderer, [], &mut list, &view, &mut m.image, &opts);
        let e = metrics::compare_covered(&m.image, &m.truth).ok()?;
        self.errors.push(e);
        self.error = Some(e);
        self.error
    }

    /// The on-screen line (upper case, for the bitmap font): what it showed, its memory and
    /// ratio, and the last measured PSNR against geometry.
    pub fn line(&self) -> String {
        let showing = match self.object.showing() {
            Showing::Slab(k) => format!("SLAB {k}"),
            Showing::Geometry => "GEOMETRY".to_string(),
            Showing::Nothing => "OFF".to_string(),
        };
        let error = match self.error {
            Some(e) => format!("{:.1} DB", e.psnr_capped(99.0)),
            None => "-".to_string(),
        };
        format!(
            "LIGHT FIELD {showing}  {:.1} MB ({:.0}:1)  ERR {error}",
            self.bytes() as f64 / 1e6,
            self.ratio()
        )
    }
}

/// The statue's geometry standing at `at`: a stone plinth and column carrying a large
/// bronze urn, a smooth solid of revolution (no thin parts, no surface hiding another:
/// every ray meets it once and its outline is wide and smooth), about 3 units tall, all
/// matte. It replaced an armillary sphere (three rings round a globe), whose rings passed
/// in front of each other, ghosted between cameras and cracked where no camera found
/// the surface: 20.4 / 18.5 dB mean / worst over the tour at 640x360, the urn 21.1 / 18.7.
/// (Matte: a light field with depth correction carries a diffuse surface exactly between
/// its cameras, a highlight only as well as its camera spacing samples it; polished
/// metals measured 16.9 / 10.9 dB on the rings, matte 20.3 / 16.4.)
pub fn urn(at: Vec3) -> MeshGroup {
    let material = |color: Rgba| {
        Arc::new(Material {
            shading: Shading::Lit {
                specular: 0.0,
                shininess: 8.0,
            },
            ..Material::lit(color)
        })
    };
    let plain = |mut m: Mesh| {
        m.colors.clear();
        Arc::new(m)
    };
    let stone = material(Rgba::from_srgb8(168, 160, 148));
    let bronze = material(Rgba::from_srgb8(170, 110, 60));
    MeshGroup::new()
        .with(
            plain(procedural::cuboid(Vec3::new(0.9, 0.3, 0.9))),
            stone.clone(),
            Mat4::from_translation(at + Vec3::Y * 0.15),
        )
        .with(
            plain(procedural::cylinder(0.14, 1.2, 24)),
            stone,
            Mat4::from_translation(at + Vec3::Y * 0.3),
        )
        .with(
            Arc::new(urn_mesh(48, 40)),
            bronze,
            Mat4::from_translation(at + Vec3::Y * 1.45),
        )
}

/// The urn's profile: its radius at height `t` of 1.6 units (0 at the foot, 1 at the
/// lip), closed at both ends: a foot, a round body and a narrow neck flaring to the lip.
fn urn_radius(t: f32) -> f32 {
    use std::f32::consts::PI;
    let body = 0.62 * (PI * (t / 0.8).min(1.0)).sin().max(0.0).powf(0.8);
    let neck = 0.2 + 0.12 * ((t - 0.8) / 0.2).clamp(0.0, 1.0).powi(2);
    let r = body.max(neck);
    // Closed: a foot of 0.25 rounded in over the first and last few hundredths.
    let ends = (t / 0.03).min((1.0 - t) / 0.03).clamp(0.0, 1.0);
    r.max(0.25 * ends) * ends.sqrt()
}

/// The urn as a mesh: `rows` rings of `segments` vertices along [`urn_radius`], normals
/// from the profile's slope (smooth all round).
fn urn_mesh(segments: u32, rows: u32) -> Mesh {
    let (segments, rows) = (segments.max(3), rows.max(2));
    let height = 1.6;
    let at = |j: u32| {
        let t = j as f32 / rows as f32;
        (urn_radius(t), t * height)
    };
    let mut mesh = Mesh::default();
    for j in 0..=rows {
        let (r, y) = at(j);
        let (r0, y0) = at(j.saturating_sub(1));
        let (r1, y1) = at((j + 1).min(rows));
        // Outward normal of the profile (dr, dy) in the (radius, height) plane.
        let (nr, ny) = (y1 - y0, -(r1 - r0));
        let len = (nr * nr + ny * ny).sqrt().max(1e-6);
        let (nr, ny) = (nr / len, ny / len);
        for i in 0..=segments {
            let th = std::f32::consts::TAU * i as f32 / segments as f32;
            let (sn, cs) = th.sin_cos();
            mesh.positions.push(Vec3::new(cs * r, y, -sn * r));
            mesh.normals
                .push(Vec3::new(cs * nr, ny, -sn * nr).normalize_or_zero());
            mesh.uvs.push(Vec2::new(
                i as f32 / segments as f32,
                1.0 - j as f32 / rows as f32,
            ));
        }
    }
    let stride = segments + 1;
    for j in 0..rows {
        for i in 0..segments {
            let a = j * stride + i;
            let (b, c, d) = (a + 1, a + 1 + stride, a + stride);
            mesh.indices.extend_from_slice(&[a, b, c, a, c, d]);
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::showcase::{camera, Showcase, SKY};

    /// The statue in the showcase: drawn from its light field from the plaza's edge, close
    /// to its geometry, within its memory;
    /// from near it, drawn as geometry and saying so.
    #[test]
    fn the_statue_is_drawn_from_its_light_field_and_measured_against_its_geometry() {
        let mut show = Showcase::new();
        let (w, h) = (320, 180);
        let mut renderer = Renderer::new();
        let mut target = Target::new(w, h);
        let opts = FrameOptions {
            clear: Some(SKY),
            ..Default::default()
        };
        let centre = STATUE_AT + Vec3::Y * 1.5;
        // From across the plaza, as the tour sees it: one of the five slabs.
        let far = camera(centre + Vec3::new(-6.0, 4.0, 12.0), centre, w, h);
        show.render(&mut renderer, &far, &mut target, &opts);
        let statue = &mut show.ibr.statue;
        assert!(matches!(statue.object.showing(), Showing::Slab(_)));
        let e = statue
            .measure(&far, w, h)
            .expect("a light-field image to measure");
        assert!(e.pixels > 200, "{} pixels compared", e.pixels);
        assert!(
            e.psnr_db > 14.0,
            "PSNR {:.1} dB against the geometry",
            e.psnr_db
        );
        // Held raw, within the memory the showcase allows it (8 x 8 x 160 x 160 samples of
        // colour and depth on five slabs).
        assert!(statue.bytes() <= 100 << 20, "{} bytes", statue.bytes());
        assert!(statue.line().contains("SLAB"), "{}", statue.line());
        // Within its bounding sphere no slab sees it whole: its geometry is drawn, and the
        // readout says so.
        let near = camera(centre + Vec3::new(0.6, 0.2, 0.8), centre, w, h);
        show.render(&mut renderer, &near, &mut target, &opts);
        let statue = &mut show.ibr.statue;
        assert_eq!(statue.object.showing(), Showing::Geometry);
        assert!(statue.measure(&near, w, h).is_none());
        assert!(statue.line().contains("GEOMETRY"), "{}", statue.line());
        let c = show.ibr.counters();
        assert_eq!(c[4].geometry, 1, "{c:?}");
    }

    /// The statue alone on a transparent `w` x `h` frame from `camera`: its light-field
    /// image's error against its geometry (over the pixels either covers) and the two as
    /// 8-bit RGBA (`None` when no slab showed it).
    fn alone(statue: &mut Statue, camera: &Camera, w: u32, h: u32) -> Option<Shown> {
        let view = FrameView::still(camera, w, h, &statue.lighting);
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..Default::default()
        };
        let (mut renderer, mut frames) = (Renderer::new(), FrameLoop::new());
        let (mut image, mut truth) = (Target::new(w, h), Target::new(w, h));
        let mut list: [&mut dyn Technique; 1] = [&mut statue.object];
        frames.render(&mut renderer, [], &mut list, &view, &mut image, &opts);
        if !matches!(statue.object.showing(), Showing::Slab(_)) {
            return None;
        }
        let mut draws: Vec<Draw<'_>> = Vec::new();
        statue.object.reference(&mut draws);
        frames.render(&mut renderer, draws, &mut [], &view, &mut truth, &opts);
        let e = metrics::compare_covered(&image, &truth).ok()?;
        Some((e, [image.to_rgba8(), truth.to_rgba8()]))
    }

    type Shown = (ImageError, [Vec<u8>; 2]);

    /// Sum of the absolute colour change between two frames over the pixels either
    /// covers, and those pixels.
    fn change(a: &[u8], b: &[u8]) -> (u64, u64) {
        let mut sum = 0;
        let mut n = 0;
        for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
            if p[3] > 0 || q[3] > 0 {
                sum += (0..3).map(|c| u64::from(p[c].abs_diff(q[c]))).sum::<u64>();
                n += 1;
            }
        }
        (sum, n)
    }

    /// The statue over the showcase tour at `w` x `h` (`n` frames): its light-field image
    /// against its geometry from the same eye on every frame a slab shows it; the mean and
    /// worst PSNR and the flicker (mean absolute frame-to-frame change of its image over
    /// the same of its geometry, over consecutive frames both drawn from the light field).
    pub(crate) fn tour_error(w: u32, h: u32, n: usize) -> (f64, f64, f64, usize) {
        tour_error_with(StatueSettings::default(), w, h, n)
    }

    fn tour_error_with(
        settings: StatueSettings,
        w: u32,
        h: u32,
        n: usize,
    ) -> (f64, f64, f64, usize) {
        let show = Showcase::new();
        let mut statue = Statue::with_settings(&show.scene.lighting, settings);
        let (mut psnr, mut worst, mut frames) = (0.0, f64::INFINITY, 0);
        let (mut moved, mut moved_truth) = (0u64, 0u64);
        let mut last: Option<[Vec<u8>; 2]> = None;
        for i in 0..n {
            let (eye, look) = show.path(i, n);
            let cam = camera(eye, look, w, h);
            let now = alone(&mut statue, &cam, w, h);
            if let Some((e, [image, truth])) = &now {
                if e.pixels > 0 {
                    let db = e.psnr_capped(99.0);
                    psnr += db;
                    worst = f64::min(worst, db);
                    frames += 1;
                }
                if let Some([was, was_truth]) = &last {
                    moved += change(image, was).0;
                    moved_truth += change(truth, was_truth).0;
                }
            }
            last = now.map(|n| n.1);
        }
        let flicker = moved as f64 / moved_truth.max(1) as f64;
        (psnr / frames.max(1) as f64, worst, flicker, frames)
    }

    /// Over the tour at 320 x 180, the statue drawn from its light field is close to its
    /// geometry on every frame and flickers no more than it (within 1.5 times).
    #[test]
    fn over_the_tour_the_statue_matches_its_geometry_and_does_not_flicker() {
        let (mean, worst, flicker, frames) = tour_error(320, 180, 120);
        eprintln!("statue over the tour: {frames} frames, PSNR mean {mean:.1} dB, worst {worst:.1} dB, flicker {flicker:.2}");
        assert!(frames >= 10, "{frames} frames from the light field");
        // Measured 33.7 dB mean, 30.1 worst over 54 frames with the outline from geometry
        // and raw 8 x 8 slabs (24.7 and 21.0 without it, 4096 codewords, session 10; the
        // polished, thin-ringed statue before: 16.9 and 10.9); the goal is 30 / 25.
        assert!(mean >= 32.0, "mean PSNR {mean:.1} dB");
        assert!(worst >= 28.5, "worst PSNR {worst:.1} dB");
        assert!(flicker <= 1.5, "flicker {flicker:.2}");
    }
}
