//! Captures on disk in the `transforms.json` convention of NeRF-style tools (the NeRF
//! synthetic scenes, instant-ngp, nerfstudio): one JSON file beside the images, read into
//! [`DepthImage`]s and written from them.
//!
//! What is read, top level or per frame (a frame's own value wins):
//! - intrinsics: `fl_x`, `fl_y`, `cx`, `cy` in pixels (`cy` from the top row), or
//!   `camera_angle_x` (horizontal field of view, radians; square pixels, centred);
//!   `w`, `h` in pixels (else the colour image's size, which must agree when given);
//! - `frames[].file_path`: the colour image (PNG or JPEG, sRGB, straight alpha), relative to
//!   the JSON's folder; a path without an extension gets `.png` as in the NeRF scenes;
//! - `frames[].transform_matrix`: 4 x 4, rows, **camera to world** with OpenGL axes (the
//!   camera looks down its -Z, +Y up), exactly the engine's convention;
//! - `frames[].depth_file_path`: the depth map, PFM or OpenEXR: **distance along the
//!   optical axis in scene units** (not along the ray), `+inf` where nothing was seen;
//! - `near`, `far` (optional, ours): the depth range of the frame's camera; without them it
//!   is taken from the depth map.
//!
//! Every path must stay inside the JSON's folder. A file that cannot be used (sizes that
//! disagree, NaN, zero or negative depth, no frames, a singular pose) is an error naming it.
//! [`write_transforms`] writes `images/NNNN.png`, `depth/NNNN.pfm` and the JSON with
//! per-frame intrinsics, so [`read_transforms`] gives the same images back (colour to 8
//! bits).

use super::{DepthImage, EMPTY};
use engine::color::{encode_srgb8, srgb_to_linear_lut};
use engine::load::{self, Disk, Files, LoadError};
use engine::{Camera, Premul, Projection, Rgba};
use glam::Mat4;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// The largest `transforms.json` read (64 MiB).
const MAX_JSON_BYTES: u64 = 64 << 20;

/// A pinhole camera's intrinsics in pixels: focal lengths and principal point (`cy` from
/// the top row, y down), for a `w` x `h` image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intrinsics {
    pub fl_x: f32,
    pub fl_y: f32,
    pub cx: f32,
    pub cy: f32,
}

impl Intrinsics {
    /// A perspective camera's intrinsics for a `width` x `height` image; `None` for an
    /// orthographic one.
    pub fn of(projection: &Projection, width: u32, height: u32) -> Option<Self> {
        if !projection.is_perspective() {
            return None;
        }
        let [l, r, b, t] = projection.extents();
        let (n, _) = projection.near_far();
        let (w, h) = (width as f32, height as f32);
        Some(Intrinsics {
            fl_x: w * n / (r - l),
            fl_y: h * n / (t - b),
            cx: w * -l / (r - l),
            cy: h * t / (t - b),
        })
    }

    /// The projection with these intrinsics for a `width` x `height` image: symmetric
    /// ([`Projection::Perspective`]) when the principal point is the centre and pixels are
    /// square, else off-axis ([`Projection::Frustum`]).
    pub fn projection(&self, width: u32, height: u32, near: f32, far: f32) -> Projection {
        let (w, h) = (width as f32, height as f32);
        let centred = (self.cx - w / 2.0).abs() <= 1e-4 * w
            && (self.cy - h / 2.0).abs() <= 1e-4 * h
            && (self.fl_x - self.fl_y).abs() <= 1e-5 * self.fl_y;
        if centred {
            return Projection::Perspective {
                fov_y: 2.0 * (h / 2.0 / self.fl_y).atan(),
                aspect: w / h,
                near,
                far,
            };
        }
        Projection::Frustum {
            left: -self.cx * near / self.fl_x,
            right: (w - self.cx) * near / self.fl_x,
            bottom: -(h - self.cy) * near / self.fl_y,
            top: self.cy * near / self.fl_y,
            near,
            far,
        }
    }
}

/// Reads the capture described by the `transforms.json` at `path`, one depth image per
/// frame, in the file's order.
pub fn read_transforms(path: &Path) -> Result<Vec<DepthImage>, LoadError> {
    read_transforms_from(path, &Disk)
}

