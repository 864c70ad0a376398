//! The loaders' fuzzing entry points: each takes arbitrary bytes as one kind of user file,
//! loads it from memory ([`Memory`]) and checks what a load promises. The `cargo fuzz`
//! targets under `fuzz/` call these, and the corpus replay test calls them on every saved
//! input, so both exercise exactly the same code.
//!
//! What is checked beyond "no panic": a successful load's meshes pass
//! [`crate::Mesh::validate`] and every instance names a mesh and material that exist.

use super::{Loaded, Memory};
use crate::color::Encoding;
use std::path::Path;

/// Called once by each fuzz target before fuzzing: puts back Rust's default panic hook in
/// place of libFuzzer's aborting one, so that a panic inside a third-party decoder, which
/// the loaders catch and turn into an error, is not counted as a crash. A panic that
/// escapes a loader still aborts the run (libfuzzer-sys catches it at the target's edge).
pub fn init() {
    drop(std::panic::take_hook());
}

/// A 2 x 2 PNG the models may refer to as `t.png` (so texture paths are exercised).
pub const TEXTURE_PNG: &[u8] = &[
    0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0x00, 0x00, 0x00, 0x0D, 0x49, 0x48, 0x44, 0x52,
    0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x02, 0x00, 0x00, 0x00, 0xFD, 0xD4, 0x9A,
    0x73, 0x00, 0x00, 0x00, 0x12, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9C, 0x63, 0xF8, 0xCF, 0xC0, 0xC0,
    0x00, 0xC2, 0x0C, 0xFF, 0x81, 0x00, 0x00, 0x1F, 0xEE, 0x05, 0xFB, 0x0B, 0xD9, 0x68, 0x8B, 0x00,
    0x00, 0x00, 0x00, 0x49, 0x45, 0x4E, 0x44, 0xAE, 0x42, 0x60, 0x82,
];

/// A GLB container of `json` and, when not empty, the binary chunk `bin` (each padded to
/// four bytes: spaces and zeros), as the specification lays it out. For tests and seeds.
pub fn glb_container(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    j.resize(j.len().div_ceil(4) * 4, b' ');
    let mut b = bin.to_vec();
    b.resize(b.len().div_ceil(4) * 4, 0);
    let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&j);
    if !b.is_empty() {
        out.extend_from_slice(&(b.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&b);
    }
    out
}

/// A small binary buffer the glTF inputs may refer to as `b.bin`.
fn buffer() -> Vec<u8> {
    (0..=255u8).cycle().take(1024).collect()
}

/// Panics when a successful load breaks the loaders' promises.
fn check(result: Result<Loaded, super::LoadError>) {
    let Ok(loaded) = result else { return };
    let scene = &loaded.scene;
    for (i, m) in scene.meshes.iter().enumerate() {
        if let Err(e) = m.validate() {
            panic!("mesh {i} fails validation after a successful load: {e}");
        }
    }
    for inst in &scene.instances {
        assert!(
            inst.mesh < scene.meshes.len(),
            "instance names a missing mesh"
        );
        assert!(
            inst.material < scene.materials.len(),
            "instance names a missing material"
        );
    }
}

/// An OBJ, and after the first NUL byte (if any) the MTL library `m.mtl` it may use.
pub fn obj(data: &[u8]) {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &[][..]),
    };
    let files = Memory::default()
        .with("m.obj", obj)
        .with("m.mtl", mtl)
        .with("t.png", TEXTURE_PNG);
    check(super::obj_from(Path::new("m.obj"), &files));
}

/// A glTF JSON file, beside `b.bin` and `t.png`.
pub fn gltf(data: &[u8]) {
    let files = Memory::default()
        .with("m.gltf", data)
        .with("b.bin", buffer())
        .with("t.png", TEXTURE_PNG);
    check(super::gltf_from(Path::new("m.gltf"), &files));
}

/// A GLB file, beside `b.bin` and `t.png`.
pub fn glb(data: &[u8]) {
    let files = Memory::default()
        .with("m.glb", data)
        .with("b.bin", buffer())
        .with("t.png", TEXTURE_PNG);
    check(super::gltf_from(Path::new("m.glb"), &files));
}

/// The most pixels an image input may declare to be decoded by the `image` crate: larger images
/// decode correctly but take long enough (a 2048 x 2048 JPEG from a 10 KB file, 0.4 s) to
/// trip libFuzzer's one-second hang limit on a busy machine, which would hide real hangs.
/// The size limits themselves are unit-tested.
pub const FUZZ_IMAGE_PIXELS: u64 = 1 << 20;

/// An image file through the texture path (format guessed from the bytes), as colour, when
/// its header declares at most [`FUZZ_IMAGE_PIXELS`].
pub fn image(data: &[u8]) {
    let declared = ::image::ImageReader::new(std::io::Cursor::new(data))
        .with_guessed_format()
        .ok()
        .and_then(|r| r.into_dimensions().ok());
    if declared.is_some_and(|(w, h)| w as u64 * h as u64 > FUZZ_IMAGE_PIXELS) {
        return;
    }
    let files = Memory::default().with("i.png", data);
    if let Ok(t) = super::image_from(Path::new("i.png"), Encoding::Srgb, &files) {
        assert!(
            t.width() > 0 && t.height() > 0,
            "a decoded texture is empty"
        );
    }
}

/// A depth map file: PFM, and the same bytes as OpenEXR and as a 16-bit PNG. A decoded
/// image holds exactly its width times height values.
pub fn float_image(data: &[u8]) {
    let files = Memory::default()
        .with("d.pfm", data)
        .with("d.exr", data)
        .with("d.png", data);
    for name in ["d.pfm", "d.exr", "d.png"] {
        if let Ok(img) = super::float_image_from(Path::new(name), &files) {
            assert_eq!(
                img.data.len() as u64,
                img.width as u64 * img.height as u64,
                "a float image's size and data disagree"
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_texture_decodes() {
        let files = Memory::default().with("t.png", TEXTURE_PNG);
        let t = super::super::image_from(Path::new("t.png"), Encoding::Srgb, &files).unwrap();
        assert_eq!((t.width(), t.height()), (2, 2));
    }
}
