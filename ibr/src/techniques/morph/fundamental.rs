//! The fundamental matrix of two uncalibrated views from point pairs, by Hartley's
//! normalised eight-point algorithm (1997): each image's points moved to mean 0 and mean
//! distance sqrt 2 from it, the linear system `A f = 0` solved in least squares (the
//! eigenvector of `A^T A` with the smallest eigenvalue), rank 2 enforced (the smallest
//! singular value zeroed), the normalisation undone.
//!
//! The eigenvectors come from a cyclic Jacobi solver on symmetric matrices of at most
//! 9 x 9, in `f64`: the only decomposition the algorithm needs (the rank-2 step and the
//! epipoles are eigenvectors of `F^T F` and `F F^T`), small enough not to bring in a linear
//! algebra crate.
//!
//! Points are in pixels of their image, x to the right and y down, continuous: pixel
//! `(i, j)` covers `[i, i + 1) x [j, j + 1)`, its centre at `(i + 0.5, j + 0.5)`.

use glam::{DMat3, DVec2, DVec3, Vec2};

/// Why the pairs give no fundamental matrix.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FundamentalError {
    /// Fewer than 8 point pairs: how many were given.
    #[error("{0} point pairs: the eight-point algorithm needs at least 8")]
    TooFew(usize),
    /// The pair at this index has a NaN or infinite coordinate.
    #[error("point pair {0} is not finite")]
    NotFinite(usize),
    /// All points of one image (named) are the same point.
    #[error("the points of the {0} image all coincide: nothing to normalise")]
    Coincident(&'static str),
    #[error(
        "the pairs do not fix one fundamental matrix (second-smallest singular value {0:.1e} of the normalised system): the points lie on a line or a plane, or too few are independent"
    )]
    /// The pairs fix no single matrix: the normalised system's second-smallest singular
    /// value.
    Degenerate(f64),
}

/// The fundamental matrix `F` of two views `a` and `b`: `x_b^T F x_a = 0` for the pixels
/// `x_a` and `x_b` (homogeneous, `(x, y, 1)`) that see one point. Rank 2, unit Frobenius
/// norm, and its epipoles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fundamental {
    f: DMat3,
    /// `F e_a = 0`: where `a` sees `b`'s eye (homogeneous, unit length).
    epipole_a: DVec3,
    /// `F^T e_b = 0`: where `b` sees `a`'s eye.
    epipole_b: DVec3,
}

impl Fundamental {
    /// The least-squares fundamental matrix of `pairs` (`(in a, in b)`, at least 8, not
    /// all on a line or a plane), by the normalised eight-point algorithm.
    pub fn from_points(pairs: &[(Vec2, Vec2)]) -> Result<Self, FundamentalError> {
        if pairs.len() < 8 {
            return Err(FundamentalError::TooFew(pairs.len()));
        }
        if let Some(i) = pairs
            .iter()
            .position(|(a, b)| !(a.is_finite() && b.is_finite()))
        {
            return Err(FundamentalError::NotFinite(i));
        }
        let pa: Vec<DVec2> = pairs.iter().map(|p| p.0.as_dvec2()).collect();
        let pb: Vec<DVec2> = pairs.iter().map(|p| p.1.as_dvec2()).collect();
        let ta = normaliser(&pa).ok_or(FundamentalError::Coincident("first"))?;
        let tb = normaliser(&pb).ok_or(FundamentalError::Coincident("second"))?;
        // The normal equations A^T A of the rows (x_b x_a^T, flattened row by row).
        let mut ata = [[0f64; 9]; 9];
        for (&a, &b) in pa.iter().zip(&pb) {
            let a = ta * a.extend(1.0);
            let b = tb * b.extend(1.0);
            let row = [
                b.x * a.x,
                b.x * a.y,
                b.x,
                b.y * a.x,
                b.y * a.y,
                b.y,
                a.x,
                a.y,
                1.0,
            ];
            for i in 0..9 {
                for j in 0..9 {
                    ata[i][j] += row[i] * row[j];
                }
            }
        }
        let (values, vectors) = symmetric_eigen(ata);
        // A second null vector: the pairs leave a family of solutions. (Points from one
        // plane, exact to f32, give 4e-8; the tests' scenes 0.03 to 0.08.)
        let largest = values[8].max(f64::MIN_POSITIVE);
        let second = (values[1].max(0.0) / largest).sqrt();
        if second.is_nan() || second <= 1e-4 {
            return Err(FundamentalError::Degenerate(second));
        }
        let f: [f64; 9] = std::array::from_fn(|k| vectors[k][0]);
        let fn_ = from_rows(&f);
        // Rank 2: F (I - v v^T) for the right singular vector v of the smallest singular
        // value drops that value and keeps the others.
        let v = smallest(fn_.transpose() * fn_);
        let fn2 = fn_ - fn_ * outer(v, v);
        let f = tb.transpose() * fn2 * ta;
        let norm = frobenius(f);
        if !(norm > 0.0 && norm.is_finite()) {
            return Err(FundamentalError::Degenerate(0.0));
        }
        let f = f * (1.0 / norm);
        let fundamental = Fundamental {
            f,
            epipole_a: smallest(f.transpose() * f),
            epipole_b: smallest(f * f.transpose()),
        };
        // Rank 1 (the two largest singular values not both there) fixes no epipole.
        let (values, _) = eigen3(f.transpose() * f);
        if values[1].max(0.0).sqrt() <= 1e-9 {
            return Err(FundamentalError::Degenerate(values[1].max(0.0).sqrt()));
        }
        Ok(fundamental)
    }

    /// The matrix (unit Frobenius norm; its sign is arbitrary).
    pub fn matrix(&self) -> DMat3 {
        self.f
    }

