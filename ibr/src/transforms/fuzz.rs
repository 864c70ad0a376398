//! The fuzzing entry point of `transforms.json` captures, shared by the `cargo fuzz` target
//! and the corpus replay test; production code, so it takes none of `engine`'s test hooks.

use super::{read_transforms_from, EMPTY};
use engine::load;
use std::path::Path;

/// A 2 x 2 RGB PNG, the capture's colour image `a.png`.
const TEXTURE_PNG: &[u8] = &[
    0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0x00, 0x00, 0x00, 0x0D, 0x49, 0x48, 0x44, 0x52,
    0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x08, 0x02, 0x00, 0x00, 0x00, 0xFD, 0xD4, 0x9A,
    0x73, 0x00, 0x00, 0x00, 0x12, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9C, 0x63, 0xF8, 0xCF, 0xC0, 0xC0,
    0x00, 0xC2, 0x0C, 0xFF, 0x81, 0x00, 0x00, 0x1F, 0xEE, 0x05, 0xFB, 0x0B, 0xD9, 0x68, 0x8B, 0x00,
    0x00, 0x00, 0x00, 0x49, 0x45, 0x4E, 0x44, 0xAE, 0x42, 0x60, 0x82,
];

/// The fuzzing entry point (`fuzz/`, and the corpus replay test): `data` as a
/// `transforms.json` whose folder holds a 2 x 2 colour image `a.png` and depth maps
/// `a.pfm` (2 x 2) and `b.pfm` (1 x 1). A capture that loads has one camera a frame, each
/// with finite, invertible matrices and positive depths.
pub fn fuzz(data: &[u8]) {
    let files = load::Memory::default()
        .with("c/transforms.json", data)
        .with("c/a.png", TEXTURE_PNG)
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
