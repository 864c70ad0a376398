//! Panoramas (Chen 95, QuickTime VR; environment maps): the far scene captured from one
//! point into a cube map, six 90-degree views, and drawn as the sky behind everything from
//! there: each pixel's ray direction looked up, whatever the eye's position. Right where
//! it was captured and in any direction; wrong, by parallax, as the eye moves away, which
//! is where the method fails. [`CubeMap::predicted_px`] says by how much before rendering
//! (the nearest point it holds, seen from the moved eye), and [`Sky`] re-captures when
//! that passes a tolerance. A [`Cylinder`] is the cube unrolled around the vertical, the
//! QuickTime VR panorama: turn in place and look around, within its band of heights.

use crate::core::{Capturer, DepthImage};
use crate::stereo::rectify::{bilinear, pixel_ray};
use engine::{Camera, Draw, Lighting, Premul};
use glam::{DVec3, DVec4, Mat4, Vec2, Vec3};
use rayon::prelude::*;
use std::ops::Range;

/// The six faces' view directions and up vectors: +x, -x, +y, -y, +z, -z.
const FACES: [(Vec3, Vec3); 6] = [
    (Vec3::X, Vec3::Y),
    (Vec3::NEG_X, Vec3::Y),
    (Vec3::Y, Vec3::NEG_Z),
    (Vec3::NEG_Y, Vec3::Z),
    (Vec3::Z, Vec3::Y),
    (Vec3::NEG_Z, Vec3::Y),
];

/// The six 90-degree cameras of a cube map at `centre` seeing from `near` to `far` along
/// each face's axis, in [`CubeMap`]'s face order (+x, -x, +y, -y, +z, -z).
fn face_cameras(centre: Vec3, near: f32, far: f32) -> [Camera; 6] {
    FACES.map(|(dir, up)| {
        Camera::look_at(centre, centre + dir, up, std::f32::consts::FRAC_PI_2, 1.0)
            .with_depth_range(near.max(1e-4), far.max(near * 2.0))
    })
}

