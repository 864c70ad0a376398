//! Procedural shapes: tori, spheres, boxes, planes, grids, cylinders, cones, icospheres and
//! the huge overlapping triangles of the fill-rate benchmarks.

use super::*;

/// A torus around the Y axis: `u` segments around the ring of radius `major`, `v` around
/// the tube of radius `minor`; exactly `2 * u * v` triangles. Colours follow the normals.
pub fn torus(major: f32, minor: f32, u: u32, v: u32) -> Mesh {
    let (u, v) = (u.max(3), v.max(3));
    let mut b = Builder::default();
    for i in 0..=u {
        let th = TAU * i as f32 / u as f32;
        let (s, c) = th.sin_cos();
        for j in 0..=v {
            let ph = TAU * j as f32 / v as f32;
            let n = Vec3::new(c * ph.cos(), ph.sin(), s * ph.cos());
            let p = Vec3::new(c * major, 0.0, s * major) + minor * n;
            let uv = Vec2::new(i as f32 / u as f32, j as f32 / v as f32);
            b.vertex(p, n, uv, normal_color(n));
        }
    }
    b.lattice(0, u, v);
    b.finish()
}

/// The peers' torus (major 0.95, minor 0.38, untilted) with `n` triangles: exactly `n`
/// when `n / 2` factors into a grid of aspect between 1/4 and 16 (every even `n` the
/// benchmarks use does), otherwise the closest such grid.
pub fn torus_with_triangles(n: u32) -> Mesh {
    let (u, v) = factor_grid((n / 2).max(9), 2.0);
    torus(0.95, 0.38, u.max(3), v.max(3))
}

/// The largest distance of [`torus_with_triangles`]`(n)`'s surface from the true torus it
/// stands for, object units (a bound: the chord's sagitta around the ring at the outer
/// equator plus the sagitta around the tube). Coarser tori stand in for finer ones within
/// the two bounds summed (levels of detail).
pub fn torus_deviation(n: u32) -> f32 {
    let (u, v) = factor_grid((n / 2).max(9), 2.0);
    let (u, v) = (u.max(3) as f32, v.max(3) as f32);
    let (major, minor) = (0.95f32, 0.38f32);
    let sagitta = |radius: f32, segments: f32| radius * (1.0 - (PI / segments).cos());
    sagitta(major + minor, u) + sagitta(minor, v)
}

/// A UV sphere of `rings` latitude bands and `segments` longitude segments:
/// `2 * segments * (rings - 1)` triangles (one triangle per segment at each pole).
pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
    let (r, s) = (rings.max(2), segments.max(3));
    let mut b = Builder::default();
    for i in 0..=r {
        let lat = PI * i as f32 / r as f32;
        for j in 0..=s {
            let lon = TAU * j as f32 / s as f32;
            // Pole vertices sit at the segment's middle longitude so their uvs are centred.
            let lon_uv = if i == 0 || i == r {
                (j as f32 + 0.5) / s as f32
            } else {
                j as f32 / s as f32
            };
            let n = Vec3::new(lat.sin() * lon.cos(), lat.cos(), -lat.sin() * lon.sin());
            let uv = Vec2::new(lon_uv, i as f32 / r as f32);
            b.vertex(n * radius, n, uv, normal_color(n));
        }
    }
    let nv = s + 1;
    for i in 0..r {
        for j in 0..s {
            let a = i * nv + j;
            let bb = (i + 1) * nv + j;
            let c = (i + 1) * nv + j + 1;
            let d = i * nv + j + 1;
            if i != 0 {
                b.oriented_tri(a, bb, d);
            }
            if i != r - 1 {
                b.oriented_tri(bb, c, d);
            }
        }
    }
    b.finish()
}

/// An axis-aligned box of the given full size centred on the origin: 12 triangles, one
/// uv square per face, white.
pub fn cuboid(size: Vec3) -> Mesh {
    let mut b = Builder::default();
    add_box(&mut b, Vec3::ZERO, size * 0.5, Rgba::WHITE);
    b.finish()
}

