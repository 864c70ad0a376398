//! The third reconstruction: a depth image as a mesh. Neighbouring samples are joined into
//! triangles (two per 2 x 2 block of pixel centres) that the engine's rasterizer draws from
//! any camera, with the samples' colours interpolated; a triangle is left out where its
//! corners' depths differ by more than the edge tolerance, so the mesh breaks at depth
//! discontinuities instead of stretching "rubber sheets" across them.

use super::is_filled;
use crate::core::{unproject, DepthImage};
use engine::{Material, Mesh};

/// Rebuilds `mesh` (reusing its memory) from `image`: a vertex per filled pixel with finite
/// depth, at its world point, with its colour; triangles between neighbours on one surface
/// (relative depth differences at most `edge`). Returns the triangles.
pub fn depth_mesh(image: &DepthImage, edge: f32, mesh: &mut Mesh, index: &mut Vec<u32>) -> usize {
    mesh.clear();
    let (w, h) = (image.width(), image.height());
    index.clear();
    index.resize(w as usize * h as usize, u32::MAX);
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let (c, z) = (image.color[i], image.depth[i]);
            if !is_filled(c) || !z.is_finite() {
                continue;
            }
            let Some(p) = unproject(&image.camera, x as f32 + 0.5, y as f32 + 0.5, z, w, h) else {
                continue;
            };
            index[i] = mesh.positions.len() as u32;
            mesh.positions.push(p);
            mesh.colors.push(c.unpremultiply());
        }
    }
    let same = |a: usize, b: usize| {
        let (za, zb) = (image.depth[a], image.depth[b]);
        (za - zb).abs() <= edge * za.min(zb)
    };
    for y in 0..h.saturating_sub(1) {
        for x in 0..w.saturating_sub(1) {
            let i00 = (y * w + x) as usize;
            let (i10, i01, i11) = (i00 + 1, i00 + w as usize, i00 + w as usize + 1);
            // Two triangles per block, each kept only over one surface.
            for tri in [[i00, i01, i10], [i10, i01, i11]] {
                if tri.iter().all(|&k| index[k] != u32::MAX)
                    && same(tri[0], tri[1])
                    && same(tri[1], tri[2])
                    && same(tri[0], tri[2])
                {
                    mesh.indices.extend(tri.map(|k| index[k]));
                }
            }
        }
    }
    mesh.indices.len() / 3
}

/// The material a depth mesh is drawn with: its vertex colours, unlit, both sides.
pub fn depth_mesh_material() -> Material {
    Material::unlit(engine::Rgba::WHITE).double_sided(true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::warp::tests::{boxes, camera, cast, mismatch, reference, H, W};
    use engine::{Draw, FrameOptions, Renderer, Rgba, Target};
    use glam::{Mat4, Vec3};

    fn render(mesh: &Mesh, camera: &engine::Camera) -> DepthImage {
        let material = depth_mesh_material();
        let mut target = Target::new(W, H);
        let opts = FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..Default::default()
        };
        Renderer::new().render(
            [Draw {
                mesh,
                material: &material,
                transform: Mat4::IDENTITY,
            }],
            camera,
            &engine::Lighting::default(),
            &mut target,
            &opts,
        );
        DepthImage::from_target(&target, camera)
    }

    #[test]
    fn the_mesh_breaks_at_depth_edges_and_matches_the_view_it_warps_to() {
        let r = reference();
        let (mut mesh, mut index) = (Mesh::default(), Vec::new());
        let tris = depth_mesh(&r, 0.05, &mut mesh, &mut index);
        // Two triangles per block of four filled pixels at most, fewer across the edges.
        let full = 2 * (W as usize - 1) * (H as usize - 1);
        assert!(tris < full && tris > full * 3 / 4, "{tris} of {full}");
        assert!(mesh.validate().is_ok());
        // No triangle joins the red box to the wall behind it.
        for t in mesh.indices.chunks(3) {
            let red = t
                .iter()
                .filter(|&&v| mesh.colors[v as usize].r > 0.5)
                .count();
            assert!(red == 0 || red == 3, "a triangle spans the box's edge");
        }
        // Drawn from a moved eye, it shows what that eye sees wherever it covers.
        let target = camera(Vec3::new(0.5, 0.2, 2.2), Vec3::new(0.2, 0.0, -4.0));
        let truth = cast(&target, W, H, &boxes());
        let seen = render(&mesh, &target);
        let (off, both) = mismatch(&seen, &truth, 0.08);
        assert!(both > (W * H) as usize / 2 && off < 0.03, "{off} of {both}");
        // Memory is reused: a second build allocates nothing new in the mesh.
        let cap = mesh.positions.capacity();
        depth_mesh(&r, 0.05, &mut mesh, &mut index);
        assert_eq!(mesh.positions.capacity(), cap);
    }
}