/// Which faces of a cube map at `centre` seeing from `near` to `far` (in [`FACES`]'
/// order) may show a triangle of `draws`: those whose [`face_bands`] hold a row.
#[cfg(test)]
fn faces_shown(draws: &[Draw<'_>], centre: Vec3, near: f32, far: f32) -> [bool; 6] {
    face_bands(draws, centre, near, far, 64).map(|rows| !rows.is_empty())
}

/// The rows of each `size`-pixel face of a cube map at `centre` seeing from `near` to `far`
/// (in [`FACES`]' order) that a triangle of `draws` may cover; empty for a face that can
/// show nothing. A face sees the pyramid round its axis `a` (up `u`, side `v`): `a.p >=
/// |u.p|`, `a.p >= |v.p|` and `near <= a.p <= far` for `p` from the centre; a triangle
/// with its three corners outside one of those six planes lies wholly outside (it is
/// their hull), and one inside covers no row beyond its corners' (a triangle in front of
/// the eye projects to the triangle of its projected corners), two rows spare each side.
/// A ring of far land leaves the top and the bottom faces empty and covers a band of
/// rows round the horizon of the four others: only that band is rendered
/// ([`capture_faces`]). Conservative: a face's rows are all kept at the least doubt (a
/// corner level with the eye or behind it).
fn face_bands(draws: &[Draw<'_>], centre: Vec3, near: f32, far: f32, size: u32) -> [Range<u32>; 6] {
    let planes = FACES.map(|(a, u)| {
        let v = a.cross(u);
        [a - u, a + u, a - v, a + v]
    });
    let rows = size as f32;
    let (mut lo, mut hi) = ([f32::INFINITY; 6], [f32::NEG_INFINITY; 6]);
    let mut world = Vec::new();
    for draw in draws {
        world.clear();
        world.extend(
            (draw.mesh.positions.iter()).map(|&p| draw.transform.transform_point3(p) - centre),
        );
        for t in draw.mesh.indices.chunks_exact(3) {
            let corner = |k: usize| world.get(t[k] as usize).copied();
            let (Some(p0), Some(p1), Some(p2)) = (corner(0), corner(1), corner(2)) else {
                continue;
            };
            let corners = [p0, p1, p2];
            for (f, (a, u)) in FACES.iter().enumerate() {
                if lo[f] <= 0.0 && hi[f] >= rows {
                    continue;
                }
                // A little slack for the pixels on the face's edge.
                let out =
                    |k: &dyn Fn(Vec3) -> f32| corners.iter().all(|&p| k(p) < -1e-3 * p.length());
                let outside = planes[f].iter().any(|n| out(&|p| n.dot(p)))
                    || out(&|p| a.dot(p) - near)
                    || out(&|p| far - a.dot(p));
                if outside {
                    continue;
                }
                for p in corners {
                    let along = a.dot(p);
                    if along <= 1e-3 * p.length() {
                        (lo[f], hi[f]) = (f32::NEG_INFINITY, f32::INFINITY);
                        break;
                    }
                    // The image row (0 at the top edge, `size` at the bottom).
                    let row = (1.0 - u.dot(p) / along) * 0.5 * rows;
                    (lo[f], hi[f]) = (lo[f].min(row), hi[f].max(row));
                }
            }
        }
    }
    std::array::from_fn(|f| {
        if lo[f] > hi[f] {
            return 0..0;
        }
        let from = (lo[f].floor() - 2.0).clamp(0.0, rows) as u32;
        let to = (hi[f].ceil() + 2.0).clamp(0.0, rows) as u32;
        if to > from {
            from..to
        } else {
            0..size
        }
    })
}

/// The faces of `cameras` (a cube map's, in order), each rendered over its rows of
/// `bands` only (a crop of its camera, [`Camera::crop`], the face's image rows exactly),
/// the faces on the thread pool, one of `capturers` each (a renderer with its target, and
/// the image its band is read into, kept from capture to capture: until session 20 a band
/// image was made afresh for every face of every re-capture); the rows outside left empty
/// (transparent, depth [`crate::core::EMPTY`]). A face's storage is taken from `spare`
/// (faces of an earlier cube map with the rows they may hold) before new ones are made,
/// and only the rows it held are cleared. Returns the faces and the pixels rendered.
fn capture_faces(
    draws: &[Draw<'_>],
    cameras: &[Camera],
    bands: &[Range<u32>],
    lighting: &Lighting,
    size: u32,
    spare: &mut Vec<(DepthImage, Range<u32>)>,
    capturers: &mut Vec<(Capturer, DepthImage)>,
) -> (Vec<DepthImage>, u64) {
    let crops: Vec<(Camera, u32)> = (cameras.iter().zip(bands))
        .filter(|(_, rows)| !rows.is_empty())
        .map(|(c, rows)| {
            let (top, bottom) = (rows.start as f32, rows.end as f32);
            let crop = c.crop(
                Vec2::new(0.0, top),
                Vec2::new(size as f32, bottom),
                size,
                size,
            );
            (crop, rows.len() as u32)
        })
        .collect();
    if let (true, Some((camera, _))) = (capturers.len() < crops.len(), crops.first()) {
        let empty = DepthImage::new(0, 0, *camera);
        capturers.resize_with(crops.len(), || (Capturer::new(), empty.clone()));
    }
    (crops.par_iter().zip(capturers.par_iter_mut())).for_each(|((camera, rows), (cap, out))| {
        cap.capture(draws.iter().copied(), camera, lighting, size, *rows, out);
    });
    let pixels = crops.iter().map(|(_, rows)| *rows as u64).sum::<u64>() * size as u64;
    let mut rendered = capturers.iter().map(|(_, band)| band).take(crops.len());
    let row = size as usize;
    let faces = (cameras.iter().zip(bands))
        .map(|(camera, rows)| {
            let (mut face, held) = (spare.pop())
                .filter(|(b, _)| (b.width(), b.height()) == (size, size))
                .unwrap_or_else(|| (DepthImage::new(size, size, *camera), 0..0));
            face.camera = *camera;
            let (from, to) = (rows.start as usize * row, rows.end as usize * row);
            for (i, (c, d)) in (face.color.iter_mut().zip(face.depth.iter_mut()))
                .enumerate()
                .take(held.end as usize * row)
                .skip(held.start as usize * row)
            {
                if !(from..to).contains(&i) {
                    (*c, *d) = (Premul::TRANSPARENT, crate::core::EMPTY);
                }
            }
            if !rows.is_empty() {
                if let Some(band) = rendered.next() {
                    face.color[from..to].copy_from_slice(&band.color);
                    face.depth[from..to].copy_from_slice(&band.depth);
                }
            }
            face
        })
        .collect();
    (faces, pixels)
}

/// A cube map: six square views from one centre, with depth (for the error prediction).
#[derive(Clone, Debug)]
pub struct CubeMap {
    centre: Vec3,
    faces: Vec<DepthImage>,
    /// The rows of each face that may hold something ([`face_bands`]): the others are
    /// empty. Empty for a face left empty, not rendered: it could show nothing.
    bands: [Range<u32>; 6],
    /// Each face's world-to-clip matrix, made once: a lookup per pixel of every frame.
    to_clip: Vec<Mat4>,
    /// The nearest point's distance ([`CubeMap::nearest`]), found once at the capture.
    nearest: f32,
    /// The squared tangents of elevation past which (above, below) a lookup finds nothing
    /// ([`open_sky`]), `None` where that is not known: [`BehindRow`] skips those lookups.
    open: Option<(f32, f32)>,
}

impl CubeMap {
    /// Captures `draws` from `centre` into six `size` x `size` faces, seeing from `near`
    /// (what is nearer is left out: the near scene is drawn as geometry) to `far` along each
    /// face's axis. A point seen by a face lies farther along that face's axis than along
    /// any other, so what it holds is what lies outside the cube of half side `near` round
    /// the centre ([`trim_beyond`] keeps the rest).
    pub fn capture(
        draws: &[Draw<'_>],
        lighting: &Lighting,
        centre: Vec3,
        size: u32,
        near: f32,
        far: f32,
    ) -> CubeMap {
        let bands = face_bands(draws, centre, near, far, size);
        let cameras = face_cameras(centre, near, far);
        let (spare, capturers) = (&mut Vec::new(), &mut Vec::new());
        let (faces, _) = capture_faces(draws, &cameras, &bands, lighting, size, spare, capturers);
        CubeMap::assemble(centre, faces, bands)
    }

    /// The cube map of six faces captured from `centre` with [`face_cameras`] (in their
    /// order), perhaps a few at a time ([`Sky`] spreads a re-capture over frames).
    /// `None` unless there are six.
    pub fn from_faces(centre: Vec3, faces: Vec<DepthImage>) -> Option<CubeMap> {
        (faces.len() == FACES.len()).then(|| {
            let bands = std::array::from_fn(|f| 0..faces[f].height());
            CubeMap::assemble(centre, faces, bands)
        })
    }

    /// The cube map of six faces (not checked), empty outside their rows of `bands`.
    fn assemble(centre: Vec3, faces: Vec<DepthImage>, bands: [Range<u32>; 6]) -> CubeMap {
        let nearest = (faces.iter().zip(&bands))
            .flat_map(|(f, rows)| {
                let row = f.width() as usize;
                let held = rows.start as usize * row..rows.end as usize * row;
                f.depth.get(held).unwrap_or(&[]).iter()
            })
            .copied()
            .filter(|d| d.is_finite())
            .fold(f32::INFINITY, f32::min);
        CubeMap {
            centre,
            to_clip: faces.iter().map(|f| f.camera.gl_view_proj()).collect(),
            open: open_sky(&bands, faces.first().map_or(0, |f| f.height())),
            faces,
            bands,
            nearest,
        }
    }

    /// How many faces were rendered (the others could show nothing and were left empty).
    pub fn faces_rendered(&self) -> usize {
        self.bands.iter().filter(|rows| !rows.is_empty()).count()
    }

    /// The rows of face `f` (in +x, -x, +y, -y, +z, -z order) that were rendered and may
    /// hold something; the others are empty.
    pub fn face_rows(&self, f: usize) -> Range<u32> {
        self.bands.get(f).cloned().unwrap_or(0..0)
    }

    /// Where it was captured.
    pub fn centre(&self) -> Vec3 {
        self.centre
    }

    /// The distance (along each face's axis) of the nearest point it holds; infinity when
    /// it holds only sky.
    pub fn nearest(&self) -> f32 {
        self.nearest
    }

    /// The view of the panorama from `camera`'s orientation (its position does not
    /// matter: the panorama is drawn as if infinitely far), `w` x `h`. Depth is empty
    /// everywhere: it is the sky, behind everything.
    pub fn view(&self, camera: &Camera, w: u32, h: u32) -> DepthImage {
        let mut out = DepthImage::new(w, h, *camera);
        let to_world = camera.gl_view_proj().inverse();
        let eye = camera.eye();
        out.color
            .par_chunks_mut(w.max(1) as usize)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, c) in row.iter_mut().enumerate() {
                    let dir = pixel_ray(&to_world, eye, (x as u32, y as u32), (w, h));
                    if let Some(s) = self.sample(dir) {
                        *c = s;
                    }
                }
            });
        out
    }

    /// Fills the pixels of `frame` that show nothing with the panorama, as its sky. Each
    /// row's rays are linear in the column ([`RowRays`]): a pixel's direction is two
    /// multiply-adds a component, not a 4x4 product and a division (the lookup is the same
    /// up to rounding: it depends on the direction, not its length).
    pub fn behind(&self, frame: &mut DepthImage) {
        let (w, h) = (frame.width(), frame.height());
        let behind = self.behind_view(&frame.camera, (w, h));
        // Only the empty pixels are looked up.
        frame
            .color
            .par_chunks_mut(w.max(1) as usize)
            .enumerate()
            .for_each(|(y, row)| {
                let row_behind = behind.row(y as u32);
                for (x, c) in row.iter_mut().enumerate() {
                    if c.a > 0.0 {
                        continue;
                    }
                    *c = row_behind.at(x).0;
                }
            });
    }

    /// [`CubeMap::behind`]'s lookups for a `w` x `h` view by `camera`, a row at a time and
    /// a pixel at a time, for a caller that holds its frame in another form (the views
    /// moment's near scene as the engine's sRGB bytes, looked up where they are empty).
    pub fn behind_view(&self, camera: &Camera, (w, h): (u32, u32)) -> Behind<'_> {
        Behind {
            map: self,
            rays: RowRays::new(camera, (w, h)),
        }
    }

    /// The predicted error of drawing this from `eye`: how far (in pixels, at `focal_px`
    /// pixels per unit of tangent) the nearest point it holds moves when seen from `eye`
    /// instead of the centre, at worst (moved across the line of sight). Zero at the
    /// centre; it grows with the distance moved and shrinks with the scene's distance.
    pub fn predicted_px(&self, eye: Vec3, focal_px: f32) -> f32 {
        let nearest = self.nearest();
        if !nearest.is_finite() {
            return 0.0;
        }
        focal_px * (eye - self.centre).length() / nearest
    }
}

