//! Single-channel float images, the files depth maps are exchanged in: PFM (the Portable
//! Float Map of Middlebury, ETH3D and most stereo and depth tools) and OpenEXR (through the
//! `exr` crate).
//!
//! A [`FloatImage`] is row-major with the **top row first**, like every image in the engine.
//! PFM stores rows bottom to top; [`parse_pfm`] and [`pfm_bytes`] turn them over. PFM's
//! header is `Pf` (one channel) or `PF` (three: the first is read), the width and height,
//! and a scale whose sign gives the byte order (negative: little-endian); we write `Pf`,
//! little-endian, scale -1. From an OpenEXR file's first layer one channel is read: `Z`
//! (depth), else `Y` (luminance), else `R`, else one named `*.Z` or `*Depth` (Blender's
//! passes), else the first; we write one 32-bit `Z` channel, losslessly compressed.
//! Values are passed through as they are (NaN and infinities included): what they mean
//! is the reader's business (`ibr::images` takes infinity as "nothing there").

use super::{Files, LoadError, MAX_FILE_BYTES};
use crate::texture::MAX_TEXTURE_SIZE;
use std::path::Path;

/// A one-channel `f32` image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    pub width: u32,
    pub height: u32,
    /// `width * height` values.
    pub data: Vec<f32>,
}

impl FloatImage {
    /// `None` when `data` does not hold `width * height` values.
    pub fn new(width: u32, height: u32, data: Vec<f32>) -> Option<Self> {
        (data.len() as u64 == width as u64 * height as u64).then_some(FloatImage {
            width,
            height,
            data,
        })
    }
}

/// Reads a `.pfm` or `.exr` file (chosen by the extension, any case) from `files`.
pub fn float_image_from(path: &Path, files: &dyn Files) -> Result<FloatImage, LoadError> {
    let bytes = files.read(path, MAX_FILE_BYTES)?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("pfm") => parse_pfm(&bytes).map_err(|e| LoadError::invalid(path, e)),
        Some("exr") => parse_exr(&bytes).map_err(|e| LoadError::invalid(path, e)),
        _ => Err(LoadError::invalid(
            path,
            "not a float image: expected a .pfm or .exr file",
        )),
    }
}

/// Reads a float image from the disk ([`float_image_from`]).
pub fn float_image(path: &Path) -> Result<FloatImage, LoadError> {
    float_image_from(path, &super::Disk)
}

/// Decodes PFM bytes.
pub fn parse_pfm(bytes: &[u8]) -> Result<FloatImage, String> {
    let mut pos = 0;
    let kind = token(bytes, &mut pos).ok_or("empty file: not a PFM")?;
    let channels = match kind {
        b"Pf" => 1,
        b"PF" => 3,
        _ => return Err("not a PFM file (it must start with 'Pf' or 'PF')".into()),
    };
    let width = number::<u32>(bytes, &mut pos, "width")?;
    let height = number::<u32>(bytes, &mut pos, "height")?;
    let scale = number::<f32>(bytes, &mut pos, "scale")?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(format!(
            "PFM scale {scale} is neither positive nor negative"
        ));
    }
    // Exactly one whitespace byte separates the header from the data.
    if !bytes.get(pos).is_some_and(u8::is_ascii_whitespace) {
        return Err("PFM header does not end in whitespace".into());
    }
    pos += 1;
    check_size(width, height)?;
    let (w, h) = (width as usize, height as usize);
    let need = w * h * channels * 4;
    let data = &bytes[pos..];
    if data.len() < need {
        return Err(format!(
            "PFM data is {} bytes; a {width} x {height} image with {channels} channel(s) needs {need}",
            data.len()
        ));
    }
    let little = scale < 0.0;
    let mut out = vec![0.0; w * h];
    for (row, dst) in out.chunks_exact_mut(w).enumerate() {
        // File rows run bottom to top.
        let src = &data[(h - 1 - row) * w * channels * 4..];
        for (x, v) in dst.iter_mut().enumerate() {
            let b: [u8; 4] = src[x * channels * 4..x * channels * 4 + 4]
                .try_into()
                .unwrap_or([0; 4]);
            *v = if little {
                f32::from_le_bytes(b)
            } else {
                f32::from_be_bytes(b)
            };
        }
    }
    Ok(FloatImage {
        width,
        height,
        data: out,
    })
}

