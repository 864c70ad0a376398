//! Poses as `transform_matrix` holds them: camera to world, four rows of four, read and
//! written in `f64` so that a pose survives the file: the writer inverts the view in `f64`
//! and writes an exact last row `0 0 0 1`; the reader accepts a last row within
//! [`LAST_ROW_TOLERANCE`] of it (as `f32` writers leave it), sets it exactly and inverts in
//! `f64` before converting to the engine's `f32`.

use glam::{DMat4, Mat4};
use serde_json::Value;

/// How far from `0 0 0 1` a read last row may be (each entry).
pub const LAST_ROW_TOLERANCE: f64 = 1e-5;

/// The exact last row of an affine matrix.
const LAST_ROW: [f64; 4] = [0.0, 0.0, 0.0, 1.0];

/// `m` (rows) with its last row set to exactly `0 0 0 1`.
fn affine(mut rows: [[f64; 4]; 4]) -> [[f64; 4]; 4] {
    rows[3] = LAST_ROW;
    rows
}

/// The world -> view matrix of a frame's camera-to-world `transform_matrix` (4 rows of 4).
pub(super) fn pose(value: Option<&Value>) -> Result<Mat4, String> {
    let rows = value
        .and_then(Value::as_array)
        .filter(|r| r.len() == 4)
        .ok_or("\"transform_matrix\" is not 4 rows")?;
    let mut m = [[0.0f64; 4]; 4];
    for (r, row) in rows.iter().enumerate() {
        let row = row
            .as_array()
            .filter(|c| c.len() == 4)
            .ok_or("a \"transform_matrix\" row is not 4 numbers")?;
        for (c, v) in row.iter().enumerate() {
            m[r][c] = v
                .as_f64()
                .filter(|x| x.is_finite() && x.abs() < f32::MAX as f64)
                .ok_or("\"transform_matrix\" holds something other than finite numbers")?;
        }
    }
    if m[3]
        .iter()
        .zip(LAST_ROW)
        .any(|(a, b)| (a - b).abs() > LAST_ROW_TOLERANCE)
    {
        return Err(format!(
            "\"transform_matrix\" is not affine: its last row {:?} must be 0 0 0 1 (within {LAST_ROW_TOLERANCE:e})",
            m[3]
        ));
    }
    let c2w = DMat4::from_cols_array_2d(&affine(m)).transpose();
    let det = c2w.determinant();
    if det.abs() <= 1e-12 || !det.is_finite() {
        return Err("\"transform_matrix\" is singular".into());
    }
    let view = DMat4::from_cols_array_2d(&affine(c2w.inverse().transpose().to_cols_array_2d()))
        .transpose()
        .as_mat4();
    if !view.is_finite() {
        return Err("\"transform_matrix\" cannot be inverted".into());
    }
    Ok(view)
}

/// The rows of the camera-to-world matrix of `view` (world -> view), inverted in `f64`,
/// with an exact last row.
pub(super) fn camera_to_world_rows(view: &Mat4) -> [[f64; 4]; 4] {
    affine(view.as_dmat4().inverse().transpose().to_cols_array_2d())
}

#[cfg(test)]
mod tests {
    use super::*;
    use engine::Camera;
    use glam::Vec3;

    /// The pose of the issue: an eye and target whose `f32` inverse left 0.99999988.
    fn odd() -> Mat4 {
        let eye = glam::DVec3::new(-61.70723, 62.5967785, -205.712078).as_vec3();
        let target = Vec3::new(0.0086, 21.45, 0.0072);
        Camera::look_at(eye, target, Vec3::Y, 0.8, 1.5).view
    }

    #[test]
    fn the_issue_pose_is_written_exactly_and_read_back() {
        let view = odd();
        // The old writer: the inverse in f32 does not end in an exact 0 0 0 1.
        let f32_rows = view.inverse().transpose().to_cols_array_2d();
        assert_ne!(f32_rows[3], [0.0, 0.0, 0.0, 1.0], "the case of the issue");
        let rows = camera_to_world_rows(&view);
        assert_eq!(rows[3], LAST_ROW);
        let back = pose(Some(&serde_json::json!(rows))).unwrap();
        for (a, b) in back.to_cols_array().iter().zip(view.to_cols_array()) {
            assert!((a - b).abs() <= 1e-6 * (1.0 + b.abs()), "{back} vs {view}");
        }
        // A file written by an f32 writer reads too, its last row set exact.
        let f32_file: Vec<Vec<f64>> = f32_rows
            .iter()
            .map(|r| r.iter().map(|x| *x as f64).collect())
            .collect();
        let back = pose(Some(&serde_json::json!(f32_file))).unwrap();
        for (a, b) in back.to_cols_array().iter().zip(view.to_cols_array()) {
            assert!((a - b).abs() <= 1e-5 * (1.0 + b.abs()), "{back} vs {view}");
        }
    }

    #[test]
    fn a_last_row_beyond_the_tolerance_is_refused() {
        let mut rows = camera_to_world_rows(&odd());
        rows[3][3] = 1.0 + 2e-5;
        let e = pose(Some(&serde_json::json!(rows))).unwrap_err();
        assert!(e.contains("not affine") && e.contains("1e-5"), "{e}");
        rows[3][3] = 1.0 - 9e-6;
        rows[3][0] = -9e-6;
        assert!(pose(Some(&serde_json::json!(rows))).is_ok());
    }
}