/// The elevations past which a cube map of `size`-pixel faces holding `bands` finds
/// nothing, as squared tangents `(above, below)` (each 0 at least), when its top and bottom
/// faces are empty (a ring of far land round the horizon): a ray `d` that lands on a side
/// face (axis `a`, up `+y`) lands at `v = d.y / a`, and `|v| >= |d.y| / |d.xz|` (the side
/// face's axis is at most the horizontal length), on the same side of the horizon; so a
/// ray whose tangent of elevation is past a side face's band's top (or bottom) row, with
/// two rows to spare for the bilinear lookup's second row and rounding, lands outside
/// every band or on an empty face: [`CubeMap::sample`] finds it transparent.
fn open_sky(bands: &[Range<u32>; 6], size: u32) -> Option<(f32, f32)> {
    let (top, bottom) = (&bands[2], &bands[3]);
    if !top.is_empty() || !bottom.is_empty() || size == 0 {
        return None;
    }
    // Face row r's tangent up at the face's centre column (row 0 at the top).
    let v = |r: f32| 1.0 - 2.0 * (r + 0.5) / size as f32;
    let sides = [0, 1, 4, 5].map(|f| &bands[f]);
    let (mut above, mut below) = (0.0f32, 0.0f32);
    for rows in sides.iter().filter(|rows| !rows.is_empty()) {
        above = above.max(v(rows.start as f32 - 3.0));
        below = below.min(v(rows.end as f32 + 2.0));
    }
    Some((above * above, below * below))
}