/// Encodes a float image as PFM (`Pf`, little-endian, bottom row first).
pub fn pfm_bytes(image: &FloatImage) -> Vec<u8> {
    let (w, h) = (image.width as usize, image.height as usize);
    let mut out = format!("Pf\n{} {}\n-1\n", image.width, image.height).into_bytes();
    out.reserve(w * h * 4);
    for row in (0..h).rev() {
        for v in &image.data[row * w..(row + 1) * w] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// Writes a float image as `.pfm` or `.exr`, by the extension of `path`.
pub fn write_float_image(path: &Path, image: &FloatImage) -> Result<(), LoadError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("pfm") => std::fs::write(path, pfm_bytes(image)).map_err(|e| LoadError::io(path, e)),
        Some("exr") => write_exr(path, image),
        _ => Err(LoadError::invalid(
            path,
            "float images are written as .pfm or .exr",
        )),
    }
}

fn parse_exr(bytes: &[u8]) -> Result<FloatImage, String> {
    use exr::prelude::*;
    let bad = |e: Error| format!("bad OpenEXR: {e}");
    // The header first: refuse a huge image before anything is allocated for it.
    let panicked =
        |why: String| format!("the OpenEXR decoder failed on this file (it panicked: {why})");
    let meta =
        super::image::guarded(|| MetaData::read_from_buffered(std::io::Cursor::new(bytes), false))
            .map_err(panicked)?
            .map_err(bad)?;
    for header in meta.headers.iter() {
        let size = header.layer_size;
        if size.0 > MAX_TEXTURE_SIZE as usize || size.1 > MAX_TEXTURE_SIZE as usize {
            return Err(format!(
                "OpenEXR layer is {} x {}; sides must be 1..={MAX_TEXTURE_SIZE}",
                size.0, size.1
            ));
        }
        if header.deep {
            return Err("deep OpenEXR data is not a depth map".into());
        }
    }
    let image = super::image::guarded(|| {
        read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .non_parallel()
            .from_buffered(std::io::Cursor::new(bytes))
    })
    .map_err(panicked)?
    .map_err(bad)?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    let list = &layer.channel_data.list;
    let name = |c: &AnyChannel<FlatSamples>| c.name.to_string();
    let pick = ["Z", "Y", "R"]
        .iter()
        .find_map(|want| list.iter().find(|c| name(c) == *want))
        .or_else(|| {
            list.iter()
                .find(|c| name(c).ends_with(".Z") || name(c).ends_with("Depth"))
        })
        .or(list.first())
        .ok_or("OpenEXR layer has no channels")?;
    if pick.sampling != Vec2(1, 1) {
        return Err("subsampled OpenEXR channels are not a depth map".into());
    }
    check_size(w as u32, h as u32)?;
    let data: Vec<f32> = pick.sample_data.values_as_f32().collect();
    FloatImage::new(w as u32, h as u32, data)
        .ok_or_else(|| "OpenEXR channel size and data disagree".into())
}

/// A float image as a one-channel (`Z`) OpenEXR file, 32-bit float, lossless ZIP.
fn write_exr(path: &Path, image: &FloatImage) -> Result<(), LoadError> {
    use exr::prelude::*;
    let size = (image.width as usize, image.height as usize);
    let channel = AnyChannel::new("Z", FlatSamples::F32(image.data.clone()));
    let channels = AnyChannels::sort(smallvec::smallvec![channel]);
    let layer = Layer::new(
        size,
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_file(path)
        .map_err(|e| LoadError::invalid(path, format!("cannot write OpenEXR: {e}")))
}

fn check_size(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 || width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
        return Err(format!(
            "image is {width} x {height}; sides must be 1..={MAX_TEXTURE_SIZE}"
        ));
    }
    Ok(())
}

