//! Captures on disk in the `transforms.json` convention of NeRF-style tools (the NeRF
//! synthetic scenes, instant-ngp, nerfstudio): one JSON file beside the images, read into
//! [`DepthImage`]s and written from them. The README's "Exchange formats" tables list the
//! same keys with the documents they come from.
//!
//! What is read, top level or per frame (a frame's own value wins):
//! - intrinsics: `fl_x`, `fl_y`, `cx`, `cy` in pixels (`cy` from the top row; nerfstudio,
//!   instant-ngp), else `camera_angle_x` / `camera_angle_y` (fields of view in radians;
//!   the NeRF synthetic scenes, instant-ngp), a missing focal length taken from the other
//!   axis (square pixels) and a missing principal point at the centre; `w`, `h` in pixels
//!   (else the colour image's size, which must agree when given);
//! - the lens: `camera_model` (nerfstudio) may be `OPENCV`, `PINHOLE`, `SIMPLE_PINHOLE`,
//!   `SIMPLE_RADIAL` or `RADIAL` (pinhole models); others (`OPENCV_FISHEYE`,
//!   `EQUIRECTANGULAR`, ...) are refused, as are instant-ngp's `is_fisheye: true`,
//!   `latlong` and `ftheta_p0`. Distortion `k1`..`k4`, `p1`, `p2` must be 0 or absent:
//!   the images are taken as undistorted pinhole images, and a file that says otherwise is
//!   refused with the coefficient named (undistort the images first);
//! - `frames[].file_path`: the colour image (PNG or JPEG, sRGB, straight alpha), relative to
//!   the JSON's folder; a path without an extension gets `.png` as in the NeRF scenes
//!   (`./train/r_0`);
//! - `frames[].transform_matrix`: 4 x 4, rows, **camera to world** with OpenGL axes (the
//!   camera looks down its -Z, +Y up), exactly the engine's convention. Read in `f64`; the
//!   last row must be within 1e-5 of `0 0 0 1` (writers that invert in `f32` leave
//!   `0.99999988` there) and is then set exactly; the inverse is taken in `f64` (`transforms/pose.rs`);
//! - the depth map, `frames[].depth_file_path` (nerfstudio) or `frames[].depth_path`
//!   (instant-ngp): **distance along the optical axis** (not along the ray), as both tools
//!   read it; PFM or OpenEXR (values in scene units times `depth_unit_scale_factor` when
//!   given) or a 16-bit grey PNG of integers: times `integer_depth_scale` for `depth_path`
//!   (instant-ngp, which loads no depth without it, so neither do we), times
//!   `depth_unit_scale_factor` for `depth_file_path` (nerfstudio's default 1e-3: millimetres
//!   to metres). A stored 0 means **nothing measured** and reads as [`EMPTY`] (+inf), as
//!   instant-ngp and RGB-D datasets write it; `+inf` likewise; NaN and negative values are
//!   errors;
//! - `near`, `far` (optional, ours): the depth range of the frame's camera; without them it
//!   is taken from the depth map.
//!
//! Ignored: instant-ngp's `aabb_scale`, `aabb`, `scale` and `offset` say how instant-ngp
//! fits the scene into its own unit cube (positions times `scale` plus `offset`, depths times
//! `scale`), not where the cameras are: the poses and depths of the file stay in the file's
//! units, which is what a reader outside instant-ngp wants. Also ignored: nerfstudio's
//! `applied_transform` (already applied to the poses it accompanies), `sharpness`,
//! `rotation`, and any other key.
//!
//! Every path must stay inside the JSON's folder. A file that cannot be used (sizes that
//! disagree, NaN or negative depth, no frames, a singular pose) is an error naming it.
//! [`write_transforms`] writes `images/NNNN.png`, `depth/NNNN.pfm` and the JSON with
//! per-frame intrinsics, `camera_model: OPENCV` (no distortion),
//! `depth_unit_scale_factor: 1` (so nerfstudio reads the depths in scene units) and
//! camera-to-world poses inverted in `f64` with an exact last row, so [`read_transforms`]
//! gives the same images back (colour to 8 bits).

