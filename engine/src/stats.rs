//! Per-frame work counters. Tests and benchmarks read them; they cost a few adds per
//! triangle and per 8-pixel row, and are summed in a fixed order so they are the same at
//! any thread count.

use std::ops::AddAssign;
use std::time::Duration;

/// What one frame did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameStats {
    /// Draws submitted.
    pub draws: u64,
    /// Draws skipped whole before their vertices were transformed: their bounding box lies
    /// wholly outside one plane of the view frustum (see
    /// [`crate::Renderer::set_draw_culling`]).
    pub draws_culled: u64,
    /// Triangles submitted.
    pub triangles_in: u64,
    /// Of `triangles_rejected`, the triangles of the culled draws (never transformed nor
    /// set up).
    pub triangles_draw_culled: u64,
    /// Vertices transformed (those of the draws not culled).
    pub vertices_transformed: u64,
    /// Triangles that crossed the near, far or guard-band planes and were clipped.
    pub triangles_clipped: u64,
    /// Triangles dropped as back-facing.
    pub triangles_culled: u64,
    /// Triangles dropped as invalid (non-finite positions, zero area, wholly outside the
    /// frustum, or covering no pixel centre), those of culled draws included.
    pub triangles_rejected: u64,
    /// Triangles set up for binning: their pixel bounding box holds a pixel centre, and
    /// when it holds at most 4, at least one of them is covered.
    pub triangles_set_up: u64,
    /// (triangle, tile) pairs written to the bins.
    pub triangles_binned: u64,
    /// Covered pixels that reached the per-pixel depth test (pixels of 8 x 8 blocks that the
    /// hierarchical depth test rejected whole are not counted here).
    pub fragments_tested: u64,
    /// Fragments that passed the depth test and were shaded (a nailboard's at the depth its
    /// offset moves them to: those hidden there read their offset only, and are not counted).
    pub fragments_shaded: u64,
    /// Of `fragments_shaded`, those of blended draws (each shades what lies behind it too:
    /// `fragments_shaded - fragments_shaded_blended` over the pixels is the opaque
    /// overdraw).
    pub fragments_shaded_blended: u64,
    /// Of `fragments_shaded`, those shaded by the general shader (textures, vertex colour
    /// or lights), the costliest per fragment.
    pub fragments_shaded_general: u64,
    /// Rows of 8 lanes the shader ran on (`fragments_shaded / rows_shaded` is how full the
    /// lanes were: 8 at best; thin and small triangles leave most lanes idle).
    pub rows_shaded: u64,
    /// Of `rows_shaded`, those that held a pack of two rows or more of a triangle in a
    /// block (8 covered lanes at most, sharing one texture level of detail).
    pub rows_paired: u64,
    /// Fragments written to the target (after alpha test).
    pub fragments_written: u64,
    /// 8 x 8 blocks found wholly inside a triangle (no per-pixel edge tests).
    pub blocks_full: u64,
    /// 8 x 8 blocks that needed per-pixel edge tests.
    pub blocks_partial: u64,
    /// 8 x 8 blocks skipped because the triangle lies behind everything stored there.
    pub blocks_hiz_rejected: u64,
    /// Clusters (runs of up to 32 consecutive triangles of one draw) skipped in a tile
    /// because they lie wholly behind the depth stored in every block they overlap there.
    pub clusters_occluded: u64,
    /// (triangle, tile) pairs of those clusters: never read nor rasterized in that tile.
    pub triangles_occluded: u64,
}

impl AddAssign for FrameStats {
    fn add_assign(&mut self, o: Self) {
        self.draws += o.draws;
        self.draws_culled += o.draws_culled;
        self.triangles_in += o.triangles_in;
        self.triangles_draw_culled += o.triangles_draw_culled;
        self.vertices_transformed += o.vertices_transformed;
        self.triangles_clipped += o.triangles_clipped;
        self.triangles_culled += o.triangles_culled;
        self.triangles_rejected += o.triangles_rejected;
        self.triangles_set_up += o.triangles_set_up;
        self.triangles_binned += o.triangles_binned;
        self.fragments_tested += o.fragments_tested;
        self.fragments_shaded += o.fragments_shaded;
        self.fragments_shaded_blended += o.fragments_shaded_blended;
        self.fragments_shaded_general += o.fragments_shaded_general;
        self.rows_shaded += o.rows_shaded;
        self.rows_paired += o.rows_paired;
        self.fragments_written += o.fragments_written;
        self.blocks_full += o.blocks_full;
        self.blocks_partial += o.blocks_partial;
        self.blocks_hiz_rejected += o.blocks_hiz_rejected;
        self.clusters_occluded += o.clusters_occluded;
        self.triangles_occluded += o.triangles_occluded;
    }
}

/// What one draw cost in the tile stage, read with [`crate::Renderer::draw_costs`] after
/// [`crate::Renderer::set_draw_costs`] turned the counting on: which draws of a frame shade
/// the most fragments, and how long their triangles took. The counts are integer sums, the
/// same at any thread count; `raster` is wall-clock time summed over the workers (for
/// profiling only, and itself slowed by the two clock reads per triangle and tile).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawCost {
    /// Covered pixels of the draw that reached the per-pixel depth test.
    pub fragments_tested: u64,
    /// Fragments of the draw that passed the depth test and were shaded.
    pub fragments_shaded: u64,
    /// Rows of 8 lanes the draw's shader ran on.
    pub rows_shaded: u64,
    /// Time in the raster and shade of the draw's triangles, summed over the workers.
    pub raster: Duration,
}

impl AddAssign for DrawCost {
    fn add_assign(&mut self, o: Self) {
        self.fragments_tested += o.fragments_tested;
        self.fragments_shaded += o.fragments_shaded;
        self.rows_shaded += o.rows_shaded;
        self.raster += o.raster;
    }
}