/// The next whitespace-separated header token (at most 64 bytes).
fn token<'a>(bytes: &'a [u8], pos: &mut usize) -> Option<&'a [u8]> {
    while bytes.get(*pos).is_some_and(u8::is_ascii_whitespace) {
        *pos += 1;
    }
    let start = *pos;
    while *pos < bytes.len() && !bytes[*pos].is_ascii_whitespace() && *pos - start < 64 {
        *pos += 1;
    }
    (*pos > start).then(|| &bytes[start..*pos])
}

fn number<T: std::str::FromStr>(bytes: &[u8], pos: &mut usize, what: &str) -> Result<T, String> {
    token(bytes, pos)
        .and_then(|t| std::str::from_utf8(t).ok())
        .and_then(|t| t.parse().ok())
        .ok_or_else(|| format!("PFM header: bad or missing {what}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> FloatImage {
        FloatImage::new(3, 2, vec![1.0, 2.5, f32::INFINITY, -4.0, 0.0, 1e-3]).unwrap()
    }

    #[test]
    fn pfm_round_trips_top_row_first() {
        let img = sample();
        let bytes = pfm_bytes(&img);
        assert!(bytes.starts_with(b"Pf\n3 2\n-1\n"));
        // The file's first row is the image's bottom row.
        assert_eq!(&bytes[10..14], &(-4.0f32).to_le_bytes());
        assert_eq!(parse_pfm(&bytes).unwrap(), img);
    }

    #[test]
    fn big_endian_and_three_channel_pfm_read() {
        // 1 x 2, three channels, big-endian (positive scale): the first channel is read.
        let mut b = b"PF\n1 2\n1.0\n".to_vec();
        for v in [7.0f32, 0.0, 0.0, 9.0, 0.0, 0.0] {
            b.extend_from_slice(&v.to_be_bytes());
        }
        let img = parse_pfm(&b).unwrap();
        assert_eq!((img.width, img.height), (1, 2));
        assert_eq!(img.data, vec![9.0, 7.0]);
    }

    #[test]
    fn bad_pfm_says_why() {
        let cases: [(&[u8], &str); 5] = [
            (b"", "empty"),
            (b"P6\n1 1\n255\n", "not a PFM"),
            (b"Pf\n2 x\n-1\n", "height"),
            (b"Pf\n2 2\n0\n", "scale"),
            (b"Pf\n2 2\n-1\n\0\0\0\0", "needs 16"),
        ];
        for (bytes, want) in cases {
            let e = parse_pfm(bytes).unwrap_err();
            assert!(e.contains(want), "{e:?} should mention {want:?}");
        }
        assert!(parse_pfm(b"Pf\n0 5\n-1\n").unwrap_err().contains("sides"));
        assert!(parse_pfm(b"Pf\n99999999 99999999\n-1\n")
            .unwrap_err()
            .contains("sides"));
    }

    #[test]
    fn exr_round_trips_as_one_z_channel() {
        let img = FloatImage::new(3, 2, vec![1.0, 2.5, f32::INFINITY, 4.0, 0.0, 1e-3]).unwrap();
        let dir = std::env::temp_dir().join(format!("parallax-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("d.exr");
        write_float_image(&path, &img).unwrap();
        let back = float_image(&path).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(back, img);
    }

    #[test]
    fn other_extensions_are_refused_by_name() {
        let files = super::super::Memory::default().with("d.png", vec![0u8; 4]);
        let e = float_image_from(Path::new("d.png"), &files).unwrap_err();
        assert!(e.to_string().starts_with("d.png"), "{e}");
    }
}
