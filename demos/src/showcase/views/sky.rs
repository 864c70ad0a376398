//! The views moment's panorama sky: what a panorama carries, the land far beyond the
//! plaza's scene (a ring of mountains 650 to 1,200 units away, [`FarLand`], where the
//! scene's own terrain, trees and hills end at about 85), captured from above the plaza
//! into a cube map ([`ibr::panorama::Sky`]) and drawn behind the near scene (the whole of
//! the plaza's scene, drawn as geometry) while the eye walks away from the capture point.
//! A re-capture is spread two faces a frame, started where the eye will be when the held
//! panorama's predicted parallax passes [`SKY_TOLERANCE_PX`], and swapped in whole then.
//! The ring lies within about 12 degrees of the horizon: the cube's top and bottom faces
//! can show none of it and are not rendered (session 12), four faces a capture, and of
//! those only the rows round the horizon the ring can cover (session 13: 0.45 of 3.1
//! million pixels a frame at 1280x720), into faces whose storage is made at loading.
//! Each frame is measured against the whole geometry (scene and far land) from the same
//! eye, over the pixels the panorama fills.
//!
//! (Until session 11 the panorama held the scene beyond 10 units, the trees and hills 60
//! units away with sharp outlines against the sky: 23.5 / 20.6 dB mean / worst at 640x360,
//! resampling and parallax at their outlines. A panorama is a skybox: what is truly far.)

use super::{db, in_view, over_sky, over_sky_pixel, triangles, world_spheres, Frame, Stages};
use crate::showcase::{self, attractions, SKY};
use crate::timing::Usage;
use engine::color::{unpack, Encoder, Encoding};
use engine::procedural::value_noise;
use engine::{Camera, Draw, Lighting, Material, Mesh, Premul, Rgba, Shading, Sphere, Target};
use glam::{Mat4, Quat, Vec3};
use ibr::capture::Capturer;
use ibr::images::DepthImage;
use ibr::metrics::{self, Image, ImageError, Options, Region};
use ibr::panorama::{Behind, Sky};
use rayon::prelude::*;
use std::time::Instant;

/// The panorama holds what lies farther than this from where it was captured (along each
/// cube face's axis): the far land, beyond the plaza's scene and its cameras' far plane.
pub const SPLIT: f32 = 300.0;
/// The far end of the panorama's captures and of the geometry it is measured against.
const LAND_FAR: f32 = 2000.0;
/// Where the first panorama is captured: above the plaza's southern edge, looking north
/// over it.
pub const SKY_CENTRE: Vec3 = Vec3::new(0.0, 3.0, 7.0);
/// The panorama is captured again when its predicted parallax passes this many pixels.
pub const SKY_TOLERANCE_PX: f32 = 3.0;
/// Faces of a re-capture taken a frame: two frames for the four that show the far land,
/// which the headless run's four sky frames leave room for.
const FACES_PER_FRAME: usize = 2;
/// The eye's walk: as far as would make the first panorama this many tolerances wrong, so
/// every image size sees the same re-capture: at the walk's end, where the held
/// panorama's parallax passes the tolerance, begun a frame before where the headless
/// run's four sky frames step a third of the walk each.
const SKY_WALK_TOLERANCES: f32 = 1.25;

/// The far land: a ring of mountains round the plaza, far beyond its scene, one mesh.
#[derive(Debug)]
pub(super) struct FarLand {
    mesh: Mesh,
    material: Material,
}

impl FarLand {
    /// Azimuth steps round the ring and rows from each mountain's foot to its ridge.
    const STEPS: u32 = 256;
    const ROWS: u32 = 6;

