//! Tests of the procedural meshes: counts, validity, normals, winding, determinism.

use super::*;

/// Six times the signed volume: positive when triangles wind counter-clockwise seen
/// from outside.
fn volume(m: &Mesh) -> f32 {
    m.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            a.dot(b.cross(c))
        })
        .sum::<f32>()
        / 6.0
}

/// Every triangle's winding agrees with its vertices' normals.
fn winding_matches_normals(m: &Mesh) -> bool {
    m.indices.chunks_exact(3).all(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
        let n: Vec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
        let g = (b - a).cross(c - a);
        g.length_squared() == 0.0 || g.dot(n) > 0.0
    })
}

fn check(m: &Mesh, closed: bool) {
    m.validate().unwrap();
    let n = m.positions.len();
    assert!(n > 0);
    assert_eq!(m.normals.len(), n);
    assert_eq!(m.uvs.len(), n);
    assert_eq!(m.colors.len(), n);
    for nrm in &m.normals {
        assert!((nrm.length() - 1.0).abs() < 1e-4, "normal {nrm}");
    }
    assert!(m.positions.iter().all(|p| p.is_finite()));
    assert!(m.uvs.iter().all(|p| p.is_finite()));
    assert!(winding_matches_normals(m));
    if closed {
        assert!(volume(m) > 0.0, "signed volume {}", volume(m));
    }
}

#[test]
fn torus_has_exactly_2uv_triangles_and_encloses_its_volume() {
    let m = torus(1.0, 0.25, 48, 24);
    assert_eq!(m.triangle_count(), 2 * 48 * 24);
    check(&m, true);
    let exact = 2.0 * PI * PI * 1.0 * 0.25 * 0.25;
    assert!((volume(&m) - exact).abs() < 0.05 * exact);
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let ring = Vec3::new(p.x, 0.0, p.z).normalize() * 1.0;
        assert!((*p - ring).normalize().dot(*n) > 0.999);
    }
}

#[test]
fn torus_with_triangles_is_exact_for_benchmark_sizes() {
    for n in [1_000, 10_000, 100_000, 1_000_000, 2_000_000] {
        assert_eq!(factor_grid(n / 2, 2.0).0 * factor_grid(n / 2, 2.0).1, n / 2);
    }
    let m = torus_with_triangles(10_000);
    assert_eq!(m.triangle_count(), 10_000);
    check(&m, true);
}

#[test]
fn sphere_counts_volume_and_outward_normals() {
    let m = uv_sphere(2.0, 12, 20);
    assert_eq!(m.triangle_count(), 2 * 20 * 11);
    check(&m, true);
    let exact = 4.0 / 3.0 * PI * 8.0;
    assert!((volume(&m) - exact).abs() < 0.05 * exact);
    for (p, n) in m.positions.iter().zip(&m.normals) {
        assert!(p.normalize().dot(*n) > 0.999);
    }
}

