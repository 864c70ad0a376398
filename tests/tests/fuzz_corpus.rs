//! Replays every saved fuzzing input (`fuzz/corpus/<target>/`) through the same entry
//! points the `cargo fuzz` targets call (`engine::load::fuzz`), on stable Rust without
//! libFuzzer, so a loader change that panics on a known input fails the ordinary suite.
//! The corpora start from `fuzz/seeds.py` and grow with the long runs of `fuzz/run.sh`.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// A fuzz target's entry point: takes the raw bytes, must never panic.
type Target = fn(&[u8]);

const TARGETS: [(&str, Target); 6] = [
    ("obj", engine::load::fuzz::obj),
    ("gltf", engine::load::fuzz::gltf),
    ("glb", engine::load::fuzz::glb),
    ("image", engine::load::fuzz::image),
    ("float_image", engine::load::fuzz::float_image),
    ("transforms", ibr::images::transforms::fuzz),
];

fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz/corpus")
        .join(target);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

#[test]
fn every_saved_fuzz_input_loads_or_fails_cleanly() {
    for (target, run) in TARGETS {
        let files = corpus(target);
        assert!(
            files.iter().any(|f| f
                .file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("seed-"))),
            "{target}: no seeds (run fuzz/seeds.py)"
        );
        let mut failed = Vec::new();
        for f in &files {
            let bytes = std::fs::read(f).expect("read corpus file");
            if catch_unwind(AssertUnwindSafe(|| run(&bytes))).is_err() {
                failed.push(f.display().to_string());
            }
        }
        assert!(failed.is_empty(), "{target}: panicked on {failed:?}");
        println!("{target}: {} inputs replayed", files.len());
    }
}

#[test]
fn the_hand_written_depth_map_seeds_are_valid_files() {
    // fuzz/seeds.py writes PFM and OpenEXR byte by byte from the formats' specifications;
    // these must decode to the values it wrote, or the fuzzer starts from nothing useful.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus/float_image");
    let cases: [(&str, u32, u32, &[f32]); 4] = [
        // PFM rows run bottom to top in the file: the file's first row is the last here.
        (
            "seed-small.pfm",
            3,
            2,
            &[4.0, 0.5, 1e-3, 1.0, 2.5, f32::INFINITY],
        ),
        ("seed-big_endian.pfm", 2, 2, &[3.0, 4.0, 1.0, 2.0]),
        ("seed-grey.exr", 2, 2, &[1.0, 2.0, f32::INFINITY, 0.5]),
        ("seed-rgb.exr", 3, 1, &[1.0, 2.0, 3.0]),
    ];
    for (name, w, h, values) in cases {
        let img = engine::load::float_image(&dir.join(name)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((img.width, img.height), (w, h), "{name}");
        assert_eq!(img.data, values, "{name}");
    }
}

#[test]
fn a_decoder_that_panics_gives_an_error_or_a_placeholder_not_a_crash() {
    // Found by the glb target (7.26 million executions in): a PNG inside a GLB whose
    // palette makes the png crate (0.18.1) index past a slice. The texture falls back to
    // the placeholder with a warning naming the failure; the model still loads.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus");
    let glb = std::fs::read(dir.join("glb/regress-png_palette_panic.glb")).unwrap();
    let files = engine::load::Memory::default()
        .with("m.glb", glb)
        .with("b.bin", vec![0u8; 1024])
        .with("t.png", engine::load::fuzz::TEXTURE_PNG);
    match engine::load::gltf_from(Path::new("m.glb"), &files) {
        Ok(loaded) => assert!(
            loaded.warnings.iter().any(|w| w.contains("decoder failed")),
            "{:?}",
            loaded.warnings
        ),
        Err(e) => assert!(e.to_string().contains("decoder failed"), "{e}"),
    }
    // Found by the image target: a JPEG that trips an assertion in zune-jpeg's AVX2
    // upsampler (other machines take another path, which may decode or refuse it).
    let jpeg = std::fs::read(dir.join("image/regress-jpeg_upsampler_panic.jpg")).unwrap();
    let files = engine::load::Memory::default().with("i.jpg", jpeg);
    if let Err(e) = engine::load::image_from(Path::new("i.jpg"), engine::Encoding::Srgb, &files) {
        assert!(e.to_string().starts_with("i.jpg"), "{e}");
    }
}