/// [`read_transforms`], reading every file from `files`.
pub fn read_transforms_from(path: &Path, files: &dyn Files) -> Result<Vec<DepthImage>, LoadError> {
    read_capture(path, files, true)
}

/// Reads a capture of photographs with their cameras: as [`read_transforms`], but a frame
/// may leave out `depth_file_path`, and then has no depth (every pixel
/// [`super::EMPTY`]). For what needs only images and poses (view morphing with the stereo
/// matcher, stereo from unrectified pairs).
pub fn read_photos(path: &Path) -> Result<Vec<DepthImage>, LoadError> {
    read_photos_from(path, &Disk)
}

/// [`read_photos`], reading every file from `files`.
pub fn read_photos_from(path: &Path, files: &dyn Files) -> Result<Vec<DepthImage>, LoadError> {
    read_capture(path, files, false)
}

/// The capture at `path`; depth maps required or not.
fn read_capture(
    path: &Path,
    files: &dyn Files,
    depth_required: bool,
) -> Result<Vec<DepthImage>, LoadError> {
    let bad = |why: String| LoadError::invalid(path, why);
    let bytes = files.read(path, MAX_JSON_BYTES)?;
    let root: Value = serde_json::from_slice(&bytes).map_err(|e| bad(format!("bad JSON: {e}")))?;
    let root = root
        .as_object()
        .ok_or_else(|| bad("the top level is not a JSON object".into()))?;
    let frames = root
        .get("frames")
        .and_then(Value::as_array)
        .ok_or_else(|| bad("no \"frames\" list".into()))?;
    if frames.is_empty() {
        return Err(bad("\"frames\" is empty: no cameras".into()));
    }
    let dir = path.parent().unwrap_or(Path::new(""));
    frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let f = f
                .as_object()
                .ok_or_else(|| bad(format!("frame {i} is not an object")))?;
            read_frame(path, dir, root, f, files, depth_required).map_err(|e| match e {
                // Errors about the JSON itself say which frame.
                LoadError::Invalid { file, reason } if file.0 == path => {
                    LoadError::invalid(path, format!("frame {i}: {reason}"))
                }
                e => e,
            })
        })
        .collect()
}

