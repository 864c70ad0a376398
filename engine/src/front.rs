//! Front end: clips, sets up and bins one chunk of triangles (a contiguous range in
//! submission order), writing only that chunk's buffers, so chunks run in parallel.

use crate::bin::Bins;
use crate::clip::{clip_triangle, ClipVert, MAX_POLY};
use crate::color::Rgba;
use crate::material::Shading;
use crate::mesh::Mesh;
use crate::setup::{setup, Dropped, Tri, CLIPPED};
use crate::space::{ScreenVert, Viewport};
use crate::state::DrawInfo;
use crate::stats::FrameStats;
use crate::vertex::{VertexPos, MAX_VARYINGS, NOT_FINITE};
use glam::{Vec3, Vec4};

/// One chunk of triangles' front-end output, on cache lines of its own (its vectors'
/// lengths change with every triangle while another core works on the next chunk).
#[derive(Debug, Default)]
#[repr(align(128))]
pub(crate) struct Chunk {
    pub(crate) tris: Vec<Tri>,
    /// Varyings of vertices made by clipping.
    pub(crate) extra: Vec<f32>,
    pub(crate) bins: Bins,
    /// The chunk's triangles in runs of at most [`CLUSTER`] of one draw, each with its
    /// pixel box and nearest depth, for the tile loop's occlusion test of whole runs.
    pub(crate) clusters: Vec<Cluster>,
    pub(crate) stats: FrameStats,
}

/// Most triangles in one [`Cluster`]: a mesh's neighbouring triangles usually lie near
/// one another, so a short run has a tight box.
pub(crate) const CLUSTER: u32 = 32;

/// A run of consecutive set-up triangles of one draw (at most [`CLUSTER`]): the union of
/// their pixel boxes and the nearest (largest reversed) depth any of their pixels can
/// have, the depth planes' maximum over each triangle's box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cluster {
    /// Index in the chunk's `tris` of the run's first triangle.
    pub(crate) first: u32,
    /// The draw the run's triangles belong to.
    pub(crate) draw: u32,
    /// Inclusive pixel box `[x0, y0, x1, y1]`.
    pub(crate) bbox: [u16; 4],
    /// The nearest depth over the run (no safety margin; the test adds it).
    pub(crate) near: f32,
}

impl Cluster {
    /// The largest depth `tri`'s plane reaches over its pixel box (at one of its corners).
    #[inline]
    fn near_of(tri: &Tri) -> f32 {
        let (w, h) = (
            tri.bbox[2].saturating_sub(tri.bbox[0]) as f32,
            tri.bbox[3].saturating_sub(tri.bbox[1]) as f32,
        );
        let z = &tri.z;
        z.c + (z.dx * w).max(0.0) + (z.dy * h).max(0.0)
    }
}