mod depth;
mod fuzz;
mod pose;

pub use self::depth::read_depth_image;
use self::depth::{planes, DepthFile, DepthUnits};
pub use self::fuzz::fuzz;
use self::pose::pose;
pub use self::pose::LAST_ROW_TOLERANCE;
pub use crate::core::{srgb8, Intrinsics};
use crate::core::{DepthImage, EMPTY};
use engine::color::{encode_srgb8, srgb_to_linear_lut};
use engine::load::{self, Disk, Files, LoadError};
use engine::{Camera, Premul, Rgba};
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// The largest `transforms.json` read (64 MiB).
const MAX_JSON_BYTES: u64 = 64 << 20;

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
/// `super::EMPTY`). For what needs only images and poses (view morphing with the stereo
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
    // nerfstudio's key first, then instant-ngp's.
    let (depth_key, depth_rel) = match file_of("depth_file_path")? {
        Some(rel) => ("depth_file_path", Some(rel)),
        None => ("depth_path", file_of("depth_path")?),
    };
    if depth_required && depth_rel.is_none() {
        return Err(bad(
            "no \"depth_file_path\" (or \"depth_path\"): a depth image needs a depth map".into(),
        ));
    }
    let positive = |k: &str| -> Result<Option<f32>, LoadError> {
        match number(k)? {
            Some(x) if x <= 0.0 => Err(bad(format!("\"{k}\" is {x}; it must be positive"))),
            x => Ok(x),
        }
    };
    let units = depth_units(depth_key, &positive)?;
    let colour_path = dir.join(&colour_rel);
    let read = |rel: &Path, full: &Path| {
        files
            .read_inside(dir, rel, None, load::MAX_FILE_BYTES)
            .map_err(|e| LoadError::invalid(full, e))
    };
    let colour_bytes = read(&colour_rel, &colour_path)?;
    let depth = match &depth_rel {
        Some(rel) => {
            let path = dir.join(rel);
            let bytes = read(rel, &path)?;
            Some(DepthFile { path, bytes, units })
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
    lens(&key, &number).map_err(bad)?;
    let intrinsics = intrinsics_of(&number, &bad, w, h)?;
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

/// How a frame's depth map is scaled: instant-ngp's 16-bit PNG (`"depth_path"`) by its
/// `integer_depth_scale`, nerfstudio's by its unit scale factor (millimetres when absent);
/// float maps by the unit scale factor alone. `positive` reads a key that must be positive.
fn depth_units(
    depth_key: &str,
    positive: &dyn Fn(&str) -> Result<Option<f32>, LoadError>,
) -> Result<DepthUnits, LoadError> {
    let unit_factor = positive("depth_unit_scale_factor")?;
    Ok(if depth_key == "depth_path" {
        DepthUnits {
            integer: positive("integer_depth_scale")?.ok_or_else(|| {
                "\"depth_path\" names a 16-bit PNG but there is no \"integer_depth_scale\" (instant-ngp loads no depth without it)".to_string()
            }),
            float: unit_factor.unwrap_or(1.0),
        }
    } else {
        DepthUnits {
            integer: Ok(unit_factor.unwrap_or(depth::NERFSTUDIO_UNIT_SCALE)),
            float: unit_factor.unwrap_or(1.0),
        }
    })
}

/// A frame's intrinsics for a `w` x `h` image (`number` reads its keys, `bad` words its
/// errors): focal lengths as given or from the fields of view, one for both axes when
/// only one is known, and the principal point as given or at the centre.
fn intrinsics_of(
    number: &dyn Fn(&str) -> Result<Option<f32>, LoadError>,
    bad: &dyn Fn(String) -> LoadError,
    w: u32,
    h: u32,
) -> Result<Intrinsics, LoadError> {
    let angle = |k: &str, side: u32| -> Result<Option<f32>, LoadError> {
        match number(k)? {
            Some(a) if a > 0.0 && a < std::f32::consts::PI => {
                Ok(Some(side as f32 / 2.0 / (a / 2.0).tan()))
            }
            Some(a) => Err(bad(format!(
                "\"{k}\" is {a}; a field of view is between 0 and pi"
            ))),
            None => Ok(None),
        }
    };
    let fl_x = match number("fl_x")? {
        Some(f) => Some(f),
        None => angle("camera_angle_x", w)?,
    };
    let fl_y = match number("fl_y")? {
        Some(f) => Some(f),
        None => angle("camera_angle_y", h)?,
    };
    let (fl_x, fl_y) = match (fl_x, fl_y) {
        (Some(x), Some(y)) => (x, y),
        (Some(f), None) | (None, Some(f)) => (f, f),
        (None, None) => {
            return Err(bad(
                "no intrinsics: give \"fl_x\" (and \"fl_y\", \"cx\", \"cy\") or a \"camera_angle_x\" between 0 and pi".into(),
            ))
        }
    };
    let intrinsics = Intrinsics {
        fl_x,
        fl_y,
        cx: number("cx")?.unwrap_or(w as f32 / 2.0),
        cy: number("cy")?.unwrap_or(h as f32 / 2.0),
    };
    if !(intrinsics.fl_x > 0.0 && intrinsics.fl_y > 0.0) {
        return Err(bad("focal lengths must be positive".into()));
    }
    Ok(intrinsics)
}

/// Camera models whose images are pinhole images (nerfstudio's `camera_model`, COLMAP's
/// names), when their distortion coefficients are 0.
const PINHOLE_MODELS: [&str; 5] = [
    "OPENCV",
    "PINHOLE",
    "SIMPLE_PINHOLE",
    "SIMPLE_RADIAL",
    "RADIAL",
];

/// Refuses a lens that is not an undistorted pinhole (module docs).
fn lens<'a>(
    key: &dyn Fn(&str) -> Option<&'a Value>,
    number: &dyn Fn(&str) -> Result<Option<f32>, LoadError>,
) -> Result<(), String> {
    if let Some(model) = key("camera_model") {
        let name = model.as_str().ok_or("\"camera_model\" is not a string")?;
        if !PINHOLE_MODELS.contains(&name) {
            return Err(format!(
                "\"camera_model\" is {name}; only pinhole cameras are read ({})",
                PINHOLE_MODELS.join(", ")
            ));
        }
    }
    if key("is_fisheye").and_then(Value::as_bool) == Some(true) {
        return Err("\"is_fisheye\" is true; only pinhole cameras are read".into());
    }
    for k in ["latlong", "ftheta_p0"] {
        if key(k).is_some() {
            return Err(format!(
                "\"{k}\" names a lens other than a pinhole; only pinhole cameras are read"
            ));
        }
    }
    for k in ["k1", "k2", "k3", "k4", "p1", "p2"] {
        let v = number(k).map_err(|e| e.to_string())?;
        if let Some(v) = v.filter(|v| *v != 0.0) {
            return Err(format!(
                "lens distortion \"{k}\": {v} is not modelled; undistort the images first (only pinhole cameras are read)"
            ));
        }
    }
    Ok(())
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
        let c2w = pose::camera_to_world_rows(&image.camera.view);
        let intrinsics = json!({
            "w": w, "h": h, "fl_x": k.fl_x, "fl_y": k.fl_y, "cx": k.cx, "cy": k.cy,
            "camera_angle_x": 2.0 * (w as f32 / 2.0 / k.fl_x).atan(),
            "camera_model": "OPENCV", "depth_unit_scale_factor": 1.0,
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

#[cfg(test)]
mod tests;

#[cfg(test)]
pub(crate) mod foreign;

#[cfg(test)]
mod properties;