fn read_frame(
    path: &Path,
    dir: &Path,
    root: &Map<String, Value>,
    frame: &Map<String, Value>,
    files: &dyn Files,
    depth_required: bool,
) -> Result<DepthImage, LoadError> {
    let bad = |why: String| LoadError::invalid(path, why);
    let key = |k: &str| frame.get(k).or_else(|| root.get(k));
    let number = |k: &str| -> Result<Option<f32>, LoadError> {
        match key(k) {
            None => Ok(None),
            Some(v) => v
                .as_f64()
                .map(|x| Some(x as f32))
                .filter(|x| x.is_some_and(f32::is_finite))
                .ok_or_else(|| bad(format!("\"{k}\" is not a finite number"))),
        }
    };
    let file_of = |k: &str| -> Result<Option<PathBuf>, LoadError> {
        match frame.get(k) {
            None => Ok(None),
            Some(v) => {
                let s = v
                    .as_str()
                    .ok_or_else(|| bad(format!("\"{k}\" is not a string")))?;
                load::inside_path(s).map(Some).map_err(bad)
            }
        }
    };

    // Colour and depth.
    let mut colour_rel = file_of("file_path")?.ok_or_else(|| bad("no \"file_path\"".into()))?;
    if colour_rel.extension().is_none() {
        colour_rel.set_extension("png");
    }
    let depth_rel = file_of("depth_file_path")?;
    if depth_required && depth_rel.is_none() {
        return Err(bad(
            "no \"depth_file_path\": a depth image needs a depth map".into(),
        ));
    }
    let colour_path = dir.join(&colour_rel);
    let read = |rel: &Path, full: &Path| {
        files
            .read_inside(dir, rel, None, load::MAX_FILE_BYTES)
            .map_err(|e| LoadError::invalid(full, e))
    };
    let colour_bytes = read(&colour_rel, &colour_path)?;
    let depth = match &depth_rel {
        Some(rel) => {
            let full = dir.join(rel);
            let bytes = read(rel, &full)?;
            Some((full, bytes))
        }
        None => None,
    };
    let planes = planes(&colour_path, &colour_bytes, depth)?;
    let (w, h) = (planes.width, planes.height);
    for (k, v) in [("w", w), ("h", h)] {
        if let Some(given) = number(k)? {
            if given != v as f32 {
                return Err(LoadError::invalid(
                    &colour_path,
                    format!(
                        "image is {w} x {h} but {} says \"{k}\": {given}",
                        path.display()
                    ),
                ));
            }
        }
    }
    let depth = &planes.depth;

    // Camera.
    let intrinsics = match (number("fl_x")?, number("fl_y")?, number("camera_angle_x")?) {
        (Some(fl_x), fl_y, _) => Intrinsics {
            fl_x,
            fl_y: fl_y.unwrap_or(fl_x),
            cx: number("cx")?.unwrap_or(w as f32 / 2.0),
            cy: number("cy")?.unwrap_or(h as f32 / 2.0),
        },
        (None, _, Some(angle)) if angle > 0.0 && angle < std::f32::consts::PI => {
            let fl = w as f32 / 2.0 / (angle / 2.0).tan();
            Intrinsics {
                fl_x: fl,
                fl_y: fl,
                cx: number("cx")?.unwrap_or(w as f32 / 2.0),
                cy: number("cy")?.unwrap_or(h as f32 / 2.0),
            }
        }
        _ => {
            return Err(bad(
                "no intrinsics: give \"fl_x\" (and \"fl_y\", \"cx\", \"cy\") or a \"camera_angle_x\" between 0 and pi".into(),
            ))
        }
    };
    if !(intrinsics.fl_x > 0.0 && intrinsics.fl_y > 0.0) {
        return Err(bad("focal lengths must be positive".into()));
    }
    let (lo, hi) = depth
        .iter()
        .filter(|d| d.is_finite())
        .fold((f32::INFINITY, 0.0f32), |(lo, hi), &d| {
            (lo.min(d), hi.max(d))
        });
    let near = number("near")?.unwrap_or(if lo.is_finite() { lo * 0.5 } else { 0.1 });
    let far = number("far")?.unwrap_or(if hi > 0.0 { hi * 2.0 } else { 1000.0 });
    if !(near > 0.0 && far > near) {
        return Err(bad(format!(
            "depth range near {near}, far {far}: need 0 < near < far"
        )));
    }
    let view = pose(frame.get("transform_matrix")).map_err(bad)?;
    let camera = Camera {
        view,
        projection: intrinsics.projection(w, h, near, far),
    };

    Ok(planes.with_camera(camera))
}

/// A colour image and its depth map, checked against each other.
struct Planes {
    width: u32,
    height: u32,
    color: Vec<Premul>,
    depth: Vec<f32>,
}

impl Planes {
    fn with_camera(self, camera: Camera) -> DepthImage {
        let (w, h) = (self.width, self.height);
        DepthImage::from_planes(w, h, self.color, self.depth, camera)
            .unwrap_or_else(|| DepthImage::new(w, h, camera))
    }
}

/// Decodes a colour image (sRGB, straight alpha) and a depth map (PFM or OpenEXR, by the
/// extension of `depth_path`), refusing sizes that disagree and depths that are NaN, zero
/// or negative.
fn planes(
    colour_path: &Path,
    colour_bytes: &[u8],
    depth: Option<(PathBuf, Vec<u8>)>,
) -> Result<Planes, LoadError> {
    let (w, h, rgba) = load::rgba8_from_bytes(colour_bytes, colour_path)?;
    let Some((depth_path, depth_bytes)) = depth else {
        return Ok(colour_planes(
            w,
            h,
            &rgba,
            vec![EMPTY; w as usize * h as usize],
        ));
    };
    let depth_path = depth_path.as_path();
    let depth = load::float_image_from(
        depth_path,
        &load::Memory::default().with(depth_path, depth_bytes),
    )?;
    if (depth.width, depth.height) != (w, h) {
        return Err(LoadError::invalid(
            depth_path,
            format!(
                "depth map is {} x {} but its colour image {} is {w} x {h}",
                depth.width,
                depth.height,
                colour_path.display()
            ),
        ));
    }
    if let Some((i, d)) = depth
        .data
        .iter()
        .enumerate()
        .find(|(_, d)| d.is_nan() || **d <= 0.0)
    {
        return Err(LoadError::invalid(
            depth_path,
            format!(
                "depth at pixel ({}, {}) is {d}; depths are positive distances (+inf where nothing was seen)",
                i as u32 % w,
                i as u32 / w
            ),
        ));
    }
    Ok(colour_planes(w, h, &rgba, depth.data))
}

