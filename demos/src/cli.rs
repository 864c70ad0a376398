//! What the command-line tools share: parsing of vector arguments.

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vectors_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_vec3("1, -2,3.5"), Ok(Vec3::new(1.0, -2.0, 3.5)));
        for bad in ["1,2", "1,2,3,4", "a,b,c", "1,nan,2", ""] {
            assert!(parse_vec3(bad).is_err(), "{bad}");
        }
    }
}