/// Whether `d` lies past the elevations `open` ([`open_sky`]): a lookup finds nothing.
#[inline]
fn in_open_sky(d: Vec3, (above, below): (f32, f32)) -> bool {
    let (level, y2) = (d.x * d.x + d.z * d.z, d.y * d.y);
    (d.y > 0.0 && y2 > above * level) || (d.y < 0.0 && y2 > below * level)
}

/// A panorama's colours behind a view ([`CubeMap::behind_view`]), a row at a time.
#[derive(Debug)]
pub struct Behind<'a> {
    map: &'a CubeMap,
    rays: RowRays,
}

/// One row of [`Behind`].
#[derive(Debug)]
pub struct BehindRow<'a> {
    map: &'a CubeMap,
    ray: RowRay,
    open: Option<(f32, f32)>,
    /// The whole row lies past those elevations ([`BehindRow::is_open_sky`]).
    shut: bool,
}

impl Behind<'_> {
    /// Row `y`'s lookups (its rays set up once).
    pub fn row(&self, y: u32) -> BehindRow<'_> {
        let ray = self.rays.row(y);
        // The rays along a row are a segment (times a sign, the same at both ends: then
        // along it); past an elevation is a convex cone: with both ends in it, so is the
        // whole row. Tightened by a ten-thousandth against rounding the rays between.
        let w = self.rays.size.0 as usize;
        let open = self.map.open;
        let shut = open.is_some_and(|(above, below)| {
            let tight = (above * 1.0002 + 1e-4, below * 1.0002 + 1e-4);
            let (first, last) = (ray.at(0), ray.at(w.saturating_sub(1)));
            let same_sign = ray.far_w.0.signum()
                == (ray.far_w.0 + ray.far_w.1 * (w.max(1) - 1) as f64).signum();
            same_sign
                && ((in_open_sky(first, (tight.0, f32::INFINITY))
                    && in_open_sky(last, (tight.0, f32::INFINITY)))
                    || (in_open_sky(first, (f32::INFINITY, tight.1))
                        && in_open_sky(last, (f32::INFINITY, tight.1))))
        });
        BehindRow {
            map: self.map,
            ray,
            open,
            shut,
        }
    }
}

