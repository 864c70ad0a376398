//! A frame's colour image and depth map, decoded and checked against each other: depth
//! units applied (`integer_depth_scale`, `depth_unit_scale_factor`), 0 read as "nothing
//! measured" ([`EMPTY`]), NaN and negative depths refused.

use crate::core::{DepthImage, EMPTY};
use engine::color::srgb_to_linear_lut;
use engine::load::{self, Disk, Files, LoadError};
use engine::{Camera, Premul, Rgba};
use std::path::{Path, PathBuf};

/// nerfstudio's default `depth_unit_scale_factor`: integer depths in millimetres.
pub(super) const NERFSTUDIO_UNIT_SCALE: f32 = 1e-3;

/// What a depth map's stored values are multiplied by to give scene units.
pub(super) struct DepthUnits {
    /// For 16-bit PNG integers; the reason there is none otherwise.
    pub integer: Result<f32, String>,
    /// For PFM and OpenEXR floats.
    pub float: f32,
}

/// A depth map's file: its path (for errors and the format), bytes and units.
pub(super) struct DepthFile {
    pub path: PathBuf,
    pub bytes: Vec<u8>,
    pub units: DepthUnits,
}

/// A colour image and its depth map, checked against each other.
pub(super) struct Planes {
    pub width: u32,
    pub height: u32,
    pub color: Vec<Premul>,
    pub depth: Vec<f32>,
}

impl Planes {
    pub(super) fn with_camera(self, camera: Camera) -> DepthImage {
        let (w, h) = (self.width, self.height);
        DepthImage::from_planes(w, h, self.color, self.depth, camera)
            .unwrap_or_else(|| DepthImage::new(w, h, camera))
    }
}

/// Decodes a colour image (sRGB, straight alpha) and a depth map (PFM, OpenEXR or 16-bit
/// PNG, by the extension of its path), refusing sizes that disagree and depths that are
/// NaN or negative; a stored 0 becomes [`EMPTY`], the others are scaled by the units.
pub(super) fn planes(
    colour_path: &Path,
    colour_bytes: &[u8],
    depth: Option<DepthFile>,
) -> Result<Planes, LoadError> {
    let (w, h, rgba) = load::rgba8_from_bytes(colour_bytes, colour_path)?;
    let Some(DepthFile { path, bytes, units }) = depth else {
        return Ok(colour_planes(
            w,
            h,
            &rgba,
            vec![EMPTY; w as usize * h as usize],
        ));
    };
    let depth_path = path.as_path();
    let is_png = depth_path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let scale = if is_png {
        units
            .integer
            .map_err(|why| LoadError::invalid(depth_path, why))?
    } else {
        units.float
    };
    let depth =
        load::float_image_from(depth_path, &load::Memory::default().with(depth_path, bytes))?;
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
        .find(|(_, d)| d.is_nan() || **d < 0.0)
    {
        return Err(LoadError::invalid(
            depth_path,
            format!(
                "depth at pixel ({}, {}) is {d}; depths are positive distances (0 or +inf where nothing was measured)",
                i as u32 % w,
                i as u32 / w
            ),
        ));
    }
    let data = depth
        .data
        .into_iter()
        .map(|d| {
            if d == 0.0 {
                EMPTY
            } else if scale == 1.0 {
                d
            } else {
                d * scale
            }
        })
        .collect();
    Ok(colour_planes(w, h, &rgba, data))
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
/// `transforms.json`), taken by `camera` (the depth range is kept from it). A PFM or
/// OpenEXR depth map is in scene units; a 16-bit PNG in millimetres (nerfstudio's default
/// unit, times 1e-3); 0 is "nothing measured".
pub fn read_depth_image(
    colour: &Path,
    depth: &Path,
    camera: Camera,
) -> Result<DepthImage, LoadError> {
    let colour_bytes = Disk.read(colour, load::MAX_FILE_BYTES)?;
    let bytes = Disk.read(depth, load::MAX_FILE_BYTES)?;
    let depth = DepthFile {
        path: depth.to_path_buf(),
        bytes,
        units: DepthUnits {
            integer: Ok(NERFSTUDIO_UNIT_SCALE),
            float: 1.0,
        },
    };
    Ok(planes(colour, &colour_bytes, Some(depth))?.with_camera(camera))
}
