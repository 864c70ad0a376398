//! A procedural city block whose triangle count scales over three orders of magnitude while
//! its screen coverage stays the same, with the camera paths the impostor benchmarks fly:
//! the scene behind "frame cost follows pixels, not triangles".
//!
//! Every building is a box whose faces are split into a `k` x `k` grid of quads with a
//! vertex-coloured window pattern, so raising `k` multiplies triangles (about `12 k^2` per
//! building) without moving a single silhouette edge.

use engine::procedural::XorShift;
use engine::{Light, Lighting, Material, Mesh, Rgba, Shading};
use glam::{Mat4, Vec3};
use ibr::subject::{MeshGroup, Subject};
use std::sync::Arc;

/// The city: buildings (one subject each) on a ground plate.
#[derive(Clone, Debug)]
pub struct City {
    pub buildings: Vec<MeshGroup>,
    pub ground: MeshGroup,
    pub lighting: Lighting,
    /// Half the side of the square the buildings stand in.
    pub half_extent: f32,
}

/// Camera paths over the city, parameterised by `t` in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    /// The eye slides sideways along a straight line, always looking the same way.
    Translate,
    /// The eye stays put and turns (yaw sweep).
    Rotate,
    /// The eye circles the city looking at its centre.
    Orbit,
}

impl City {
    /// `grid` x `grid` buildings with faces split `k` x `k` (about `12 k^2 grid^2`
    /// triangles), deterministic for `seed`.
    pub fn new(grid: u32, k: u32, seed: u64) -> City {
        let grid = grid.max(1);
        let k = k.max(1);
        let spacing = 6.0;
        let half_extent = grid as f32 * spacing * 0.5;
        let mut rng = XorShift::new(seed);
        let material = Arc::new(Material {
            shading: Shading::Lit {
                specular: 0.1,
                shininess: 16.0,
            },
            ..Material::default()
        });
        let mut buildings = Vec::new();
        for gz in 0..grid {
            for gx in 0..grid {
                let w = rng.range(2.4, 4.2);
                let d = rng.range(2.4, 4.2);
                let h = rng.range(4.0, 16.0);
                let x = (gx as f32 + 0.5) * spacing - half_extent;
                let z = (gz as f32 + 0.5) * spacing - half_extent;
                let wall = Rgba::new(
                    rng.range(0.45, 0.8),
                    rng.range(0.4, 0.7),
                    rng.range(0.35, 0.6),
                    1.0,
                );
                let mesh = Arc::new(building(Vec3::new(w, h, d), k, wall));
                buildings.push(MeshGroup::new().with(
                    mesh,
                    material.clone(),
                    Mat4::from_translation(Vec3::new(x, 0.0, z)),
                ));
            }
        }
        City {
            buildings,
            ground: ground(half_extent * 2.4, Rgba::from_srgb8(90, 96, 92)),
            lighting: daylight(),
            half_extent,
        }
    }

    /// A city of `grid` x `grid` buildings with about `triangles` triangles in all.
    pub fn with_triangles(grid: u32, triangles: usize, seed: u64) -> City {
        let per = triangles as f32 / (grid.max(1) as f32).powi(2);
        let k = ((per - 2.0).max(12.0) / 10.0).sqrt().round().max(1.0) as u32;
        City::new(grid, k, seed)
    }

    pub fn triangle_count(&self) -> usize {
        self.buildings
            .iter()
            .map(|b| b.triangle_count())
            .sum::<usize>()
            + self.ground.triangle_count()
    }

    /// `(eye, target)` at `t` in [0, 1] along `path`.
    pub fn path(&self, path: Path, t: f32) -> (Vec3, Vec3) {
        let e = self.half_extent;
        let t = t.clamp(0.0, 1.0);
        match path {
            Path::Translate => {
                let eye = Vec3::new(-e * 0.5 + e * t, e * 0.55, e * 1.9);
                (eye, eye + Vec3::new(0.0, -0.45, -1.0))
            }
            Path::Rotate => {
                let eye = Vec3::new(0.0, e * 0.55, e * 1.9);
                let yaw = (t - 0.5) * 0.9;
                (eye, eye + Vec3::new(yaw.sin(), -0.45, -yaw.cos()))
            }
            Path::Orbit => {
                let a = std::f32::consts::TAU * t;
                let eye = Vec3::new(a.sin() * e * 1.9, e * 0.7, a.cos() * e * 1.9);
                (eye, Vec3::new(0.0, 2.0, 0.0))
            }
        }
    }
}