/// Planes of sRGB bytes `rgba` (`w` x `h`) as linear premultiplied colour, with `depth`.
fn colour_planes(w: u32, h: u32, rgba: &[u8], depth: Vec<f32>) -> Planes {
    let lut = srgb_to_linear_lut();
    let color = rgba
        .chunks_exact(4)
        .map(|p| {
            let a = p[3] as f32 / 255.0;
            Rgba::new(
                lut[p[0] as usize],
                lut[p[1] as usize],
                lut[p[2] as usize],
                a,
            )
            .premultiply()
        })
        .collect();
    Planes {
        width: w,
        height: h,
        color,
        depth,
    }
}

/// A depth image from a colour file and a depth file given one by one (not through a
/// `transforms.json`), taken by `camera` (the depth range is kept from it).
pub fn read_depth_image(
    colour: &Path,
    depth: &Path,
    camera: Camera,
) -> Result<DepthImage, LoadError> {
    let colour_bytes = Disk.read(colour, load::MAX_FILE_BYTES)?;
    let depth_bytes = Disk.read(depth, load::MAX_FILE_BYTES)?;
    let depth = Some((depth.to_path_buf(), depth_bytes));
    Ok(planes(colour, &colour_bytes, depth)?.with_camera(camera))
}

/// The world -> view matrix of a frame's camera-to-world `transform_matrix` (4 rows of 4).
fn pose(value: Option<&Value>) -> Result<Mat4, String> {
    let rows = value
        .and_then(Value::as_array)
        .filter(|r| r.len() == 4)
        .ok_or("\"transform_matrix\" is not 4 rows")?;
    let mut m = [[0.0f32; 4]; 4];
    for (r, row) in rows.iter().enumerate() {
        let row = row
            .as_array()
            .filter(|c| c.len() == 4)
            .ok_or("a \"transform_matrix\" row is not 4 numbers")?;
        for (c, v) in row.iter().enumerate() {
            m[r][c] = v
                .as_f64()
                .map(|x| x as f32)
                .filter(|x| x.is_finite())
                .ok_or("\"transform_matrix\" holds something other than finite numbers")?;
        }
    }
    if m[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err("\"transform_matrix\" is not affine (last row must be 0 0 0 1)".into());
    }
    let c2w = Mat4::from_cols_array_2d(&m).transpose();
    let det = c2w.determinant();
    if det.abs() <= 1e-12 || !det.is_finite() {
        return Err("\"transform_matrix\" is singular".into());
    }
    let view = c2w.inverse();
    if !view.is_finite() {
        return Err("\"transform_matrix\" cannot be inverted".into());
    }
    Ok(view)
}

