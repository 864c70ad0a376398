//! Single-channel float images, the files depth maps are exchanged in: PFM (the Portable
//! Float Map of Middlebury, ETH3D and most stereo and depth tools), OpenEXR (through the
//! `exr` crate) and 16-bit grey PNG (the integer depth maps of RGB-D cameras, instant-ngp
//! and nerfstudio).
//!
//! A [`FloatImage`] is row-major with the **top row first**, like every image in the engine.
//!
//! - **PFM** (as the Middlebury stereo pages describe it): a header `Pf` (one channel) or
//!   `PF` (three), the width and height, and a scale whose sign gives the byte order
//!   (negative: little-endian, positive: big-endian; its magnitude is not applied), each
//!   token ended by whitespace, then raw 32-bit floats, **rows bottom to top**;
//!   [`parse_pfm`] and [`pfm_bytes`] turn them over. A `PF` file is a depth map only when
//!   its three channels are equal in every pixel (a grey image); one whose channels differ
//!   is refused, since nothing says which one is the depth. We write `Pf`, little-endian,
//!   scale -1.
//! - **OpenEXR**: from the first layer one channel is read, the first name found in this
//!   order: `Z`, `depth` (any case), a name ending in `.Z` or `Depth` (Blender's passes,
//!   `ViewLayer.Depth.Z`), `Y` (luminance), `R`; a layer of one channel is read whatever
//!   its name, and one of several channels none of which is named so is refused (the error
//!   lists them). We write one 32-bit `Z` channel, losslessly compressed.
//! - **PNG**: one 16-bit grey channel ([`parse_png16`]); the values are the integers
//!   stored (0 to 65535): what unit they count is said by the file that names the image
//!   (`ibr::images::transforms` applies `integer_depth_scale` or
//!   `depth_unit_scale_factor`). Any other PNG (8-bit, colour) is refused.
//!
//! Values are passed through as they are (NaN, zero and infinities included): what they
//! mean is the reader's business (`ibr::images` takes infinity and 0 as "nothing there").

use super::{Files, LoadError, MAX_FILE_BYTES};
use crate::texture::MAX_TEXTURE_SIZE;
use std::path::Path;

/// A one-channel `f32` image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct FloatImage {
    /// Columns, pixels.
    pub width: u32,
    /// Rows, pixels.
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