impl BehindRow<'_> {
    /// Whether the whole row lies past the elevations the panorama holds anything at:
    /// every [`BehindRow::at`] of it is transparent (the caller may skip them).
    pub fn is_open_sky(&self) -> bool {
        self.shut
    }

    /// The panorama behind pixel `x` of the row, as [`CubeMap::behind`] fills an empty
    /// pixel (transparent where it holds nothing), and whether it was looked up (`false`
    /// for a ray past the elevations it holds anything at: [`CubeMap::sample`] would
    /// find it transparent, session 18).
    #[inline]
    pub fn at(&self, x: usize) -> (Premul, bool) {
        if self.shut {
            return (Premul::TRANSPARENT, false);
        }
        let d = self.ray.at(x);
        if self.open.is_some_and(|open| in_open_sky(d, open)) {
            return (Premul::TRANSPARENT, false);
        }
        (self.map.sample(d).unwrap_or(Premul::TRANSPARENT), true)
    }
}

/// The rays through the pixel centres of a `w` x `h` view by a camera, a row at a time:
/// [`pixel_ray`] is `far / far.w - eye` for the pixel's far-plane point `far`, which is
/// linear in the column; times `far.w` (its sign kept) the ray is linear too.
#[derive(Debug)]
struct RowRays {
    /// The clip-to-world matrix's columns for x and for y, and the sum of its columns for
    /// z and w (the far plane, `w = 1`).
    col_x: DVec4,
    col_y: DVec4,
    rest: DVec4,
    eye: DVec3,
    size: (f64, f64),
}

/// One row's rays, `a + b x` times the sign of `far.w` (likewise linear).
#[derive(Debug)]
struct RowRay {
    ray: (DVec3, DVec3),
    far_w: (f64, f64),
}

impl RowRays {
    fn new(camera: &Camera, (w, h): (u32, u32)) -> RowRays {
        let to_world = camera.gl_view_proj().as_dmat4().inverse();
        RowRays {
            col_x: to_world.x_axis,
            col_y: to_world.y_axis,
            rest: to_world.z_axis + to_world.w_axis,
            eye: camera.eye().as_dvec3(),
            size: (w.max(1) as f64, h.max(1) as f64),
        }
    }