    /// The ring: ridges 650 to 1,200 units away and 25 to 135 high, feet 60 below the
    /// ground's level 200 units nearer, coloured hazy green to blue-grey by height (the
    /// haze of the air between), snow on the highest. Deterministic.
    pub(super) fn new() -> FarLand {
        let ring = |theta: f32, scale: f32, seed: u64| {
            let (x, z) = (theta.cos() * scale, theta.sin() * scale);
            let mut sum = 0.0;
            let (mut amp, mut f, mut norm) = (1.0, 1.0, 0.0);
            for octave in 0..4u64 {
                sum += amp * value_noise(x * f + 50.0, z * f + 50.0, seed + octave * 31);
                norm += amp;
                amp *= 0.5;
                f *= 2.0;
            }
            sum / norm
        };
        let haze = |c: Rgba, k: f32| {
            Rgba::new(
                c.r + (SKY.r - c.r) * k,
                c.g + (SKY.g - c.g) * k,
                c.b + (SKY.b - c.b) * k,
                1.0,
            )
        };
        let (low, high, snow) = (
            Rgba::from_srgb8(70, 104, 70),
            Rgba::from_srgb8(108, 112, 128),
            Rgba::from_srgb8(236, 240, 246),
        );
        let mut mesh = Mesh::default();
        let (n, rows) = (Self::STEPS, Self::ROWS);
        for i in 0..n {
            let theta = i as f32 / n as f32 * std::f32::consts::TAU;
            let ridge_r = 650.0 + 550.0 * ring(theta, 2.0, 11);
            let height = 25.0 + 110.0 * ring(theta, 5.0, 23).powf(1.5);
            let (foot_r, foot_y) = (ridge_r - 200.0, -60.0);
            for j in 0..=rows {
                let s = j as f32 / rows as f32;
                let r = foot_r + (ridge_r - foot_r) * s;
                let y = foot_y + (height - foot_y) * (1.0 - (1.0 - s) * (1.0 - s));
                mesh.positions
                    .push(Vec3::new(theta.sin() * r, y, -theta.cos() * r));
                let up = ((y + 20.0) / 130.0).clamp(0.0, 1.0);
                let mut c = Rgba::new(
                    low.r + (high.r - low.r) * up,
                    low.g + (high.g - low.g) * up,
                    low.b + (high.b - low.b) * up,
                    1.0,
                );
                if y > 95.0 {
                    let k = ((y - 95.0) / 20.0).clamp(0.0, 1.0);
                    c = Rgba::new(
                        c.r + (snow.r - c.r) * k,
                        c.g + (snow.g - c.g) * k,
                        c.b + (snow.b - c.b) * k,
                        1.0,
                    );
                }
                mesh.colors.push(haze(c, 0.35 + 0.15 * (r - 450.0) / 750.0));
            }
        }
        let stride = rows + 1;
        for i in 0..n {
            let (a, b) = (i * stride, (i + 1) % n * stride);
            for j in 0..rows {
                // Facing the centre (counter-clockwise seen from inside the ring).
                mesh.indices
                    .extend([a + j, b + j, a + j + 1, b + j, b + j + 1, a + j + 1]);
            }
        }
        mesh.compute_normals();
        let material = Material {
            shading: Shading::Lit {
                specular: 0.0,
                shininess: 8.0,
            },
            ..Material::lit(Rgba::WHITE)
        };
        FarLand { mesh, material }
    }

    /// The ring as a draw.
    pub(super) fn draw(&self) -> Draw<'_> {
        Draw {
            mesh: &self.mesh,
            material: &self.material,
            transform: Mat4::IDENTITY,
        }
    }
}

/// What the sky part showed in one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SkyFrame {
    /// The predicted parallax of the panorama drawn (pixels; 0 right after a capture).
    pub predicted_px: f32,
    /// The prediction for the panorama held before the frame, which decided re-capturing.
    pub before_px: f32,
    /// Whether a re-capture was completed and swapped in this frame.
    pub recaptured: bool,
    /// Faces of a re-capture taken this frame, and their pixels rendered (the rows of each
    /// that can show the far land).
    pub faces: usize,
    pub face_px: u64,
    /// Captures so far (the first included).
    pub captures: u32,
    /// The share of the frame's pixels the panorama fills: what the near scene leaves and
    /// the far scene (in the panorama or the geometry) covers; open sky left out.
    pub far_share: f64,
    /// The error over those pixels against the whole geometry from the same eye.
    pub error: Option<ImageError>,
    /// Pixels the geometry covers that neither the near scene nor the panorama fills.
    pub unfilled: u64,
    /// The near scene's triangles drawn (of the draws whose bounding sphere the view
    /// reaches), of all of its triangles (a work counter).
    pub near_triangles: usize,
    pub triangles: usize,
    /// The panorama's lookups made behind the near scene, of the pixels it left empty
    /// (work counters: those past the elevations the panorama holds anything at are not
    /// looked up; all were until session 18).
    pub lookups: u64,
    pub empty: u64,
}