#[test]
fn box_plane_quad() {
    let b = cuboid(Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(b.triangle_count(), 12);
    check(&b, true);
    assert!((volume(&b) - 6.0).abs() < 1e-4);
    let p = plane(4.0, 2.0, 5, 3);
    assert_eq!(p.triangle_count(), 30);
    check(&p, false);
    assert!(p.indices.chunks_exact(3).all(|t| {
        let [a, b, c] = [0, 1, 2].map(|k| p.positions[t[k] as usize]);
        (b - a).cross(c - a).y > 0.0
    }));
    let q = quad(2.0, 1.0);
    assert_eq!(q.triangle_count(), 2);
    check(&q, false);
}

#[test]
fn wave_grid_matches_the_peers_grid() {
    let g = wave_grid(100_000, 3.1, 1.8, 0.15);
    assert_eq!(g.triangle_count(), 100_000);
    check(&g, false);
    assert!(g.normals.iter().all(|n| n.z > 0.0));
    assert!(g.positions.iter().all(|p| p.z.abs() <= 0.15 + 1e-6));
}

#[test]
fn terrain_is_deterministic_and_smooth() {
    let t = Terrain {
        cells: 40,
        ..Default::default()
    };
    let a = t.mesh();
    assert_eq!(a.triangle_count(), 2 * 40 * 40);
    check(&a, false);
    assert_eq!(a, t.mesh());
    let other = Terrain { seed: 8, ..t }.mesh();
    assert_ne!(a.positions, other.positions);
    // Flat in the middle, varied outside, no cliffs between neighbouring samples.
    assert_eq!(t.height_at(0.5, -0.3), 0.0);
    let hs: Vec<f32> = (0..200)
        .map(|i| t.height_at(30.0, i as f32 * 0.1 - 10.0))
        .collect();
    assert!(hs.windows(2).all(|w| (w[1] - w[0]).abs() < 0.5));
    assert!(
        hs.iter().cloned().fold(f32::MIN, f32::max) - hs.iter().cloned().fold(f32::MAX, f32::min)
            > 0.1
    );
}

#[test]
fn solids_are_closed_and_outward() {
    let c = cylinder(0.5, 2.0, 16);
    assert_eq!(c.triangle_count(), 4 * 16);
    check(&c, true);
    let exact = PI * 0.25 * 2.0;
    assert!((volume(&c) - exact).abs() < 0.05 * exact);
    let k = cone(1.0, 3.0, 12);
    assert_eq!(k.triangle_count(), 24);
    check(&k, true);
    let ico = icosphere(1.0, 2);
    assert_eq!(ico.triangle_count(), 20 * 16);
    check(&ico, true);
}

#[test]
fn props_are_valid_deterministic_and_outward() {
    for kind in [TreeKind::Pine, TreeKind::Broadleaf] {
        let t = tree(kind, 4.0, 3);
        check(&t, true);
        assert!(t.triangle_count() < 500);
        assert_eq!(t, tree(kind, 4.0, 3));
        let s = t.bounding_sphere();
        assert!(s.radius < 4.0 && s.center.y > 1.0);
    }
    let r = rock(1.0, 5);
    assert_eq!(r.triangle_count(), 80);
    check(&r, true);
    assert_ne!(r, rock(1.0, 6));
    let h = house(4.0, 3.0, 2.5, 1.5);
    assert_eq!(h.triangle_count(), 44);
    check(&h, true);
}

#[test]
fn huge_triangles_face_the_camera() {
    let m = huge_triangles(16, 2);
    assert_eq!(m.triangle_count(), 16);
    check(&m, false);
    assert!(m.normals.iter().all(|n| n.z > 0.0));
}

#[test]
fn xorshift_is_deterministic_and_uniform_enough() {
    let mut a = XorShift::new(0);
    let mut b = XorShift::new(0);
    let xs: Vec<f32> = (0..10_000).map(|_| a.next_f32()).collect();
    assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
    assert_eq!(
        xs[..5],
        (0..5).map(|_| b.next_f32()).collect::<Vec<_>>()[..]
    );
    let mean = xs.iter().sum::<f32>() / xs.len() as f32;
    assert!((mean - 0.5).abs() < 0.02);
    assert_ne!(XorShift::new(1).next_u64(), XorShift::new(2).next_u64());
}

#[test]
fn a_doorway_wall_covers_the_wall_but_its_doorways() {
    let m = doorway_wall(-4.0, 4.0, 3.0, &[(-2.0, 1.0, 2.0), (1.0, 1.2, 3.0)]);
    check(&m, false);
    // Left of the first door, above it, between the doors, nothing above the second (as
    // high as the wall), right of it: 4 quads.
    assert_eq!(m.triangle_count(), 8);
    let area: f32 = m
        .indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            (b - a).cross(c - a).length() / 2.0
        })
        .sum();
    assert!(
        (area - (8.0 * 3.0 - 1.0 * 2.0 - 1.2 * 3.0)).abs() < 1e-4,
        "{area}"
    );
    assert!(m.positions.iter().all(|p| p.z == 0.0));
    assert!(m.normals.iter().all(|n| *n == Vec3::Z));
}

/// Distance of `p` from the surface of the torus of `major` and `minor` radii around Y.
fn torus_distance(p: Vec3, major: f32, minor: f32) -> f32 {
    let ring = (p.x * p.x + p.z * p.z).sqrt() - major;
    ((ring * ring + p.y * p.y).sqrt() - minor).abs()
}

#[test]
fn torus_deviation_bounds_every_coarse_torus_surface_and_is_tight() {
    // Sampled on every triangle (vertices, edge midpoints, centroid and points between),
    // the distance to the analytic torus stays within the bound, and reaches at least a
    // third of it (the bound is no wild overestimate), for the world's statue levels.
    for n in [200u32, 800, 3000] {
        let m = torus_with_triangles(n);
        assert_eq!(m.triangle_count(), n as usize);
        let bound = torus_deviation(n);
        let mut worst = 0.0f32;
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize]);
            for i in 0..=8 {
                for j in 0..=(8 - i) {
                    let (wa, wb) = (i as f32 / 8.0, j as f32 / 8.0);
                    let p = a * wa + b * wb + c * (1.0 - wa - wb);
                    worst = worst.max(torus_distance(p, 0.95, 0.38));
                }
            }
        }
        assert!(worst <= bound * 1.0001, "{n}: {worst} over {bound}");
        assert!(worst >= bound / 3.0, "{n}: {worst} far under {bound}");
    }
    assert!(torus_deviation(200) > torus_deviation(800));
    assert!(torus_deviation(800) > torus_deviation(3000));
}