/// A flat lit plate `side` units square on y = 0, centred on the origin.
pub fn ground(side: f32, color: Rgba) -> MeshGroup {
    let mut plate = engine::procedural::plane(side, side, 1, 1);
    plate.colors.clear();
    MeshGroup::new().with(
        Arc::new(plate),
        Arc::new(Material::lit(color)),
        Mat4::IDENTITY,
    )
}

/// A bluish ambient and a warm sun from high on one side.
pub fn daylight() -> Lighting {
    Lighting {
        ambient: Rgba::new(0.25, 0.27, 0.32, 1.0),
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.4, -0.8, -0.45).normalize(),
            color: Rgba::new(1.0, 0.96, 0.88, 1.0),
        }],
    }
}

/// A box building of `size` standing on the origin, every face split `k` x `k`, with
/// vertex colours: wall colour, darker window cells, a grey roof.
pub fn building(size: Vec3, k: u32, wall: Rgba) -> Mesh {
    let mut m = Mesh::default();
    let half = Vec3::new(size.x * 0.5, 0.0, size.z * 0.5);
    let window = Rgba::new(wall.r * 0.35, wall.g * 0.4, wall.b * 0.55, 1.0);
    let roof = Rgba::new(0.35, 0.35, 0.37, 1.0);
    // (origin, u axis, v axis, normal) of each face, counter-clockwise seen from outside.
    let faces = [
        (
            Vec3::new(-half.x, 0.0, half.z),
            Vec3::X * size.x,
            Vec3::Y * size.y,
            Vec3::Z,
        ),
        (
            Vec3::new(half.x, 0.0, -half.z),
            -Vec3::X * size.x,
            Vec3::Y * size.y,
            -Vec3::Z,
        ),
        (
            Vec3::new(half.x, 0.0, half.z),
            -Vec3::Z * size.z,
            Vec3::Y * size.y,
            Vec3::X,
        ),
        (
            Vec3::new(-half.x, 0.0, -half.z),
            Vec3::Z * size.z,
            Vec3::Y * size.y,
            -Vec3::X,
        ),
        (
            Vec3::new(-half.x, size.y, half.z),
            Vec3::X * size.x,
            -Vec3::Z * size.z,
            Vec3::Y,
        ),
    ];
    for (f, (origin, u, v, n)) in faces.into_iter().enumerate() {
        let base = m.positions.len() as u32;
        for j in 0..=k {
            for i in 0..=k {
                let (s, t) = (i as f32 / k as f32, j as f32 / k as f32);
                m.positions.push(origin + u * s + v * t);
                m.normals.push(n);
                // Windows: cells away from the edges, every other row, on the walls.
                let lit_cell = f < 4 && i > 0 && i < k && j > 0 && j < k && j % 2 == 1;
                m.colors.push(match (f, lit_cell) {
                    (4, _) => roof,
                    (_, true) => window,
                    _ => wall,
                });
            }
        }
        for j in 0..k {
            for i in 0..k {
                let a = base + j * (k + 1) + i;
                let (b, c, d) = (a + 1, a + k + 2, a + k + 1);
                m.indices.extend_from_slice(&[a, b, c, a, c, d]);
            }
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_scale_with_detail_and_bounds_do_not() {
        let low = City::new(4, 1, 5);
        let high = City::new(4, 20, 5);
        assert_eq!(low.buildings.len(), 16);
        assert_eq!(low.triangle_count(), 16 * 10 + 2);
        assert_eq!(high.triangle_count(), 16 * 10 * 400 + 2);
        for (a, b) in low.buildings.iter().zip(&high.buildings) {
            let (sa, sb) = (a.bounds(), b.bounds());
            assert!(sa.center.distance(sb.center) < 1e-4 && (sa.radius - sb.radius).abs() < 1e-4);
            assert!(a.parts[0].mesh.validate().is_ok() && b.parts[0].mesh.validate().is_ok());
        }
        let target = City::with_triangles(8, 1_000_000, 1).triangle_count();
        assert!((800_000..1_300_000).contains(&target), "{target}");
        let small = City::with_triangles(8, 1_000, 1).triangle_count();
        assert!(small < 1_500, "{small}");
    }

    #[test]
    fn paths_translate_rotate_and_orbit() {
        let c = City::new(4, 1, 5);
        let (e0, t0) = c.path(Path::Translate, 0.0);
        let (e1, t1) = c.path(Path::Translate, 1.0);
        assert!((e1 - e0).y.abs() < 1e-6 && (e1 - e0).z.abs() < 1e-6 && e1.x > e0.x);
        assert!(((t1 - e1) - (t0 - e0)).length() < 1e-5, "same direction");
        let (r0, _) = c.path(Path::Rotate, 0.0);
        let (r1, _) = c.path(Path::Rotate, 1.0);
        assert_eq!(r0, r1, "rotation only");
    }
}
