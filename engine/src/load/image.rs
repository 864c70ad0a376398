//! Image decoding for the loaders: bytes -> RGBA8 -> [`Texture`], with `image::Limits` so a
//! file's header cannot make us allocate more than [`MAX_IMAGE_ALLOC`] or exceed
//! [`MAX_TEXTURE_SIZE`] per side.

use super::LoadError;
use crate::color::Encoding;
use crate::texture::{Texture, MAX_TEXTURE_SIZE};
use ::image::{ImageFormat, ImageReader, Limits};
use std::io::Cursor;
use std::path::Path;

/// The most the image decoder may allocate for one image (1 GiB: a 16384 x 16384 RGBA8
/// image).
pub const MAX_IMAGE_ALLOC: u64 = 1 << 30;

/// Why bytes did not become a texture.
#[derive(Debug)]
pub(crate) enum ImageFailure {
    Decode(::image::ImageError),
    Size(u32, u32),
    /// The decoder panicked on the bytes (a bug of the decoder, caught: see [`guarded`]).
    Panic(String),
}

impl ImageFailure {
    pub(crate) fn into_load_error(self, file: &Path) -> LoadError {
        match self {
            ImageFailure::Decode(source) => LoadError::Image {
                file: file.into(),
                source,
            },
            ImageFailure::Size(w, h) => LoadError::invalid(
                file,
                format!("image is {w} x {h}; sides must be 1..={MAX_TEXTURE_SIZE}"),
            ),
            ImageFailure::Panic(why) => LoadError::invalid(file, panic_message(&why)),
        }
    }
}

impl std::fmt::Display for ImageFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ImageFailure::Decode(e) => write!(f, "{e}"),
            ImageFailure::Size(w, h) => {
                write!(
                    f,
                    "image is {w} x {h}; sides must be 1..={MAX_TEXTURE_SIZE}"
                )
            }
            ImageFailure::Panic(why) => write!(f, "{}", panic_message(why)),
        }
    }
}

fn panic_message(why: &str) -> String {
    format!("the image decoder failed on this file (it panicked: {why}); the file is damaged or unusual")
}

/// Runs a third-party decoder, turning a panic inside it into an error: fuzzing found
/// inputs that make the `png` and `zune-jpeg` decoders panic (a slice index in palette
/// expansion, an assertion in the AVX2 upsampler), and a user's file must give an error,
/// not bring the program down.
pub(crate) fn guarded<T>(decode: impl FnOnce() -> T) -> Result<T, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode)).map_err(|e| {
        e.downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| e.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".into())
    })
}

/// The decoder limits every loader uses.
pub(crate) fn limits() -> Limits {
    let mut l = Limits::default();
    l.max_image_width = Some(MAX_TEXTURE_SIZE);
    l.max_image_height = Some(MAX_TEXTURE_SIZE);
    l.max_alloc = Some(MAX_IMAGE_ALLOC);
    l
}

/// A format from a MIME type (`image/png`, `image/jpeg`), as glTF images carry it.
pub(crate) fn format_from_mime(mime: &str) -> Option<ImageFormat> {
    ImageFormat::from_mime_type(mime)
}

/// Decodes PNG or JPEG bytes into a texture. The format is sniffed from the bytes;
/// `hint` is used only when sniffing fails.
pub(crate) fn texture_from_bytes(
    bytes: &[u8],
    hint: Option<ImageFormat>,
    encoding: Encoding,
) -> Result<Texture, ImageFailure> {
    let mut reader = ImageReader::new(Cursor::new(bytes));
    if let Some(f) = hint {
        reader.set_format(f);
    }
    let mut reader = reader
        .with_guessed_format()
        .map_err(|e| ImageFailure::Decode(e.into()))?;
    reader.limits(limits());
    let img = guarded(|| reader.decode())
        .map_err(ImageFailure::Panic)?
        .map_err(ImageFailure::Decode)?;
    let (w, h) = (img.width(), img.height());
    if w == 0 || h == 0 || w > MAX_TEXTURE_SIZE || h > MAX_TEXTURE_SIZE {
        return Err(ImageFailure::Size(w, h));
    }
    let rgba = img.into_rgba8();
    Texture::from_rgba8(w, h, rgba.as_raw(), encoding).ok_or(ImageFailure::Size(w, h))
}

/// Decodes PNG or JPEG bytes (format sniffed) to straight RGBA8, within the loaders'
/// limits. `file` names the image in errors.
pub fn rgba8_from_bytes(bytes: &[u8], file: &Path) -> Result<(u32, u32, Vec<u8>), LoadError> {
    let fail = |e: ImageFailure| e.into_load_error(file);
    let reader = ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| fail(ImageFailure::Decode(e.into())))?;
    let mut reader = reader;
    reader.limits(limits());
    let img = guarded(|| reader.decode())
        .map_err(|e| fail(ImageFailure::Panic(e)))?
        .map_err(|e| fail(ImageFailure::Decode(e)))?;
    let (w, h) = (img.width(), img.height());
    if w == 0 || h == 0 || w > MAX_TEXTURE_SIZE || h > MAX_TEXTURE_SIZE {
        return Err(fail(ImageFailure::Size(w, h)));
    }
    Ok((w, h, img.into_rgba8().into_raw()))
}

/// Writes straight RGBA8 pixels (row-major, top row first) as a PNG file.
pub fn write_png_rgba8(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<(), LoadError> {
    ::image::save_buffer_with_format(
        path,
        rgba,
        width,
        height,
        ::image::ColorType::Rgba8,
        ImageFormat::Png,
    )
    .map_err(|source| LoadError::Image {
        file: path.into(),
        source,
    })
}