impl SkyFrame {
    /// The readout line (upper case, for the bitmap font): the parallax the re-capture
    /// decision acted on (the held panorama's, before the frame), and the one drawn after
    /// a re-capture.
    pub fn line(&self) -> String {
        let f = self;
        format!(
            "PANORAMA SKY  PARALLAX {:.1} PX (TOL {:.0})  FAR {:.0}% OF FRAME: {}, {:.0}% WRONG  \
             NEAR {:.1}K OF {:.1}K TRIANGLES  LOOKUPS {:.2} OF {:.2} MPX  CAPTURES {}{}",
            f.before_px,
            SKY_TOLERANCE_PX,
            100.0 * f.far_share,
            db(f.error),
            100.0 * f.error.map_or(0.0, |e| e.frac_over),
            f.near_triangles as f64 * 1e-3,
            f.triangles as f64 * 1e-3,
            f.lookups as f64 * 1e-6,
            f.empty as f64 * 1e-6,
            f.captures,
            if f.recaptured {
                format!("  RE-CAPTURED, NOW {:.1} PX", f.predicted_px)
            } else if f.faces > 0 {
                format!(
                    "  CAPTURING AHEAD, {} FACES ({:.2} MPX)",
                    f.faces,
                    f.face_px as f64 * 1e-6
                )
            } else {
                String::new()
            }
        )
    }
}

/// Focal length in pixels of `camera` for an image `width` wide.
fn focal_px(camera: &Camera, width: u32) -> f32 {
    camera.projection.gl_matrix().x_axis.x * 0.5 * width as f32
}

/// The panorama sky, its walk and the images each frame reuses.
#[derive(Debug)]
pub(super) struct SkyPart {
    pub(super) sky: Sky,
    land: FarLand,
    width: u32,
    height: u32,
    focal: f32,
    /// Length of the eye's walk from the first capture point.
    walk: f32,
    /// The walk's fraction at the last frame: the step to the next is taken as the last.
    last_t: Option<f32>,
    capturer: Capturer,
    /// The near scene's draws' bounding spheres ([`world_spheres`]), made once.
    spheres: Vec<Sphere>,
    /// What each pixel of the last frame shows ([`NEAR`], [`FAR`] or [`NOTHING`]).
    kinds: Vec<u8>,
    /// The whole geometry from the frame's eye.
    truth: DepthImage,
    truth_rgba: Vec<u8>,
    mask: Vec<bool>,
}