/// Writes `images` as a capture in `dir` (created if missing): `images/NNNN.png`,
/// `depth/NNNN.pfm` and `transforms.json`. Orthographic cameras have no form in the
/// convention and are refused.
pub fn write_transforms(dir: &Path, images: &[DepthImage]) -> Result<(), LoadError> {
    let json_path = dir.join("transforms.json");
    for sub in ["images", "depth"] {
        std::fs::create_dir_all(dir.join(sub)).map_err(|e| LoadError::io(&dir.join(sub), e))?;
    }
    let mut frames = Vec::with_capacity(images.len());
    let mut top = Map::new();
    for (i, image) in images.iter().enumerate() {
        let (w, h) = (image.width(), image.height());
        let k = Intrinsics::of(&image.camera.projection, w, h).ok_or_else(|| {
            LoadError::invalid(
                &json_path,
                format!("frame {i}: an orthographic camera has no transforms.json form"),
            )
        })?;
        let (near, far) = image.camera.near_far();
        let colour_rel = format!("images/{i:04}.png");
        let depth_rel = format!("depth/{i:04}.pfm");
        load::write_png_rgba8(&dir.join(&colour_rel), w, h, &srgb8(image))?;
        let depth = load::FloatImage::new(w, h, image.depth.clone())
            .ok_or_else(|| LoadError::invalid(&json_path, "depth plane size"))?;
        load::write_float_image(&dir.join(&depth_rel), &depth)?;
        let c2w = image.camera.view.inverse().transpose().to_cols_array_2d();
        let intrinsics = json!({
            "w": w, "h": h, "fl_x": k.fl_x, "fl_y": k.fl_y, "cx": k.cx, "cy": k.cy,
            "camera_angle_x": 2.0 * (w as f32 / 2.0 / k.fl_x).atan(),
            "near": near, "far": far,
        });
        if i == 0 {
            if let Value::Object(m) = intrinsics.clone() {
                top = m;
            }
        }
        let mut frame = json!({
            "file_path": colour_rel,
            "depth_file_path": depth_rel,
            "transform_matrix": c2w,
        });
        if let (Value::Object(f), Value::Object(m)) = (&mut frame, intrinsics) {
            f.extend(m);
        }
        frames.push(frame);
    }
    top.insert("frames".into(), Value::Array(frames));
    let text = serde_json::to_string_pretty(&Value::Object(top))
        .map_err(|e| LoadError::invalid(&json_path, e.to_string()))?;
    std::fs::write(&json_path, text).map_err(|e| LoadError::io(&json_path, e))
}

/// An image's colour as the bytes of an sRGB, straight-alpha RGBA8 file (PNG).
pub fn srgb8(image: &DepthImage) -> Vec<u8> {
    image
        .color
        .iter()
        .flat_map(|c| {
            let s = c.unpremultiply();
            [
                encode_srgb8(s.r),
                encode_srgb8(s.g),
                encode_srgb8(s.b),
                (s.a.clamp(0.0, 1.0) * 255.0).round() as u8,
            ]
        })
        .collect()
}

/// Linear premultiplied colour as the 8-bit sRGB straight colour files hold, and back:
/// what a colour goes through on a round trip (for tests and comparisons).
pub fn through_8_bits(c: Premul) -> Premul {
    let s = c.unpremultiply();
    let lut = srgb_to_linear_lut();
    let a = (s.a.clamp(0.0, 1.0) * 255.0).round() / 255.0;
    Rgba::new(
        lut[encode_srgb8(s.r) as usize],
        lut[encode_srgb8(s.g) as usize],
        lut[encode_srgb8(s.b) as usize],
        a,
    )
    .premultiply()
}

/// The fuzzing entry point (`fuzz/`, and the corpus replay test): `data` as a
/// `transforms.json` whose folder holds a 2 x 2 colour image `a.png` and depth maps
/// `a.pfm` (2 x 2) and `b.pfm` (1 x 1). A capture that loads has one camera a frame, each
/// with finite, invertible matrices and positive depths.
pub fn fuzz(data: &[u8]) {
    let files = load::Memory::default()
        .with("c/transforms.json", data)
        .with("c/a.png", load::fuzz::TEXTURE_PNG)
        .with(
            "c/a.pfm",
            load::pfm_bytes(&load::FloatImage {
                width: 2,
                height: 2,
                data: vec![1.0, 2.0, f32::INFINITY, 0.5],
            }),
        )
        .with(
            "c/b.pfm",
            load::pfm_bytes(&load::FloatImage {
                width: 1,
                height: 1,
                data: vec![1.0],
            }),
        );
    if let Ok(images) = read_transforms_from(Path::new("c/transforms.json"), &files) {
        for image in &images {
            assert!(image.camera.view.is_finite(), "a loaded pose is not finite");
            assert!(
                image.camera.clip_from_world().is_finite(),
                "a loaded projection is not finite"
            );
            assert!(
                image
                    .depth
                    .iter()
                    .all(|d| *d > 0.0 && (d.is_finite() || *d == EMPTY)),
                "a loaded depth is not a positive distance"
            );
        }
    }
}

#[cfg(test)]
mod tests;