/// The peers' flat rule: mean vertex colour times `0.25 + 0.75 |n . L|`, as unorm bytes.
fn flat_color(mesh: &Mesh, idx: [usize; 3]) -> u32 {
    let p = idx.map(|i| mesh.positions[i]);
    let c = idx.map(|i| mesh.colors.get(i).copied().unwrap_or(Rgba::WHITE));
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let len = n.length();
    let n = if len > 0.0 { n / len } else { Vec3::ZERO };
    let l = Vec3::new(0.35, 0.6, 0.72);
    let l = l / l.length();
    let shade = 0.25 + 0.75 * n.dot(l).abs();
    let q = |x: f32| ((x * shade).clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8;
    let mean = |f: fn(&Rgba) -> f32| (f(&c[0]) + f(&c[1]) + f(&c[2])) / 3.0;
    u32::from_le_bytes([q(mean(|c| c.r)), q(mean(|c| c.g)), q(mean(|c| c.b)), 255])
}

/// Clip, set up and collect the triangles of one chunk.
pub(crate) fn front_end(
    chunk: &mut Chunk,
    range: std::ops::Range<usize>,
    infos: &[DrawInfo<'_>],
    pos: &[VertexPos],
    vary: &[f32],
    vp: &Viewport,
) {
    chunk.tris.clear();
    chunk.extra.clear();
    chunk.clusters.clear();
    chunk.stats = FrameStats::default();
    if range.is_empty() || vp.width == 0 || vp.height == 0 {
        chunk.stats.triangles_rejected += range.len() as u64;
        return;
    }
    // First draw overlapping the range.
    let mut d = infos.partition_point(|i| i.tri_base + i.mesh.triangle_count() <= range.start);
    let mut t = range.start;
    while t < range.end && d < infos.len() {
        let info = &infos[d];
        let count = info.mesh.triangle_count();
        let end = (info.tri_base + count).min(range.end);
        let stride = info.layout.stride();
        let n_vert = info.mesh.positions.len();
        while t < end {
            let local = t - info.tri_base;
            t += 1;
            let ix = &info.mesh.indices[3 * local..3 * local + 3];
            if ix.iter().any(|&i| i as usize >= n_vert) {
                chunk.stats.triangles_rejected += 1;
                continue;
            }
            let idx = [ix[0] as usize, ix[1] as usize, ix[2] as usize];
            let v = idx.map(|i| &pos[info.vert_base + i]);
            let oc = v.map(|v| v.code);
            if (oc[0] | oc[1] | oc[2]) & NOT_FINITE != 0 {
                chunk.stats.triangles_rejected += 1;
                continue;
            }
            let color = match info.material.shading {
                Shading::FaceId => {
                    (info.prim_base.wrapping_add(local as u32).wrapping_add(1) & 0xff_ffff)
                        | 0xff00_0000
                }
                Shading::Flat => flat_color(info.mesh, idx),
                _ => 0,
            };
            let per_face = matches!(info.material.shading, Shading::FaceId | Shading::Flat);
            let stamp = Stamp {
                draw: d as u32,
                color: per_face.then_some(color),
            };
            if oc[0] | oc[1] | oc[2] == 0 {
                let offs = idx.map(|i| (info.vary_base + i * stride) as u32);
                match setup(
                    [v[0].screen, v[1].screen, v[2].screen],
                    offs,
                    info.cull_back,
                    vp,
                ) {
                    Ok(tri) => stamp.push(chunk, tri, 0),
                    Err(Dropped::Culled) => chunk.stats.triangles_culled += 1,
                    Err(Dropped::Rejected) => chunk.stats.triangles_rejected += 1,
                }
                continue;
            }
            if oc[0] & oc[1] & oc[2] != 0 {
                chunk.stats.triangles_rejected += 1;
                continue;
            }
            let clip = v.map(|v| v.clip);
            let offs = idx.map(|i| info.vary_base + i * stride);
            clip_and_set_up(chunk, info, clip, offs, oc, vary, vp, &stamp);
        }
        d += 1;
    }
    chunk.stats.triangles_set_up = chunk.tris.len() as u64;
}

/// What every triangle made from one input triangle carries: its draw and, for per-face
/// shadings, its colour.
struct Stamp {
    draw: u32,
    color: Option<u32>,
}

impl Stamp {
    /// Stamps `tri`, counts it into the chunk's bins and keeps it.
    #[inline]
    fn push(&self, chunk: &mut Chunk, mut tri: Tri, flags: u32) {
        tri.stamp(self.draw, flags);
        if let Some(c) = self.color {
            tri.set_color(c);
        }
        chunk.bins.count(&tri);
        let k = chunk.tris.len() as u32;
        let near = Cluster::near_of(&tri);
        match chunk.clusters.last_mut() {
            Some(c) if c.draw == self.draw && k - c.first < CLUSTER => {
                c.bbox = [
                    c.bbox[0].min(tri.bbox[0]),
                    c.bbox[1].min(tri.bbox[1]),
                    c.bbox[2].max(tri.bbox[2]),
                    c.bbox[3].max(tri.bbox[3]),
                ];
                // NaN planes never make a run hidden: `max` would drop them.
                c.near = if near.is_nan() {
                    f32::INFINITY
                } else {
                    c.near.max(near)
                };
            }
            _ => chunk.clusters.push(Cluster {
                first: k,
                draw: self.draw,
                bbox: tri.bbox,
                near: if near.is_nan() { f32::INFINITY } else { near },
            }),
        }
        chunk.tris.push(tri);
    }
}

/// A triangle crossing the near, far or guard-band planes (`oc`: its vertices' outcodes,
/// not all outside one plane): clipped to a polygon whose new vertices' varyings go to the
/// chunk's `extra`, then set up as a fan.
#[allow(clippy::too_many_arguments)] // reason: one triangle's inputs, passed through as they are
fn clip_and_set_up(
    chunk: &mut Chunk,
    info: &DrawInfo<'_>,
    clip: [Vec4; 3],
    offs: [usize; 3],
    oc: [u8; 3],
    vary: &[f32],
    vp: &Viewport,
    stamp: &Stamp,
) {
    chunk.stats.triangles_clipped += 1;
    let stride = info.layout.stride();
    let cv = |k: usize| {
        let mut c = ClipVert {
            pos: clip[k],
            vary: [0.0; MAX_VARYINGS],
        };
        c.vary[..stride].copy_from_slice(&vary[offs[k]..offs[k] + stride]);
        c
    };
    let mut poly = [cv(0); MAX_POLY];
    let n = clip_triangle(
        [cv(0), cv(1), cv(2)],
        oc[0] | oc[1] | oc[2],
        vp.guard(),
        stride,
        &mut poly,
    );
    let mut sv = [ScreenVert::default(); MAX_POLY];
    let mut extra = [0u32; MAX_POLY];
    let mut ok = n >= 3;
    for k in 0..n {
        match vp.to_screen(poly[k].pos) {
            Some(s) => sv[k] = s,
            None => ok = false,
        }
        extra[k] = chunk.extra.len() as u32;
        chunk.extra.extend_from_slice(&poly[k].vary[..stride]);
    }
    if !ok {
        chunk.stats.triangles_rejected += 1;
        return;
    }
    for k in 1..n - 1 {
        match setup(
            [sv[0], sv[k], sv[k + 1]],
            [extra[0], extra[k], extra[k + 1]],
            info.cull_back,
            vp,
        ) {
            Ok(tri) => stamp.push(chunk, tri, CLIPPED),
            Err(Dropped::Culled) => chunk.stats.triangles_culled += 1,
            Err(Dropped::Rejected) => {}
        }
    }
}