impl SkyPart {
    /// The part for `w` x `h` frames; the panorama holds the far land, not `draws` (the
    /// plaza's scene, drawn as geometry). The near scene is rendered once from the walk's
    /// first eye, so that the capturer's target is made at loading, not in the first
    /// frame (a fifth of its time, in page faults).
    pub(super) fn new(draws: &[Draw<'_>], lighting: &Lighting, w: u32, h: u32) -> SkyPart {
        let mut part = SkyPart::with_tolerance(lighting, w, h, SKY_TOLERANCE_PX);
        part.spheres = world_spheres(draws);
        let (eye, at) = part.pose(0.0);
        let camera = showcase::camera(eye, at, w, h);
        let cap = &mut part.capturer;
        cap.render(
            draws.iter().copied(),
            &camera,
            lighting,
            w,
            h,
            Encoding::Srgb,
        );
        part
    }

    /// With a tolerance other than [`SKY_TOLERANCE_PX`] (the tests' small images walk as
    /// far as the showcase's at the same tolerances).
    pub(super) fn with_tolerance(
        lighting: &Lighting,
        w: u32,
        h: u32,
        tolerance_px: f32,
    ) -> SkyPart {
        let focal = focal_px(&showcase::camera(SKY_CENTRE, Vec3::NEG_Z, w, h), w);
        // At least a texel per pixel of the view: half a face spans the focal length.
        // (512 at most until session 11: 0.4 texels per pixel at 1280x720.)
        let size = ((2.0 * focal).ceil() as u32).clamp(64, 1536);
        let land = FarLand::new();
        let mut sky = Sky::new(
            &[land.draw()],
            lighting,
            SKY_CENTRE,
            size,
            (SPLIT, LAND_FAR),
            tolerance_px,
        )
        .spread(FACES_PER_FRAME);
        // The re-capture's faces' storage made now, at loading, not in a frame.
        sky.reserve();
        let nearest = sky.map.nearest();
        let walk = if nearest.is_finite() {
            SKY_WALK_TOLERANCES * tolerance_px * nearest / focal.max(1.0)
        } else {
            1.0
        };
        let empty = DepthImage::new(0, 0, showcase::camera(SKY_CENTRE, Vec3::NEG_Z, w, h));
        SkyPart {
            sky,
            land,
            width: w,
            height: h,
            focal,
            walk: walk.clamp(0.1, 8.0),
            last_t: None,
            capturer: Capturer::new(),
            spheres: Vec::new(),
            kinds: Vec::new(),
            truth: empty,
            truth_rgba: Vec::new(),
            mask: Vec::new(),
        }
    }

    /// The eye and the point it looks at, a fraction `t` along the walk (past 1 for where
    /// it would go on): sideways from the capture point, looking out over the plaza and
    /// turning a little.
    pub(super) fn pose(&self, t: f32) -> (Vec3, Vec3) {
        let eye = SKY_CENTRE + Vec3::X * (self.walk * t);
        let dir = Quat::from_rotation_y(0.15 - 0.3 * t) * Vec3::new(0.3, -0.1, -1.0);
        (eye, eye + dir)
    }

    /// The last frame's geometry as RGBA8 over the sky, and the far pixels it is measured
    /// over (for its flicker).
    pub(super) fn truth_and_mask(&self) -> (Vec<u8>, Vec<bool>) {
        (self.truth_rgba.clone(), self.mask.clone())
    }

    /// The near scene drawn, the panorama behind it (its re-capture's next faces taken
    /// first), and the whole geometry from the same eye to measure it against.
    pub(super) fn frame(
        &mut self,
        draws: &[Draw<'_>],
        lighting: &Lighting,
        t: f32,
        out: &mut Frame,
    ) -> SkyFrame {
        let (w, h) = (self.width, self.height);
        let (eye, at) = self.pose(t);
        // Where the eye will be when a re-capture started now is complete.
        let step = self.last_t.map_or(0.0, |last| (t - last).max(0.0));
        self.last_t = Some(t);
        let ahead = self.pose(t + step * self.sky.lead() as f32).0;
        let before_px = self.sky.map.predicted_px(eye, self.focal);
        let land = [self.land.draw()];
        let start = Instant::now();
        let update = self.sky.update(&land, lighting, eye, ahead, self.focal);
        let mut stages = Stages {
            sky: start.elapsed(),
            ..Stages::default()
        };
        let camera = showcase::camera(eye, at, w, h);
        if self.spheres.len() != draws.len() {
            self.spheres = world_spheres(draws);
        }
        let cap = &mut self.capturer;
        let start = Instant::now();
        // Only the draws the view reaches: the same pixels, fewer triangles set up.
        let mut near = Vec::with_capacity(draws.len());
        in_view(draws, &self.spheres, &camera, &mut near);
        let target = cap.render(
            near.iter().copied(),
            &camera,
            lighting,
            w,
            h,
            Encoding::Srgb,
        );
        stages.geometry = start.elapsed();
        // The near scene's bytes as they are where it covers, the panorama behind where it
        // leaves the view empty: no float image of the near scene (session 18).
        let start = Instant::now();
        let behind = self.sky.map.behind_view(&camera, (w, h));
        let lookups = over_panorama(target, &behind, &mut out.rgba, &mut self.kinds);
        stages.over_sky = start.elapsed();
        out.stages = stages;
        // The far pixels: what the near scene leaves and the panorama or the geometry
        // covers.
        let measure = Instant::now();
        let used = Usage::now();
        let whole = camera.with_depth_range(0.1, LAND_FAR);
        let all = draws.iter().copied().chain(land);
        cap.capture(all, &whole, lighting, w, h, &mut self.truth);
        let (mut far, mut unfilled, mut empty) = (0usize, 0u64, 0u64);
        self.mask.clear();
        self.mask
            .extend((self.kinds.iter().zip(&self.truth.color)).map(|(&k, g)| {
                let m = k != NEAR && (k == FAR || g.a > 0.0);
                far += m as usize;
                unfilled += (g.a > 0.0 && k == NOTHING) as u64;
                empty += (k != NEAR) as u64;
                m
            }));
        over_sky(&self.truth, &mut self.truth_rgba);
        (out.width, out.height) = (w, h);
        let error = compare_masked(&out.rgba, &self.truth_rgba, (w, h), &self.mask);
        if let (Some(dir), Some(e)) = (std::env::var_os(attractions::DUMP), error) {
            let n = (t * 1000.0) as usize;
            let both = [out.rgba.as_slice(), self.truth_rgba.as_slice()];
            attractions::dump(dir.as_ref(), "sky", n, e, both, &self.mask, (w, h));
        }
        // Both reads of the usage inside the measure's time, which the frame leaves out.
        out.measure_usage = Usage::now().since(used);
        out.measure = measure.elapsed();
        SkyFrame {
            predicted_px: self.sky.map.predicted_px(eye, self.focal),
            before_px,
            recaptured: update.swapped,
            faces: update.faces,
            face_px: update.pixels,
            captures: self.sky.captures,
            far_share: far as f64 / (w as f64 * h as f64),
            error,
            unfilled,
            near_triangles: triangles(&near),
            triangles: triangles(draws),
            lookups,
            empty,
        }
    }
}

/// The error of RGBA8 image `a` against `b`, both `size`, over the pixels of `mask`;
/// `None` when there is none.
fn compare_masked(a: &[u8], b: &[u8], (w, h): (u32, u32), mask: &[bool]) -> Option<ImageError> {
    let options = Options {
        region: Region::Mask(mask),
        ..Options::default()
    };
    metrics::compare_rgba8(
        Image::new(w, h, a).ok()?,
        Image::new(w, h, b).ok()?,
        &options,
    )
    .ok()
}

/// What a pixel of the sky part's frame shows ([`over_panorama`]): the near scene (drawn
/// as geometry, any coverage), the panorama where the near scene leaves it empty, or
/// neither (the sky colour).
pub(super) const NEAR: u8 = 0;
pub(super) const FAR: u8 = 1;
pub(super) const NOTHING: u8 = 2;

/// The near scene's render `target` (sRGB, cleared transparent) with the panorama behind
/// it (`behind`, looked up where the near scene leaves a pixel empty) and both over the
/// showcase's sky colour, as opaque sRGB RGBA8 into `out`; what each pixel shows into
/// `kinds`. The same bytes as reading the target into linear floats, filling its empty
/// pixels with [`ibr::panorama::CubeMap::behind`] and [`over_sky`] (the test
/// `the_panorama_pass_makes_the_float_paths_bytes`): a pixel the near scene covers whole
/// is its stored bytes (every sRGB byte decodes and encodes to itself), the others go
/// through the float path. Rows on the pool, each pixel its own (the same bytes on any
/// number of threads). Until session 18 the near scene was read back to a float image
/// (colour and depth, 20 bytes a pixel) and encoded again, and every empty pixel was
/// looked up. Returns the panorama's lookups made (a work counter: the empty pixels past
/// the elevations it holds anything at are not looked up, [`ibr::panorama::BehindRow`]).
/// An empty pixel with nothing behind it is the sky colour's bytes, packed once (session
/// 20: until then each such pixel in a row the panorama can reach was packed again).
pub(super) fn over_panorama(
    target: &Target,
    behind: &Behind<'_>,
    out: &mut Vec<u8>,
    kinds: &mut Vec<u8>,
) -> u64 {
    let (w, h) = (target.width() as usize, target.height() as usize);
    let (sky, encoder) = (SKY.premultiply(), Encoder::new(Encoding::Srgb));
    let encoding = target.encoding();
    let open = over_sky_pixel(&encoder, sky, Premul::TRANSPARENT).to_le_bytes();
    out.clear();
    out.resize(w * h * 4, 0);
    kinds.clear();
    kinds.resize(w * h, NOTHING);
    if w == 0 {
        return 0;
    }
    out.par_chunks_mut(w * 4)
        .zip(kinds.par_chunks_mut(w))
        .enumerate()
        .map_init(
            || (Vec::with_capacity(w), Vec::with_capacity(w)),
            |(colors, depths), (y, (bytes, kinds))| {
                target.read_row(y as u32, colors, depths);
                let row = behind.row(y as u32);
                let mut lookups = 0;
                let pixels = colors.iter().zip(bytes.chunks_exact_mut(4));
                for (x, ((p, px), kind)) in pixels.zip(kinds.iter_mut()).enumerate() {
                    if p >> 24 == 0xff && encoding == Encoding::Srgb {
                        px.copy_from_slice(&p.to_le_bytes());
                        *kind = NEAR;
                        continue;
                    }
                    let mut c = unpack(encoding, *p);
                    if c.a > 0.0 {
                        *kind = NEAR;
                    } else if row.is_open_sky() {
                        px.copy_from_slice(&open);
                        continue;
                    } else {
                        let looked;
                        (c, looked) = row.at(x);
                        lookups += looked as u64;
                        *kind = if c.a > 0.0 { FAR } else { NOTHING };
                        if c == Premul::TRANSPARENT {
                            // Nothing behind: the sky colour's bytes, as packed once.
                            px.copy_from_slice(&open);
                            continue;
                        }
                    }
                    px.copy_from_slice(&over_sky_pixel(&encoder, sky, c).to_le_bytes());
                }
                lookups
            },
        )
        .sum()
}
