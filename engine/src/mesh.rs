//! Triangle meshes: indexed triangle lists with optional per-vertex attributes.
//!
//! Attribute arrays are either empty (absent) or as long as `positions`; [`Mesh::validate`]
//! checks that and the index range, and loaders call it, so the pipeline can trust a mesh
//! it is handed. Positions are in the mesh's object space.

use crate::color::Rgba;
use glam::{Vec2, Vec3};

/// An indexed triangle list. Triangle `t` is `indices[3t..3t+3]`, counter-clockwise front.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, object space.
    pub positions: Vec<Vec3>,
    /// Unit normals, or empty.
    pub normals: Vec<Vec3>,
    /// Texture coordinates (u right, v down as glTF and images have it), or empty.
    pub uvs: Vec<Vec2>,
    /// Straight linear vertex colours, or empty.
    pub colors: Vec<Rgba>,
    /// Three indices into the vertex arrays per triangle; each below `positions.len()`.
    pub indices: Vec<u32>,
}

/// A bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre, in the space of the points it bounds (object space for a mesh's, world
    /// space for a scene's).
    pub center: Vec3,
    /// Radius in the same units; >= 0.
    pub radius: f32,
}

impl Mesh {
    /// Empties every attribute array and the indices, keeping their memory (meshes
    /// rewritten every frame, such as billboard batches, reuse it).
    pub fn clear(&mut self) {
        self.positions.clear();
        self.normals.clear();
        self.uvs.clear();
        self.colors.clear();
        self.indices.clear();
    }

    /// The number of triangles: `indices.len() / 3`.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Checks the invariants the pipeline relies on; returns what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.positions.len();
        if !self.indices.len().is_multiple_of(3) {
            return Err(format!(
                "index count {} is not a multiple of 3",
                self.indices.len()
            ));
        }
        for (name, len) in [
            ("normals", self.normals.len()),
            ("uvs", self.uvs.len()),
            ("colors", self.colors.len()),
        ] {
            if len != 0 && len != n {
                return Err(format!("{name} has {len} entries for {n} positions"));
            }
        }
        if let Some(&bad) = self.indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!("index {bad} out of range for {n} vertices"));
        }
        Ok(())
    }

    /// A sphere that contains every vertex (centre of the bounding box; not minimal).
    pub fn bounding_sphere(&self) -> Sphere {
        let Some((lo, hi)) = self.bounding_box() else {
            return Sphere {
                center: Vec3::ZERO,
                radius: 0.0,
            };
        };
        let center = (lo + hi) * 0.5;
        let finite = self.positions.iter().filter(|p| p.is_finite());
        let radius = finite.map(|p| p.distance(center)).fold(0.0, f32::max);
        Sphere { center, radius }
    }

    /// The smallest and largest coordinates of the finite positions (`None` when there are
    /// none): the object-space bounding box.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        let finite = self.positions.iter().filter(|p| p.is_finite());
        let (lo, hi) = finite.fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        (lo.x <= hi.x).then_some((lo, hi))
    }

    /// Fills `normals` with area-weighted smooth vertex normals.
    pub fn compute_normals(&mut self) {
        let mut acc = vec![Vec3::ZERO; self.positions.len()];
        for t in self.indices.chunks_exact(3) {
            let [a, b, c] = [t[0] as usize, t[1] as usize, t[2] as usize];
            let n = (self.positions[b] - self.positions[a])
                .cross(self.positions[c] - self.positions[a]);
            if n.is_finite() {
                acc[a] += n;
                acc[b] += n;
                acc[c] += n;
            }
        }
        self.normals = acc.into_iter().map(|n| n.normalize_or(Vec3::Y)).collect();
    }

    /// Appends another mesh (its indices shifted). Attributes present in only one of the
    /// two are filled with defaults for the other's vertices.
    pub fn append(&mut self, other: &Mesh) {
        let base = self.positions.len() as u32;
        let (n0, n1) = (self.positions.len(), other.positions.len());
        fn merge<T: Copy>(a: &mut Vec<T>, b: &[T], n0: usize, n1: usize, fill: T) {
            if a.is_empty() && b.is_empty() {
                return;
            }
            a.resize(n0, fill);
            if b.is_empty() {
                a.extend(std::iter::repeat_n(fill, n1));
            } else {
                a.extend_from_slice(b);
            }
        }
        merge(&mut self.normals, &other.normals, n0, n1, Vec3::Y);
        merge(&mut self.uvs, &other.uvs, n0, n1, Vec2::ZERO);
        merge(&mut self.colors, &other.colors, n0, n1, Rgba::WHITE);
        self.positions.extend_from_slice(&other.positions);
        self.indices.extend(other.indices.iter().map(|i| i + base));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validate_catches_bad_meshes() {
        let mut m = Mesh {
            positions: vec![Vec3::ZERO; 3],
            indices: vec![0, 1, 2],
            ..Default::default()
        };
        assert!(m.validate().is_ok());
        m.indices.push(3);
        assert!(m.validate().unwrap_err().contains("multiple of 3"));
        m.indices.extend([4, 5]);
        assert!(m.validate().unwrap_err().contains("out of range"));
        m.indices.truncate(3);
        m.uvs = vec![Vec2::ZERO; 2];
        assert!(m.validate().unwrap_err().contains("uvs"));
    }

    #[test]
    fn append_fills_missing_attributes() {
        let tri = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![0, 1, 2],
            ..Default::default()
        };
        let mut coloured = tri.clone();
        coloured.colors = vec![Rgba::BLACK; 3];
        let mut m = tri.clone();
        m.append(&coloured);
        assert_eq!(m.colors.len(), 6);
        assert_eq!(m.colors[0], Rgba::WHITE);
        assert_eq!(m.indices[3..], [3, 4, 5]);
        assert!(m.validate().is_ok());
    }

    #[test]
    fn bounding_sphere_contains_vertices_and_ignores_nan() {
        let m = Mesh {
            positions: vec![
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(3.0, 2.0, 0.0),
                Vec3::NAN,
            ],
            ..Default::default()
        };
        let s = m.bounding_sphere();
        assert!(s.radius.is_finite());
        for p in &m.positions[..2] {
            assert!(p.distance(s.center) <= s.radius + 1e-5);
        }
    }
}