pub(super) fn add_box(b: &mut Builder, center: Vec3, half: Vec3, color: Rgba) {
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::from_array(std::array::from_fn(|k| if k == axis { sign } else { 0.0 }));
            let (t1, t2) = match axis {
                0 => (Vec3::Z, Vec3::Y),
                1 => (Vec3::X, Vec3::Z),
                _ => (Vec3::X, Vec3::Y),
            };
            let c = center + n * half;
            let (e1, e2) = (t1 * half, t2 * half);
            b.flat_quad(
                [c - e1 - e2, c + e1 - e2, c + e1 + e2, c - e1 + e2],
                color,
                n,
            );
        }
    }
}

/// A flat `width` x `depth` plane in XZ facing +Y, cut into `nx` x `nz` cells:
/// `2 * nx * nz` triangles, uvs spanning [0, 1], white.
pub fn plane(width: f32, depth: f32, nx: u32, nz: u32) -> Mesh {
    let (nx, nz) = (nx.max(1), nz.max(1));
    let mut b = Builder::default();
    for i in 0..=nx {
        for j in 0..=nz {
            let (fu, fv) = (i as f32 / nx as f32, j as f32 / nz as f32);
            let p = Vec3::new((fu - 0.5) * width, 0.0, (fv - 0.5) * depth);
            b.vertex(p, Vec3::Y, Vec2::new(fu, fv), Rgba::WHITE);
        }
    }
    b.lattice(0, nx, nz);
    b.finish()
}

/// A `width` x `height` quad in XY facing +Z, centred on the origin (a card or billboard):
/// 2 triangles, uvs with v down.
pub fn quad(width: f32, height: f32) -> Mesh {
    let (hw, hh) = (width * 0.5, height * 0.5);
    let mut b = Builder::default();
    b.vertex(
        Vec3::new(-hw, -hh, 0.0),
        Vec3::Z,
        Vec2::new(0.0, 1.0),
        Rgba::WHITE,
    );
    b.vertex(
        Vec3::new(hw, -hh, 0.0),
        Vec3::Z,
        Vec2::new(1.0, 1.0),
        Rgba::WHITE,
    );
    b.vertex(
        Vec3::new(hw, hh, 0.0),
        Vec3::Z,
        Vec2::new(1.0, 0.0),
        Rgba::WHITE,
    );
    b.vertex(
        Vec3::new(-hw, hh, 0.0),
        Vec3::Z,
        Vec2::new(0.0, 0.0),
        Rgba::WHITE,
    );
    b.tri(0, 1, 2);
    b.tri(0, 2, 3);
    b.finish()
}

/// The peers' `grid`: a wavy height field `z = amp sin(3.1 x) cos(2.3 y)` over
/// `[-half_w, half_w] x [-half_h, half_h]`, facing +Z, with about `n` triangles (exactly
/// `n` for even `n` that factor well, as [`torus_with_triangles`]); colours from position.
pub fn wave_grid(n: u32, half_w: f32, half_h: f32, amp: f32) -> Mesh {
    let (u, v) = factor_grid((n / 2).max(1), half_w / half_h);
    let mut b = Builder::default();
    for i in 0..=u {
        let x = -half_w + 2.0 * half_w * i as f32 / u as f32;
        for j in 0..=v {
            let y = -half_h + 2.0 * half_h * j as f32 / v as f32;
            let z = amp * (3.1 * x).sin() * (2.3 * y).cos();
            let dzdx = amp * 3.1 * (3.1 * x).cos() * (2.3 * y).cos();
            let dzdy = -amp * 2.3 * (3.1 * x).sin() * (2.3 * y).sin();
            let n = Vec3::new(-dzdx, -dzdy, 1.0);
            let (fu, fv) = (i as f32 / u as f32, j as f32 / v as f32);
            let zc = if amp != 0.0 { z / (2.0 * amp) } else { 0.0 };
            let c = Rgba::new(fu, fv, 0.5 + zc * 0.5, 1.0);
            b.vertex(Vec3::new(x, y, z), n, Vec2::new(fu, 1.0 - fv), c);
        }
    }
    b.lattice(0, u, v);
    b.finish()
}

