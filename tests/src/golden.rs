//! The golden-image helper: compares a rendered [`Target`] with `tests/golden/NAME.png`.
//!
//! * A missing golden fails, saying how to create it.
//! * A mismatch writes `target/golden-out/NAME-expected.png`, `NAME-diff.png` and
//!   `NAME-actual.png` and fails.
//! * `UPDATE_GOLDEN=1` writes the rendered image as the new golden instead of comparing.
//!   Only do that after a human has looked at the image and agrees it is right, and only
//!   for tests that first check the render against an independent reference (so what is
//!   stored is, byte for byte, the reference's picture).
//!
//! Images are compared as straight RGBA8 bytes (`Target::to_rgba8`) with a per-channel
//! tolerance of [`TOLERANCE`].

use engine::Target;
use std::path::{Path, PathBuf};

/// Largest allowed per-channel byte difference. 0: the goldens are exact pictures of exact
/// references (coverage and constant colours), so any difference is a real change.
pub const TOLERANCE: u8 = 0;

/// Set to `1` to (re)write goldens. See the module docs before using it.
pub const UPDATE_ENV: &str = "UPDATE_GOLDEN";

/// `tests/golden/`.
pub fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("golden")
}

/// `target/golden-out/` in the workspace (where mismatches are written).
pub fn out_dir() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| manifest.join("..").join("target"));
    target.join("golden-out")
}

fn save(path: &Path, width: u32, height: u32, rgba: &[u8]) {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    }
    image::save_buffer(path, rgba, width, height, image::ExtendedColorType::Rgba8)
        .unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
}

/// Compares `target` with `tests/golden/NAME.png` (see the module docs).
///
/// # Panics
/// When the golden is missing, differs, or cannot be read or written.
pub fn check_golden(name: &str, target: &Target) {
    check_golden_rgba(name, target.width(), target.height(), &target.to_rgba8());
}

/// [`check_golden`] on straight RGBA8 bytes, row-major, top row first.
///
/// # Panics
/// When the golden is missing, differs, or cannot be read or written.
pub fn check_golden_rgba(name: &str, width: u32, height: u32, rgba: &[u8]) {
    assert_eq!(
        rgba.len(),
        width as usize * height as usize * 4,
        "{name}: size"
    );
    let path = golden_dir().join(format!("{name}.png"));
    if std::env::var(UPDATE_ENV).is_ok_and(|v| v == "1") {
        save(&path, width, height, rgba);
        eprintln!(
            "{UPDATE_ENV}=1: wrote {} -- look at it before committing it",
            path.display()
        );
        return;
    }
    let expected = match image::open(&path) {
        Ok(img) => img.to_rgba8(),
        Err(e) => panic!(
            "golden image {} is missing or unreadable ({e}).\n\
             To create it, run the test that calls check_golden(\"{name}\") with {UPDATE_ENV}=1,\n  \
             e.g. {UPDATE_ENV}=1 cargo test -p tests --test fill_rule golden\n\
             then LOOK at the written PNG and commit it only if it is right.",
            path.display()
        ),
    };
    let diff = diff_image(
        expected.width(),
        expected.height(),
        expected.as_raw(),
        width,
        height,
        rgba,
    );
    if let Some((bad, diff)) = diff {
        let out = out_dir();
        let (ew, eh) = expected.dimensions();
        save(
            &out.join(format!("{name}-expected.png")),
            ew,
            eh,
            expected.as_raw(),
        );
        save(&out.join(format!("{name}-actual.png")), width, height, rgba);
        save(
            &out.join(format!("{name}-diff.png")),
            width.max(ew),
            height.max(eh),
            &diff,
        );
        panic!(
            "{name}: {bad} pixels differ from {} (tolerance {TOLERANCE}); see {}/{name}-{{expected,diff,actual}}.png",
            path.display(),
            out.display()
        );
    }
}

/// Are two channel bytes equal within [`TOLERANCE`]?
fn within_tolerance(p: u8, q: u8) -> bool {
    p.abs_diff(q).saturating_sub(TOLERANCE) == 0
}

/// Compares two straight RGBA8 images. `None` when they match within [`TOLERANCE`];
/// otherwise the number of differing pixels and a diff image (size = the larger of the two):
/// red where they differ, dim grey copies of the expected image elsewhere.
pub fn diff_image(
    ew: u32,
    eh: u32,
    expected: &[u8],
    aw: u32,
    ah: u32,
    actual: &[u8],
) -> Option<(u64, Vec<u8>)> {
    let (w, h) = (ew.max(aw), eh.max(ah));
    let mut out = vec![0u8; w as usize * h as usize * 4];
    let mut bad = 0u64;
    let px = |img: &[u8], iw: u32, ih: u32, x: u32, y: u32| -> Option<[u8; 4]> {
        (x < iw && y < ih).then(|| {
            let i = (y * iw + x) as usize * 4;
            [img[i], img[i + 1], img[i + 2], img[i + 3]]
        })
    };
    for y in 0..h {
        for x in 0..w {
            let e = px(expected, ew, eh, x, y);
            let a = px(actual, aw, ah, x, y);
            let same = match (e, a) {
                (Some(e), Some(a)) => e.iter().zip(a).all(|(&p, q)| within_tolerance(p, q)),
                _ => false,
            };
            let o = (y * w + x) as usize * 4;
            if same {
                let e = e.unwrap_or_default();
                let g = ((e[0] as u32 + e[1] as u32 + e[2] as u32) / 12) as u8;
                out[o..o + 4].copy_from_slice(&[g, g, g, 255]);
            } else {
                bad += 1;
                out[o..o + 4].copy_from_slice(&[255, 0, 0, 255]);
            }
        }
    }
    (bad > 0).then_some((bad, out))
}

/// Fails with a written diff (like a golden mismatch) unless `actual` equals `expected`,
/// an image computed by an independent reference in the test itself.
///
/// # Panics
/// When the images differ.
pub fn assert_same_image(name: &str, width: u32, height: u32, expected: &[u8], actual: &[u8]) {
    if let Some((bad, diff)) = diff_image(width, height, expected, width, height, actual) {
        let out = out_dir();
        save(
            &out.join(format!("{name}-expected.png")),
            width,
            height,
            expected,
        );
        save(
            &out.join(format!("{name}-actual.png")),
            width,
            height,
            actual,
        );
        save(&out.join(format!("{name}-diff.png")), width, height, &diff);
        panic!(
            "{name}: {bad} pixels differ from the reference image; see {}/{name}-{{expected,diff,actual}}.png",
            out.display()
        );
    }
}
