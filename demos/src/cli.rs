//! What the command-line tools share: their flag vocabulary, the clap recipe that lets a
//! vector flag take negative numbers, parsing of vector arguments, and the empty-output
//! check behind their warnings.
//!
//! # The shared vocabulary
//!
//! Every tool that takes these spells them the same way:
//!
//! | flag | meaning |
//! |---|---|
//! | `-W`, `--width` / `-H`, `--height` | output size in pixels |
//! | `--eye X,Y,Z` | camera position |
//! | `--target X,Y,Z` | the point the camera looks at |
//! | `--up X,Y,Z` | the camera's up direction |
//! | `--fov-y DEG` | vertical field of view, degrees |
//! | `--near`, `--far` | clip distances |
//! | `--out PATH` | the output: a file for tools writing one image, a folder for tools writing several |
//! | `--threads N` | worker threads |
//!
//! Older spellings stay as hidden aliases (`#[arg(long = "out", alias = "png")]`), so
//! scripts keep working while `--help` shows one word per idea. Each tool's `--help`
//! opens with its own job: give the `Args` struct a one-line doc comment and **no** bare
//! `about` in `#[command(...)]` (a bare `about` replaces the doc line with the crate's
//! description, which every binary shares).
//!
//! # Negative numbers in vector flags
//!
//! Clap takes a value starting with `-` for a flag unless told otherwise, so
//! `--eye -1,2,3` fails with "unexpected argument '-1' found". `allow_negative_numbers`
//! on the command is not enough for vectors: it only accepts values that parse as one
//! number, and `-1,2,3` does not. The recipe:
//!
//! ```text
//! /// One line saying what this tool does.
//! #[derive(clap::Parser)]
//! #[command(name = "tool", version, allow_negative_numbers = true)] // `--near -1` reaches the check
//! struct Args {
//!     #[arg(long, value_name = "X,Y,Z", allow_hyphen_values = true, value_parser = parse_vec3)]
//!     eye: Vec3,
//! }
//! ```
//!
//! `allow_hyphen_values` on each vector flag (one value each: a flag name where the vector
//! should be, `--eye --target 1,2,3`, is still refused, as the stray `1,2,3`). `--eye=-1,2,3`
//! works either way.
//!
//! # Warnings
//!
//! A tool whose output is empty or almost empty says so in one line on stderr,
//! `TOOL: warning: ...`, naming what was covered and the flags to change; [`almost_empty`]
//! is the shared threshold.

use glam::Vec3;

/// Parses `x,y,z` (three finite numbers) for a clap argument.
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("expected x,y,z: {e}"))?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("expected three finite numbers x,y,z, got {s:?}")),
    }
}

/// Whether `covered` pixels of `total` make an (almost) empty image, worth a warning:
/// fewer than one pixel in a thousand (and always when none is).
pub fn almost_empty(covered: usize, total: usize) -> bool {
    covered == 0 || covered.saturating_mul(1000) < total
}

/// `x,y,z` with up to four significant decimals, as a vector flag takes it.
pub fn format_vec3(v: Vec3) -> String {
    let f = |x: f32| {
        let s = format!("{x:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".to_string()
        } else {
            s.to_string()
        }
    };
    format!("{},{},{}", f(v.x), f(v.y), f(v.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn vectors_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_vec3("1, -2,3.5"), Ok(Vec3::new(1.0, -2.0, 3.5)));
        for bad in ["1,2", "1,2,3,4", "a,b,c", "1,nan,2", ""] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
    }

    /// The recipe of the module doc, as written there.
    #[derive(Debug, Parser)]
    #[command(name = "tool", allow_negative_numbers = true)]
    struct Recipe {
        #[arg(long, allow_hyphen_values = true, value_parser = parse_vec3)]
        eye: Vec3,
        #[arg(long, allow_hyphen_values = true, value_parser = parse_vec3, default_value = "0,0,0")]
        target: Vec3,
        #[arg(long, default_value_t = 0.1)]
        near: f32,
    }

    #[test]
    fn the_recipe_takes_negative_vectors_and_numbers() {
        let r = Recipe::try_parse_from(["tool", "--eye", "-1,2,-3", "--target", "-0.5,-1,0"])
            .expect("negative vectors");
        assert_eq!(r.eye, Vec3::new(-1.0, 2.0, -3.0));
        assert_eq!(r.target, Vec3::new(-0.5, -1.0, 0.0));
        let r = Recipe::try_parse_from(["tool", "--eye=-1,2,3", "--near", "-2"]).unwrap();
        assert_eq!((r.eye, r.near), (Vec3::new(-1.0, 2.0, 3.0), -2.0));
        // A flag name where the value should be is still refused.
        let e = Recipe::try_parse_from(["tool", "--eye", "--target", "1,2,3"]).unwrap_err();
        assert!(e.to_string().contains("'1,2,3'"), "{e}");
    }

    #[test]
    fn emptiness_and_vectors_print() {
        assert!(almost_empty(0, 10));
        assert!(almost_empty(307, 640 * 480));
        assert!(!almost_empty(308, 640 * 480));
        assert!(!almost_empty(1, 1));
        assert_eq!(format_vec3(Vec3::new(100.0, -0.25, -0.0)), "100,-0.25,0");
        assert_eq!(
            format_vec3(Vec3::new(1.0 / 3.0, 2.5e-5, -7.0)),
            "0.3333,0,-7"
        );
    }
}