/// A closed cylinder of radius `radius` from y = 0 to y = `height`: `4 * segments`
/// triangles (smooth side, flat fanned caps), white.
pub fn cylinder(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut b = Builder::default();
    add_cylinder(
        &mut b,
        Mat4::IDENTITY,
        radius,
        radius,
        height,
        segments,
        Rgba::WHITE,
    );
    b.finish()
}

/// A frustum (cylinder when `r0 == r1`) transformed by `xf` (rigid plus uniform scale).
pub(super) fn add_cylinder(
    b: &mut Builder,
    xf: Mat4,
    r0: f32,
    r1: f32,
    h: f32,
    segments: u32,
    c: Rgba,
) {
    let s = segments.max(3);
    let base = b.mesh.positions.len() as u32;
    let slope = (r0 - r1) / h.max(1e-6);
    for i in 0..=s {
        let th = TAU * i as f32 / s as f32;
        let (sn, cs) = th.sin_cos();
        let n = xf.transform_vector3(Vec3::new(cs, slope, -sn));
        for (k, (r, y)) in [(r0, 0.0), (r1, h)].into_iter().enumerate() {
            let p = xf.transform_point3(Vec3::new(cs * r, y, -sn * r));
            b.vertex(p, n, Vec2::new(i as f32 / s as f32, 1.0 - k as f32), c);
        }
    }
    b.lattice(base, s, 1);
    for (r, y, ny) in [(r0, 0.0, -1.0), (r1, h, 1.0)] {
        let n = xf.transform_vector3(Vec3::new(0.0, ny, 0.0));
        let center = b.vertex(
            xf.transform_point3(Vec3::new(0.0, y, 0.0)),
            n,
            Vec2::splat(0.5),
            c,
        );
        let first = b.mesh.positions.len() as u32;
        for i in 0..s {
            let th = TAU * i as f32 / s as f32;
            let (sn, cs) = th.sin_cos();
            let p = xf.transform_point3(Vec3::new(cs * r, y, -sn * r));
            b.vertex(p, n, Vec2::new(0.5 + 0.5 * cs, 0.5 + 0.5 * sn), c);
        }
        for i in 0..s {
            b.oriented_tri(center, first + i, first + (i + 1) % s);
        }
    }
}

/// A closed cone of base radius `radius` on y = 0 with its apex at y = `height`:
/// `2 * segments` triangles, faceted, white.
pub fn cone(radius: f32, height: f32, segments: u32) -> Mesh {
    let mut b = Builder::default();
    add_cone(
        &mut b,
        Vec3::ZERO,
        radius,
        height,
        segments,
        Rgba::WHITE,
        None,
    );
    b.finish()
}

/// A faceted cone; `jitter` shades alternate facets slightly for a low-poly look.
pub(super) fn add_cone(
    b: &mut Builder,
    at: Vec3,
    r: f32,
    h: f32,
    segments: u32,
    c: Rgba,
    mut rng: Option<&mut XorShift>,
) {
    let s = segments.max(3);
    let apex = at + Vec3::Y * h;
    let center = at + Vec3::Y * (h / 3.0);
    let ring = |i: u32| {
        let th = TAU * i as f32 / s as f32;
        at + Vec3::new(th.cos() * r, 0.0, -th.sin() * r)
    };
    for i in 0..s {
        let (p0, p1) = (ring(i), ring(i + 1));
        let shade = rng.as_deref_mut().map_or(1.0, |g| g.range(0.85, 1.1));
        let cc = Rgba::new(c.r * shade, c.g * shade, c.b * shade, c.a);
        let mid = (p0 + p1 + apex) / 3.0;
        b.flat_tri([p0, p1, apex], cc, mid - center);
        b.flat_tri([p0, at, p1], cc, -Vec3::Y);
    }
}