    /// `x_b^T F x_a`: zero for a pair on corresponding epipolar lines.
    pub fn residual(&self, a: Vec2, b: Vec2) -> f64 {
        b.as_dvec2()
            .extend(1.0)
            .dot(self.f * a.as_dvec2().extend(1.0))
    }

    /// The epipole of `a` (`F e_a = 0`, unit length, homogeneous): where `a` sees the eye
    /// of `b`; its last coordinate is near 0 when that is far outside the image.
    pub fn epipole_a(&self) -> DVec3 {
        self.epipole_a
    }

    /// The epipole of `b` (`F^T e_b = 0`): where `b` sees the eye of `a`.
    pub fn epipole_b(&self) -> DVec3 {
        self.epipole_b
    }

    /// The symmetric epipolar distance of a pair, in pixels: the root mean square of the
    /// distance from `b` to the epipolar line of `a` (`F x_a`) and from `a` to that of `b`
    /// (`F^T x_b`). Infinite where a line is undefined (a point on an epipole).
    pub fn distance(&self, a: Vec2, b: Vec2) -> f64 {
        let (xa, xb) = (a.as_dvec2().extend(1.0), b.as_dvec2().extend(1.0));
        let (lb, la) = (self.f * xa, self.f.transpose() * xb);
        let r = xb.dot(lb);
        let (nb, na) = (lb.x * lb.x + lb.y * lb.y, la.x * la.x + la.y * la.y);
        if !(nb > 0.0 && na > 0.0) {
            return f64::INFINITY;
        }
        (0.5 * (r * r / nb + r * r / na)).sqrt()
    }
}

/// The similarity moving `points` to mean 0 and mean distance sqrt 2; `None` when they
/// coincide.
fn normaliser(points: &[DVec2]) -> Option<DMat3> {
    let n = points.len() as f64;
    let mean = points.iter().copied().sum::<DVec2>() / n;
    let spread = points.iter().map(|p| p.distance(mean)).sum::<f64>() / n;
    let scale = 1.0 + mean.abs().max_element();
    if !(spread > 1e-9 * scale && spread.is_finite()) {
        return None;
    }
    let s = std::f64::consts::SQRT_2 / spread;
    Some(DMat3::from_cols(
        DVec3::new(s, 0.0, 0.0),
        DVec3::new(0.0, s, 0.0),
        DVec3::new(-s * mean.x, -s * mean.y, 1.0),
    ))
}

/// The 3 x 3 matrix whose rows are `f`'s three triples.
pub(crate) fn from_rows(f: &[f64; 9]) -> DMat3 {
    DMat3::from_cols_array(f).transpose()
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn frobenius(m: DMat3) -> f64 {
    m.to_cols_array().iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// The eigenvalues of a symmetric 3 x 3 matrix, ascending, and their eigenvectors.
fn eigen3(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let a: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| m.col(j)[i]));
    let (values, v) = symmetric_eigen(a);
    let vectors = std::array::from_fn(|k| DVec3::new(v[0][k], v[1][k], v[2][k]));
    (values, vectors)
}

/// The unit eigenvector of symmetric `m` with the smallest eigenvalue.
pub(crate) fn smallest(m: DMat3) -> DVec3 {
    eigen3(m).1[0]
}

/// Eigenvalues (ascending) and eigenvectors (the columns of the second result, in the same
/// order) of the symmetric matrix `a`, by cyclic Jacobi rotations.
fn symmetric_eigen<const N: usize>(mut a: [[f64; N]; N]) -> ([f64; N], [[f64; N]; N]) {
    let mut v = [[0f64; N]; N];
    for (i, row) in v.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let total: f64 = a.iter().flatten().map(|x| x * x).sum();
    for _sweep in 0..64 {
        let off: f64 = (0..N)
            .flat_map(|i| (0..N).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i][j] * a[i][j])
            .sum();
        if off.is_nan() || off <= 1e-32 * total {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                if a[p][q] == 0.0 {
                    continue;
                }
                // The rotation zeroing a[p][q] (Numerical Recipes' form, the smaller angle).
                let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..N {
                    let (kp, kq) = (a[k][p], a[k][q]);
                    a[k][p] = c * kp - s * kq;
                    a[k][q] = s * kp + c * kq;
                }
                for k in 0..N {
                    let (pk, qk) = (a[p][k], a[q][k]);
                    a[p][k] = c * pk - s * qk;
                    a[q][k] = s * pk + c * qk;
                }
                for row in v.iter_mut() {
                    let (kp, kq) = (row[p], row[q]);
                    row[p] = c * kp - s * kq;
                    row[q] = s * kp + c * kq;
                }
            }
        }
    }
    let mut order: [usize; N] = std::array::from_fn(|i| i);
    order.sort_by(|&i, &j| a[i][i].total_cmp(&a[j][j]));
    let values = std::array::from_fn(|k| a[order[k]][order[k]]);
    let vectors = std::array::from_fn(|i| std::array::from_fn(|k| v[i][order[k]]));
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobi_finds_the_eigenvectors_of_a_known_matrix() {
        // Q diag(1, 4, 9) Q^T for a rotation Q.
        let q = DMat3::from_rotation_x(0.3) * DMat3::from_rotation_z(1.1);
        let m = q * DMat3::from_diagonal(DVec3::new(4.0, 1.0, 9.0)) * q.transpose();
        let (values, vectors) = eigen3(m);
        for (k, want) in [1.0, 4.0, 9.0].into_iter().enumerate() {
            assert!((values[k] - want).abs() < 1e-12, "{values:?}");
            assert!((m * vectors[k] - vectors[k] * want).length() < 1e-12);
        }
        // Eigenvalue 1 belongs to the second column of q.
        assert!(vectors[0].dot(q.y_axis).abs() > 1.0 - 1e-12);
    }
}