/// Reads a `.pfm`, `.exr` or 16-bit `.png` file (chosen by the extension, any case) from
/// `files`.
pub fn float_image_from(path: &Path, files: &dyn Files) -> Result<FloatImage, LoadError> {
    let bytes = files.read(path, MAX_FILE_BYTES)?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("pfm") => parse_pfm(&bytes).map_err(|e| LoadError::invalid(path, e)),
        Some("exr") => parse_exr(&bytes).map_err(|e| LoadError::invalid(path, e)),
        Some("png") => parse_png16(&bytes).map_err(|e| LoadError::invalid(path, e)),
        _ => Err(LoadError::invalid(
            path,
            "not a depth map: expected a .pfm, .exr or 16-bit .png file",
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
    let value = |at: usize| {
        let b: [u8; 4] = data[at..at + 4].try_into().unwrap_or([0; 4]);
        if little {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        }
    };
    let mut out = vec![0.0; w * h];
    for (row, dst) in out.chunks_exact_mut(w).enumerate() {
        // File rows run bottom to top.
        let start = (h - 1 - row) * w * channels * 4;
        for (x, v) in dst.iter_mut().enumerate() {
            let at = start + x * channels * 4;
            *v = value(at);
            // A three-channel file is a depth map only as a grey image.
            if channels == 3 {
                let (g, b) = (value(at + 4), value(at + 8));
                if g.to_bits() != v.to_bits() || b.to_bits() != v.to_bits() {
                    return Err(format!(
                        "PF (three-channel) PFM with unequal channels at pixel ({x}, {row}): {v}, {g}, {b}; a depth map is one channel ('Pf') or three equal ones"
                    ));
                }
            }
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

/// Decodes a 16-bit grey PNG: its integers (0 to 65535) as `f32`, exactly. Other PNGs are
/// refused, naming what they hold.
pub fn parse_png16(bytes: &[u8]) -> Result<FloatImage, String> {
    use ::image::{DynamicImage, ImageFormat, ImageReader};
    let mut reader = ImageReader::with_format(std::io::Cursor::new(bytes), ImageFormat::Png);
    reader.limits(super::image::limits());
    let decoded = super::image::guarded(|| reader.decode())
        .map_err(|why| format!("the PNG decoder failed on this file (it panicked: {why})"))?
        .map_err(|e| format!("bad PNG: {e}"))?;
    let DynamicImage::ImageLuma16(grey) = decoded else {
        return Err(format!(
            "a PNG depth map must be one 16-bit grey channel; this one is {:?}",
            decoded.color()
        ));
    };
    let (w, h) = grey.dimensions();
    check_size(w, h)?;
    let data = grey.into_raw().into_iter().map(f32::from).collect();
    FloatImage::new(w, h, data).ok_or_else(|| "PNG size and data disagree".into())
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
    let pick = exr_depth_channel(list.iter().map(|c| c.name.to_string()))?;
    let pick = &list[pick];
    if pick.sampling != Vec2(1, 1) {
        return Err("subsampled OpenEXR channels are not a depth map".into());
    }
    check_size(w as u32, h as u32)?;
    let data: Vec<f32> = pick.sample_data.values_as_f32().collect();
    FloatImage::new(w as u32, h as u32, data)
        .ok_or_else(|| "OpenEXR channel size and data disagree".into())
}

/// Which of an OpenEXR layer's channels (by name, in order) holds the depth (module docs).
fn exr_depth_channel(names: impl Iterator<Item = String>) -> Result<usize, String> {
    let names: Vec<String> = names.collect();
    let find = |rule: &dyn Fn(&str) -> bool| names.iter().position(|n| rule(n));
    let rules: [&dyn Fn(&str) -> bool; 5] = [
        &|n| n == "Z",
        &|n| n.eq_ignore_ascii_case("depth"),
        &|n| n.ends_with(".Z") || n.ends_with("Depth"),
        &|n| n == "Y",
        &|n| n == "R",
    ];
    if let Some(i) = rules.iter().find_map(|rule| find(rule)) {
        return Ok(i);
    }
    match names.len() {
        0 => Err("OpenEXR layer has no channels".into()),
        1 => Ok(0),
        _ => Err(format!(
            "OpenEXR layer has no depth channel (Z, depth, *.Z, *Depth, Y or R) among {}",
            names.join(", ")
        )),
    }
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

    /// PFM bytes as the Middlebury pages describe them, assembled by hand: `kind`, the
    /// size, `scale`, then `rows` of values **bottom row first**, each value's bytes in
    /// the byte order the scale's sign names.
    fn pfm(kind: &str, w: u32, scale: &str, rows_bottom_first: &[&[f32]]) -> Vec<u8> {
        let h = rows_bottom_first.len();
        let mut b = format!("{kind}\n{w} {h}\n{scale}\n").into_bytes();
        let little = scale.starts_with('-');
        for row in rows_bottom_first {
            for v in *row {
                b.extend_from_slice(&if little {
                    v.to_le_bytes()
                } else {
                    v.to_be_bytes()
                });
            }
        }
        b
    }

    #[test]
    fn middlebury_pfm_reads_in_both_byte_orders() {
        // 2 x 2: bottom row (3, 4), top row (1, inf); the image's top row comes first.
        let rows: [&[f32]; 2] = [&[3.0, 4.0], &[1.0, f32::INFINITY]];
        let want = vec![1.0, f32::INFINITY, 3.0, 4.0];
        for scale in ["-1.0", "1.0", "-0.5", "2"] {
            let img = parse_pfm(&pfm("Pf", 2, scale, &rows)).unwrap();
            assert_eq!((img.width, img.height), (2, 2));
            assert_eq!(img.data, want, "scale {scale}");
        }
        // The byte order matters: big-endian bytes read as little-endian are other numbers.
        let big = pfm("Pf", 2, "1.0", &rows);
        let mut swapped = b"Pf\n2 2\n-1.0\n".to_vec();
        swapped.extend_from_slice(&big[big.len() - 16..]);
        assert_ne!(parse_pfm(&swapped).unwrap().data, want);
    }

    #[test]
    fn three_channel_pfm_reads_when_grey_and_is_refused_otherwise() {
        // 1 x 2, three equal channels, big-endian (positive scale).
        let grey: [&[f32]; 2] = [&[7.0, 7.0, 7.0], &[9.0, 9.0, 9.0]];
        let img = parse_pfm(&pfm("PF", 1, "1.0", &grey)).unwrap();
        assert_eq!((img.width, img.height), (1, 2));
        assert_eq!(img.data, vec![9.0, 7.0]);
        // Colour: which channel is the depth is not said; refused, naming the pixel.
        let colour: [&[f32]; 2] = [&[7.0, 0.0, 0.0], &[9.0, 9.0, 9.0]];
        let e = parse_pfm(&pfm("PF", 1, "-1.0", &colour)).unwrap_err();
        assert!(e.contains("unequal channels at pixel (0, 1)"), "{e}");
    }

    #[test]
    fn sixteen_bit_png_reads_its_integers_exactly() {
        use ::image::{ImageBuffer, Luma, Rgb};
        let values: Vec<u16> = vec![0, 1, 1000, 65535, 12345, 40000];
        let grey: ImageBuffer<Luma<u16>, Vec<u16>> =
            ImageBuffer::from_raw(3, 2, values.clone()).unwrap();
        let mut bytes = Vec::new();
        grey.write_to(
            &mut std::io::Cursor::new(&mut bytes),
            ::image::ImageFormat::Png,
        )
        .unwrap();
        let files = super::super::Memory::default().with("d.PNG", bytes);
        let img = float_image_from(Path::new("d.PNG"), &files).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        let want: Vec<f32> = values.iter().map(|v| *v as f32).collect();
        assert_eq!(img.data, want);
        // An 8-bit colour PNG is no depth map.
        let rgb: ImageBuffer<Rgb<u8>, Vec<u8>> =
            ImageBuffer::from_raw(1, 1, vec![1, 2, 3]).unwrap();
        let mut bytes = Vec::new();
        rgb.write_to(
            &mut std::io::Cursor::new(&mut bytes),
            ::image::ImageFormat::Png,
        )
        .unwrap();
        let e = parse_png16(&bytes).unwrap_err();
        assert!(e.contains("16-bit grey") && e.contains("Rgb8"), "{e}");
    }

    #[test]
    fn exr_depth_channel_is_chosen_by_name() {
        let pick = |names: &[&str]| exr_depth_channel(names.iter().map(|n| n.to_string()));
        assert_eq!(pick(&["B", "G", "R", "Z"]), Ok(3));
        assert_eq!(pick(&["B", "G", "R", "depth"]), Ok(3));
        assert_eq!(pick(&["A", "Depth", "R"]), Ok(1));
        let blender = [
            "ViewLayer.Combined.A",
            "ViewLayer.Combined.R",
            "ViewLayer.Depth.Z",
        ];
        assert_eq!(pick(&blender), Ok(2));
        assert_eq!(pick(&["B", "G", "R"]), Ok(2));
        assert_eq!(pick(&["Y"]), Ok(0));
        assert_eq!(pick(&["distance"]), Ok(0));
        let e = pick(&["u", "v"]).unwrap_err();
        assert!(e.contains("u, v"), "{e}");
    }

    #[test]
    fn exr_written_with_colour_and_a_depth_channel_reads_the_depth() {
        use exr::prelude::*;
        // As a renderer writes it: colour channels beside a `depth` channel.
        let depth = vec![1.0f32, 2.0, 0.0, 4.5];
        let mut channels = SmallVec::new();
        for (name, data) in [
            ("R", vec![0.5f32; 4]),
            ("G", vec![0.25; 4]),
            ("depth", depth.clone()),
        ] {
            channels.push(AnyChannel::new(name, FlatSamples::F32(data)));
        }
        let layer = Layer::new(
            (2, 2),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            AnyChannels::sort(channels),
        );
        let mut bytes = Vec::new();
        Image::from_layer(layer)
            .write()
            .non_parallel()
            .to_buffered(std::io::Cursor::new(&mut bytes))
            .unwrap();
        assert_eq!(parse_exr(&bytes).unwrap().data, depth);
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
