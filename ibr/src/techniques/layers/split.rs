//! Large objects cut into layers by depth range: a ground plane or a long wall spans too
//! much depth for one affine warp, so its triangles are shared out among slabs along a
//! direction (the usual view direction), each slab a subject of its own.

use crate::core::MeshGroup;
use engine::Mesh;
use glam::Vec3;
use std::sync::Arc;

/// `group` cut into `slabs` groups by where its triangles' centroids lie along `along`
/// (equal widths between the nearest and the farthest; triangles are not clipped, so a
/// slab's box may reach a little into its neighbours'). Empty slabs are left out; a group
/// with no finite triangle gives none.
pub fn split_by_depth(group: &MeshGroup, along: Vec3, slabs: usize) -> Vec<MeshGroup> {
    let dir = along.normalize_or(Vec3::NEG_Z);
    let slabs = slabs.max(1);
    let depth_of = |part: &crate::core::Part, tri: &[u32]| -> Option<f32> {
        let p = |k: usize| part.mesh.positions.get(tri[k] as usize).copied();
        let c = (p(0)? + p(1)? + p(2)?) / 3.0;
        let d = part.transform.transform_point3(c).dot(dir);
        d.is_finite().then_some(d)
    };
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for part in &group.parts {
        for tri in part.mesh.indices.chunks_exact(3) {
            if let Some(d) = depth_of(part, tri) {
                (lo, hi) = (lo.min(d), hi.max(d));
            }
        }
    }
    if lo > hi {
        return Vec::new();
    }
    let width = ((hi - lo) / slabs as f32).max(f32::MIN_POSITIVE);
    let mut out = vec![MeshGroup::new(); slabs];
    for part in &group.parts {
        let mut pieces = vec![Piece::default(); slabs];
        for tri in part.mesh.indices.chunks_exact(3) {
            let Some(d) = depth_of(part, tri) else {
                continue;
            };
            let k = (((d - lo) / width) as usize).min(slabs - 1);
            pieces[k].take(&part.mesh, tri);
        }
        for (group, piece) in out.iter_mut().zip(pieces) {
            if !piece.mesh.indices.is_empty() {
                let mesh = Arc::new(piece.mesh);
                group.parts.push(crate::core::Part::new(
                    mesh,
                    part.material.clone(),
                    part.transform,
                ));
            }
        }
    }
    out.retain(|g| !g.parts.is_empty());
    out
}

/// Some of a mesh's triangles, with their vertices renumbered.
#[derive(Clone, Debug, Default)]
struct Piece {
    mesh: Mesh,
    /// Source vertex -> this mesh's vertex.
    index: std::collections::HashMap<u32, u32>,
}

impl Piece {
    fn take(&mut self, from: &Mesh, tri: &[u32]) {
        for &v in tri {
            let next = self.mesh.positions.len() as u32;
            let at = *self.index.entry(v).or_insert_with(|| {
                let i = v as usize;
                let m = &mut self.mesh;
                m.positions.push(from.positions[i]);
                if let Some(n) = from.normals.get(i) {
                    m.normals.push(*n);
                }
                if let Some(uv) = from.uvs.get(i) {
                    m.uvs.push(*uv);
                }
                if let Some(c) = from.colors.get(i) {
                    m.colors.push(*c);
                }
                next
            });
            self.mesh.indices.push(at);
        }
    }
}