/// An icosphere: the icosahedron subdivided `subdivisions` times, `20 * 4^k` triangles,
/// smooth normals, spherical uvs, white.
pub fn icosphere(radius: f32, subdivisions: u32) -> Mesh {
    let (verts, tris) = ico_lattice(subdivisions.min(7));
    let mut b = Builder::default();
    for v in &verts {
        let uv = Vec2::new(0.5 + v.z.atan2(v.x) / TAU, 0.5 - v.y.asin() / PI);
        b.vertex(*v * radius, *v, uv, Rgba::WHITE);
    }
    for t in tris {
        b.oriented_tri(t[0], t[1], t[2]);
    }
    b.finish()
}

/// Unit-sphere vertices and triangles of a subdivided icosahedron (shared vertices).
pub(super) fn ico_lattice(subdivisions: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut verts: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .into_iter()
    .map(|(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut mids = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, verts: &mut Vec<Vec3>| -> u32 {
            *mids.entry((a.min(b), a.max(b))).or_insert_with(|| {
                verts.push(((verts[a as usize] + verts[b as usize]) * 0.5).normalize());
                (verts.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(tris.len() * 4);
        for [a, b, c] in tris {
            let ab = mid(a, b, &mut verts);
            let bc = mid(b, c, &mut verts);
            let ca = mid(c, a, &mut verts);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    (verts, tris)
}

/// A few huge overlapping, interpenetrating triangles facing +Z around the origin, as the
/// peers' `huge` scene (fill-rate bound): `n` triangles, each covering much of a view of
/// the unit square from z = 3.
pub fn huge_triangles(n: u32, seed: u64) -> Mesh {
    let mut rng = XorShift::new(seed);
    let mut b = Builder::default();
    let n = n.max(1);
    for k in 0..n {
        let z = -1.0 + 2.0 * (((k as u64 * 7919) % n as u64) as f32 + 0.5) / n as f32;
        let ang = rng.range(0.0, TAU);
        let r = rng.range(1.8, 3.2);
        let (cx, cy) = (rng.range(-0.7, 0.7), rng.range(-0.7, 0.7));
        let p: [Vec3; 3] = std::array::from_fn(|m| {
            let a = ang + m as f32 * TAU / 3.0 + rng.range(-0.3, 0.3);
            let dz = rng.range(-0.45, 0.45);
            Vec3::new(
                cx + r * a.cos(),
                cy + r * a.sin(),
                (z + dz).clamp(-1.15, 1.15),
            )
        });
        let c = Rgba::new(
            rng.range(0.15, 1.0),
            rng.range(0.15, 1.0),
            rng.range(0.15, 1.0),
            1.0,
        );
        b.flat_tri(p, c, Vec3::Z);
    }
    b.finish()
}

/// A wall in the plane z = 0 facing +Z, from `x0` to `x1` and `height` high, with doorways
/// cut out from the floor: each `(centre x, width, height)`, in increasing x, inside the
/// wall. One quad beside each doorway and one above it (none of zero size); uvs map the
/// wall to [0, 1] with v down; white.
pub fn doorway_wall(x0: f32, x1: f32, height: f32, doors: &[(f32, f32, f32)]) -> Mesh {
    let mut b = Builder::default();
    let (w, h) = (
        (x1 - x0).max(f32::MIN_POSITIVE),
        height.max(f32::MIN_POSITIVE),
    );
    let mut quad = |(qx0, qx1): (f32, f32), (qy0, qy1): (f32, f32)| {
        if qx1 <= qx0 || qy1 <= qy0 {
            return;
        }
        let corners = [(qx0, qy0), (qx1, qy0), (qx1, qy1), (qx0, qy1)].map(|(x, y)| {
            let uv = Vec2::new((x - x0) / w, 1.0 - y / h);
            b.vertex(Vec3::new(x, y, 0.0), Vec3::Z, uv, Rgba::WHITE)
        });
        b.tri(corners[0], corners[1], corners[2]);
        b.tri(corners[0], corners[2], corners[3]);
    };
    let mut x = x0;
    for &(centre, width, door_h) in doors {
        let (left, right) = (centre - width / 2.0, centre + width / 2.0);
        quad((x, left), (0.0, height));
        quad((left, right), (door_h, height));
        x = right;
    }
    quad((x, x1), (0.0, height));
    b.finish()
}