    fn row(&self, y: u32) -> RowRay {
        let (w, h) = self.size;
        let ndc_y = 1.0 - 2.0 * (y as f64 + 0.5) / h;
        let far_a = self.col_x * (1.0 / w - 1.0) + self.col_y * ndc_y + self.rest;
        let far_b = self.col_x * (2.0 / w);
        let ray = |f: DVec4| f.truncate() - self.eye * f.w;
        RowRay {
            ray: (ray(far_a), ray(far_b)),
            far_w: (far_a.w, far_b.w),
        }
    }
}

impl RowRay {
    /// Column `x`'s ray (as [`pixel_ray`]'s, times a positive factor).
    #[inline]
    fn at(&self, x: usize) -> Vec3 {
        let x = x as f64;
        let sign = (self.far_w.0 + self.far_w.1 * x).signum();
        ((self.ray.0 + self.ray.1 * x) * sign).as_vec3()
    }
}

/// Clears the pixels of `frame` that show a point outside the cube of half side `half`
/// round `centre`: the near scene's part of a view drawn in front of a panorama captured
/// at `centre` that holds what lies outside that cube ([`CubeMap::capture`]), so that each
/// point of the scene is drawn by one or the other, not both (an alpha-tested fence drawn
/// as geometry with its resampled copy showing through its holes). Returns the pixels
/// cleared.
pub fn trim_beyond(frame: &mut DepthImage, centre: Vec3, half: f32) -> usize {
    let (w, h) = (frame.width(), frame.height());
    let to_world = frame.camera.gl_view_proj().inverse();
    let eye = frame.camera.eye();
    let forward = frame.camera.forward();
    let (color, depth) = (&mut frame.color, &mut frame.depth);
    color
        .par_chunks_mut(w.max(1) as usize)
        .zip(depth.par_chunks_mut(w.max(1) as usize))
        .enumerate()
        .map(|(y, (row, row_depth))| {
            let mut n = 0;
            for (x, (c, d)) in row.iter_mut().zip(row_depth.iter_mut()).enumerate() {
                if !d.is_finite() {
                    continue;
                }
                let dir = pixel_ray(&to_world, eye, (x as u32, y as u32), (w, h));
                let along = dir.dot(forward);
                if along <= 0.0 {
                    continue;
                }
                let point = eye + dir * (*d / along);
                if (point - centre).abs().max_element() > half {
                    *c = Premul::TRANSPARENT;
                    *d = crate::core::EMPTY;
                    n += 1;
                }
            }
            n
        })
        .sum()
}

impl CubeMap {
    /// The colour seen in direction `dir` from the centre (bilinear on the face it points
    /// into); `None` for a zero or non-finite direction.
    pub fn sample(&self, dir: Vec3) -> Option<Premul> {
        let a = dir.abs();
        if !dir.is_finite() || a.max_element() <= 0.0 {
            return None;
        }
        let face = if a.x >= a.y && a.x >= a.z {
            usize::from(dir.x < 0.0)
        } else if a.y >= a.z {
            2 + usize::from(dir.y < 0.0)
        } else {
            4 + usize::from(dir.z < 0.0)
        };
        let f = &self.faces[face];
        let c = self.to_clip[face] * dir.extend(0.0);
        let (w, h) = (f.width() as f32, f.height() as f32);
        let (u, v) = (
            (c.x / c.w + 1.0) * 0.5 * w - 0.5,
            (1.0 - c.y / c.w) * 0.5 * h - 0.5,
        );
        // Both rows the lookup reads outside the face's band: empty, as the lookup would
        // find them (most of the sky, without reading the face).
        let rows = &self.bands[face];
        let top = v.clamp(0.0, h - 1.0).floor();
        if top + 1.0 < rows.start as f32 || top >= rows.end as f32 {
            return (!u.is_nan()).then_some(Premul::TRANSPARENT);
        }
        bilinear(f, u.clamp(-0.5, w - 0.5), v.clamp(-0.5, h - 0.5))
    }
}

mod cylinder;
pub use cylinder::Cylinder;

mod sky;
pub use sky::{Sky, SkyStep};

#[cfg(test)]
mod tests;
