//! The renderer: runs the stages in order and owns the scratch memory they share.
//!
//! `cull` (draws whose bounding box lies wholly outside the frustum are dropped) -> `vertex`
//! (parallel over draws and over vertices) -> `clip` + `setup` + `bin` (parallel over
//! fixed chunks of triangles, each chunk writing only its own buffers) -> `raster` + `shade`
//! (parallel over tiles, each worker owning one tile's memory) -> resolve into the target.
//! Opaque and alpha-tested draws go first, sorted near to far by their bounding boxes (so
//! what lies behind is mostly rejected before it is shaded: the depth test is strict, and
//! only fragments of exactly equal depth from two draws can come out otherwise than in
//! submission order), then blended draws sorted back to front, so a tile sees every
//! triangle in one deterministic order whatever the thread count. All buffers live in the [`Renderer`] and are reset, not reallocated, each
//! frame: once a scene has been drawn, drawing it again allocates nothing.

use crate::camera::Camera;
use crate::color::{Encoder, Rgba};
use crate::front::{front_end, Chunk};
use crate::light::Lighting;
use crate::material::{Material, Shading};
use crate::mesh::Mesh;
use crate::raster::DepthToView;
use crate::scene::{Draw, Scene};
use crate::shade::{ColorShader, ConstShader};
use crate::space::Viewport;
use crate::state::{DrawInfo, Kind, PixelMode};
use crate::stats::{DrawCost, FrameStats};
use crate::target::{Target, TILE, TILE_PIXELS};
use crate::tile::TileBuf;
use crate::vertex::{self, Layout, VertexPos};
use glam::{Mat4, Vec3};
use rayon::prelude::*;
use std::sync::Mutex;
use std::time::{Duration, Instant};
use tiles::{prepass_allowed, Counters, TileFrame};

/// One worker thread's tile memory and counters (each draw's cost too, when counted), on cache lines of its own: the raster
/// stage updates them for every triangle and row, and a neighbour on the same line would
/// make the other core's reads of its own fields miss. (Counters are integer sums, so
/// which worker counted a tile does not change the frame's totals.)
#[derive(Debug, Default)]
#[repr(align(128))]
struct Worker(Mutex<(TileBuf, FrameStats, StageTimes, Vec<DrawCost>)>);

/// Where the last frame's time went, stage by stage: wall-clock time of the vertex and
/// front-end (clip, set up, bin) stages and of the whole tile stage, and, within the tile
/// stage, the time summed over all workers spent rastering and shading (tile clears and
/// loads included) and resolving tiles to bytes. Read with [`Renderer::stage_times`]; for
/// profiling only: pixels never depend on it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// Vertex stage (wall clock).
    pub vertex: Duration,
    /// Clip, set up and bin (wall clock, parallel over chunks).
    pub front: Duration,
    /// The tile stage (wall clock, parallel over tiles).
    pub tiles: Duration,
    /// Raster and shade, summed over the workers.
    pub raster: Duration,
    /// Resolve, summed over the workers.
    pub resolve: Duration,
}

/// What the tile stage reads of the frame besides the renderer's own buffers.
struct FrameInputs<'f, 'a> {
    infos: &'f [DrawInfo<'a>],
    lighting: &'f Lighting,
    camera: &'f Camera,
    opts: &'f FrameOptions,
    peel: Option<&'f [f32]>,
}

/// Which faces are culled.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Cull {
    /// Back faces of single-sided materials (the default).
    #[default]
    PerMaterial,
    /// Nothing.
    None,
    /// Every back face, double-sided materials included.
    Back,
}

/// Per-frame options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameOptions {
    /// Clear colour (straight linear), or `None` to draw over the target's contents.
    pub clear: Option<Rgba>,
    /// Which faces are culled.
    pub cull: Cull,
}

impl Default for FrameOptions {
    fn default() -> Self {
        FrameOptions {
            clear: Some(Rgba::BLACK),
            cull: Cull::PerMaterial,
        }
    }
}

/// Renders draws into targets. Keep one alive across frames: it owns the scratch memory.
///
/// Two quads drawn with [`Renderer::render`]: the smaller one is nearer, so the depth
/// test keeps it in front although it is drawn first.
///
/// ```rust
/// use engine::{Camera, Draw, FrameOptions, Lighting, Material, Mesh, Renderer, Rgba, Target};
/// use glam::{Mat4, Vec3};
///
/// // A unit quad in the z = 0 plane, facing +Z (counter-clockwise seen from the camera).
/// let quad = Mesh {
///     positions: vec![
///         Vec3::new(-1.0, -1.0, 0.0),
///         Vec3::new(1.0, -1.0, 0.0),
///         Vec3::new(1.0, 1.0, 0.0),
///         Vec3::new(-1.0, 1.0, 0.0),
///     ],
///     indices: vec![0, 1, 2, 0, 2, 3],
///     ..Default::default()
/// };
/// let red = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
/// let blue = Material::unlit(Rgba::new(0.0, 0.0, 1.0, 1.0));
/// let camera = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.0, 1.0);
/// let near = Mat4::from_translation(Vec3::Z) * Mat4::from_scale(Vec3::splat(0.5));
/// let draws = [
///     Draw { mesh: &quad, material: &blue, transform: near },
///     Draw { mesh: &quad, material: &red, transform: Mat4::IDENTITY },
/// ];
/// let mut renderer = Renderer::new();
/// let mut target = Target::new(64, 64);
/// let opts = FrameOptions::default();
/// let stats = renderer.render(draws, &camera, &Lighting::default(), &mut target, &opts);
/// assert_eq!(stats.triangles_set_up, 4);
/// // Packed bytes r | g << 8 | b << 16 | a << 24: blue in the middle, red around it,
/// // the opaque black clear colour in the corner.
/// assert_eq!(target.pixel(32, 32), Some(0xffff_0000));
/// assert_eq!(target.pixel(23, 32), Some(0xff00_00ff));
/// assert_eq!(target.pixel(0, 0), Some(0xff00_0000));
/// // The depth at the centre is that of the blue quad, 4 units in front of the camera.
/// let depth = target.depth_reversed(32, 32).unwrap();
/// assert!((camera.view_depth_from_reversed(depth) - 4.0).abs() < 1e-3);
/// ```
#[derive(Debug, Default)]
pub struct Renderer {
    pos: Vec<VertexPos>,
    vary: Vec<f32>,
    chunks: Vec<Chunk>,
    workers: Vec<Worker>,
    infos: Vec<DrawInfo<'static>>,
    sort_keys: Vec<(u32, f32, u32)>,
    /// Which positions of the frame's draws hold their sorted draw (scratch of
    /// [`Renderer::order_draws`]).
    placed: Vec<bool>,
    last: FrameStats,
    times: StageTimes,
    /// Draw tiles with the visibility pre-pass (see [`Renderer::set_visibility_prepass`]).
    prepass: bool,
    /// Count each draw's cost (see [`Renderer::set_draw_costs`]).
    count_costs: bool,
    /// Draw every cluster, hidden or not (see [`Renderer::set_cluster_occlusion`]).
    occlusion_off: bool,
    /// The last frame's cost of each draw, in submission order (empty when not counted).
    costs: Vec<DrawCost>,
    /// The frame's directional lights' unit vectors (`shade::light_dirs`).
    light_dirs: Vec<Vec3>,
    /// The frame's meshes' bounding boxes (culling and draw order).
    boxes: cull::Boxes,
    /// Transform every draw, in view or not (see [`Renderer::set_draw_culling`]).
    culling_off: bool,
    /// How many times smaller each way low-resolution draws are shaded (see
    /// [`Renderer::set_low_res_scale`]); 0 and 1 are full resolution.
    low_res_scale: u32,
    /// The low-resolution pass's scratch memory.
    low: lowres::LowRes,
}

/// Reuses an empty vector's allocation for a type that differs only in lifetime.
fn recycle<'b, 'a>(mut v: Vec<DrawInfo<'a>>) -> Vec<DrawInfo<'b>> {
    v.clear();
    v.into_iter().map(|_| unreachable!("empty")).collect()
}

fn classify(m: &Material, mesh: &Mesh) -> (Kind, Layout) {
    let base = m.base_color.to_array();
    let plain = m.base_texture.is_none()
        && m.emissive.r == 0.0
        && m.emissive.g == 0.0
        && m.emissive.b == 0.0;
    match m.shading {
        Shading::FaceId | Shading::Flat => (
            Kind::Const(ConstShader {
                color: base,
                per_triangle: true,
            }),
            Layout::None,
        ),
        Shading::Unlit if plain && (!m.vertex_colors || mesh.colors.is_empty()) => (
            Kind::Const(ConstShader {
                color: base,
                per_triangle: false,
            }),
            Layout::None,
        ),
        Shading::Unlit if plain => (Kind::Color(ColorShader { base }), Layout::Color),
        _ => (Kind::General, Layout::Full),
    }
}

impl Renderer {
    /// A renderer with no scratch memory yet; the first frames allocate it.
    pub fn new() -> Self {
        Self::default()
    }

    /// Counters of the last frame.
    pub fn stats(&self) -> FrameStats {
        self.last
    }

    /// Whether tiles shade opaque pixels once, after a depth pre-pass (off by default). On,
    /// a frame whose opaque draws all test and write depth (and is not a depth peel)
    /// rasterizes its opaque and alpha-tested triangles first, opaque ones for depth only,
    /// and shades each opaque pixel only with the triangle that stays nearest there. The
    /// pixels are the same either way. Off by default because it measured slower on the
    /// showcase's tour (BENCHMARKS.md, "A visibility pre-pass per tile"): shading runs a
    /// row of 8 lanes at a time, and the hidden fragments it removes mostly sit in rows
    /// that are shaded anyway, while the opaque triangles are rasterized twice.
    pub fn set_visibility_prepass(&mut self, on: bool) {
        self.prepass = on;
    }

    /// Whether the tile loop skips a cluster (a run of up to 32 consecutive triangles of
    /// one draw, as the front end set them up) whose box and nearest depth lie wholly
    /// behind the depth stored in every 8 x 8 block of a tile it overlaps (on by default;
    /// no pixel changes, the skipped triangles could pass no depth test there). Counted in
    /// [`FrameStats::clusters_occluded`] and [`FrameStats::triangles_occluded`]; off, those
    /// triangles are rasterized and rejected block by block as before.
    pub fn set_cluster_occlusion(&mut self, on: bool) {
        self.occlusion_off = !on;
    }

    /// Whether a draw whose bounding box lies wholly outside one plane of the view frustum
    /// (near, far or a side of the image) is skipped before its vertices are transformed
    /// (on by default). No pixel changes: every triangle of such a draw would be rejected
    /// or cover no pixel centre. Counted in [`FrameStats::draws_culled`] and
    /// [`FrameStats::triangles_draw_culled`] (their triangles stay counted as rejected).
    pub fn set_draw_culling(&mut self, on: bool) {
        self.culling_off = !on;
    }

    /// Where the last frame's time went, stage by stage (for profiling).
    pub fn stage_times(&self) -> StageTimes {
        self.times
    }

    /// Counts what each draw costs in the tile stage from the next frame on (off by
    /// default: two clock reads per triangle and tile). Read with
    /// [`Renderer::draw_costs`]; pixels never depend on it.
    pub fn set_draw_costs(&mut self, on: bool) {
        self.count_costs = on;
    }

    /// The last frame's cost of each draw, in the order the draws were submitted (empty
    /// unless [`Renderer::set_draw_costs`] turned the counting on). The fragment and row
    /// counts sum to the frame's [`FrameStats`] and are the same at any thread count.
    pub fn draw_costs(&self) -> &[DrawCost] {
        &self.costs
    }

    /// Renders every instance of `scene` with its own lighting.
    pub fn render_scene(
        &mut self,
        scene: &Scene,
        camera: &Camera,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        self.render(scene.draws(), camera, &scene.lighting, target, opts)
    }

    /// Renders one frame of `draws` into `target`. Never fails: odd geometry is skipped and
    /// counted in [`FrameStats::triangles_rejected`].
    pub fn render<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        if self.low_res_scale > 1 {
            return self.render_low_res(draws, camera, lighting, target, opts);
        }
        self.frame(draws, camera, lighting, target, opts, None)
    }

    /// Depth peeling: renders `draws` keeping, per pixel, only fragments strictly behind the
    /// depth stored in `behind` (a second depth compare, on top of the usual test against
    /// `target`'s own depth). With `behind` holding layer k of a scene (the nearest surfaces
    /// for k = 0), the result is layer k + 1: the nearest surfaces behind it, and cleared
    /// pixels where no surface is left. Render layer 0 with [`Renderer::render`], then peel
    /// with the previous layer's target. A `behind` of another size than `target` lets
    /// nothing through.
    pub fn render_behind<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        target: &mut Target,
        opts: &FrameOptions,
        behind: &Target,
    ) -> FrameStats {
        let same = behind.width() == target.width() && behind.height() == target.height();
        let peel = if same { behind.depth_storage() } else { &[] };
        self.frame(draws, camera, lighting, target, opts, Some(peel))
    }

    /// One frame; `peel` is the tile-major depth fragments must lie strictly behind (an
    /// empty slice lets nothing through).
    fn frame<'a>(
        &mut self,
        draws: impl IntoIterator<Item = Draw<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        target: &mut Target,
        opts: &FrameOptions,
        peel: Option<&[f32]>,
    ) -> FrameStats {
        let mut infos: Vec<DrawInfo<'a>> = recycle(std::mem::take(&mut self.infos));
        let mut prim_base = 0u32;
        for d in draws {
            let (kind, layout) = classify(d.material, d.mesh);
            let blended = d.material.is_blended();
            infos.push(DrawInfo {
                mesh: d.mesh,
                material: d.material,
                transform: d.transform,
                layout,
                kind,
                vert_base: 0,
                vary_base: 0,
                tri_base: 0,
                prim_base,
                cull_back: match opts.cull {
                    Cull::PerMaterial => !d.material.double_sided,
                    Cull::None => false,
                    Cull::Back => true,
                },
                mode: PixelMode {
                    depth_test: d.material.depth_test,
                    depth_write: !blended,
                    blend_depth: match d.material.blend_depth {
                        Some(a) if blended && a.is_finite() => a.clamp(0.0, 1.0),
                        _ => f32::INFINITY,
                    },
                    alpha: d.material.alpha_mode,
                    blend: d.material.blend,
                    soft: if blended {
                        d.material.soft_distance
                    } else {
                        0.0
                    },
                    peel: peel.is_some(),
                },
            });
            prim_base = prim_base.wrapping_add(d.mesh.triangle_count() as u32);
        }
        self.frame_infos(infos, camera, lighting, target, opts, peel)
    }

    /// The frame's work after its draws are listed: not generic, so the pipeline is
    /// compiled once, here, whichever crate calls [`Renderer::render`] with whichever
    /// iterator (its speed does not depend on the caller's code generation).
    fn frame_infos<'a>(
        &mut self,
        mut infos: Vec<DrawInfo<'a>>,
        camera: &Camera,
        lighting: &Lighting,
        target: &mut Target,
        opts: &FrameOptions,
        peel: Option<&[f32]>,
    ) -> FrameStats {
        let start = Instant::now();
        let submitted = infos.len();
        let mut culled_tris = 0;
        let kept = self.order_draws(&mut infos, camera);
        for info in &infos[kept..] {
            culled_tris += info.mesh.triangle_count() as u64;
        }
        infos.truncate(kept);
        let vp = Viewport {
            width: target.width(),
            height: target.height(),
        };
        let nt = self.vertex_stage(&mut infos, camera, &vp);
        let vertex_done = Instant::now();
        let (tiles_x, tiles_y) = (target.tiles_x() as usize, target.tiles_y() as usize);
        let n_chunks = self.front_stage(&infos, nt, &vp, tiles_x, tiles_y);
        let front_done = Instant::now();
        let frame = FrameInputs {
            infos: &infos,
            lighting,
            camera,
            opts,
            peel,
        };
        self.tile_stage(&frame, n_chunks, target);
        let mut total = FrameStats {
            draws: submitted as u64,
            draws_culled: (submitted - kept) as u64,
            triangles_in: nt as u64 + culled_tris,
            triangles_draw_culled: culled_tris,
            triangles_rejected: culled_tris,
            vertices_transformed: self.pos.len() as u64,
            ..Default::default()
        };
        for c in &self.chunks[..n_chunks] {
            total += c.stats;
        }
        let mut times = StageTimes {
            vertex: vertex_done - start,
            front: front_done - vertex_done,
            tiles: front_done.elapsed(),
            ..Default::default()
        };
        for w in &mut self.workers {
            let (_, stats, t, _) = w.0.get_mut().unwrap_or_else(|e| e.into_inner());
            total += *stats;
            times.raster += t.raster;
            times.resolve += t.resolve;
        }
        self.gather_costs(submitted);
        self.infos = recycle(infos);
        self.last = total;
        self.times = times;
        total
    }

    /// Vertex stage: lays the draws' vertices and varyings out one after the other and
    /// transforms them; returns the frame's triangle count.
    fn vertex_stage(
        &mut self,
        infos: &mut [DrawInfo<'_>],
        camera: &Camera,
        vp: &Viewport,
    ) -> usize {
        let view_proj = camera.clip_from_world();
        let (mut nv, mut nf, mut nt) = (0, 0, 0);
        for info in infos.iter_mut() {
            info.vert_base = nv;
            info.vary_base = nf;
            info.tri_base = nt;
            nv += info.mesh.positions.len();
            nf += info.mesh.positions.len() * info.layout.stride();
            nt += info.mesh.triangle_count();
        }
        self.pos.resize(nv, VertexPos::default());
        self.vary.resize(nf, 0.0);
        transform_draws(infos, view_proj, vp, &mut self.pos, &mut self.vary);
        nt
    }

    /// Clip, set up and bin, in chunks of triangles (one chunk per task); returns how many
    /// chunks the `nt` triangles took.
    fn front_stage(
        &mut self,
        infos: &[DrawInfo<'_>],
        nt: usize,
        vp: &Viewport,
        tiles_x: usize,
        tiles_y: usize,
    ) -> usize {
        let chunk_size = nt.div_ceil(16).max(4096);
        let n_chunks = nt.div_ceil(chunk_size);
        if self.chunks.len() < n_chunks {
            self.chunks.resize_with(n_chunks, Chunk::default);
        }
        let (pos, vary) = (&self.pos[..], &self.vary[..]);
        self.chunks[..n_chunks]
            .par_iter_mut()
            .enumerate()
            .with_max_len(1) // one chunk per task, for the same reason as the tiles
            .for_each(|(k, chunk)| {
                let range = k * chunk_size..((k + 1) * chunk_size).min(nt);
                chunk.bins.begin(tiles_x, tiles_y);
                front_end(chunk, range, infos, pos, vary, vp);
                chunk.stats.triangles_binned = chunk.bins.build(&chunk.tris);
            });
        n_chunks
    }

    /// Raster, shade and resolve, one tile per task, each worker in its own tile memory.
    fn tile_stage(&mut self, frame: &FrameInputs<'_, '_>, n_chunks: usize, target: &mut Target) {
        let threads = rayon::current_num_threads().max(1);
        while self.workers.len() < threads {
            self.workers.push(Worker::default());
        }
        for w in &mut self.workers {
            let state = w.0.get_mut().unwrap_or_else(|e| e.into_inner());
            (state.1, state.2) = Default::default();
            state.3.clear();
            if self.count_costs {
                state.3.resize(frame.infos.len(), DrawCost::default());
            }
        }
        let tiles_x = target.tiles_x() as usize;
        let encoder = Encoder::new(target.encoding());
        let clear = frame.opts.clear.map(|c| c.premultiply());
        let encoding = target.encoding();
        let soft = DepthToView::new(*frame.camera);
        crate::shade::light_dirs(frame.lighting, &mut self.light_dirs);
        let tiles = TileFrame {
            chunks: &self.chunks[..n_chunks],
            infos: frame.infos,
            vary: &self.vary[..],
            lighting: frame.lighting,
            light_dirs: &self.light_dirs,
            eye: frame.camera.eye(),
            soft: &soft,
            prepass: self.prepass && frame.peel.is_none() && prepass_allowed(frame.infos),
            costs: self.count_costs,
            occlusion: !self.occlusion_off,
        };
        let (workers, peel) = (&self.workers[..], frame.peel);
        let chunks = &self.chunks[..n_chunks];
        // Drawing over the target's contents, a tile no triangle reaches keeps them: it is
        // neither loaded nor resolved (a pass of a few draws costs their tiles only).
        let untouched = |tile: usize| {
            clear.is_none() && peel.is_none() && chunks.iter().all(|c| c.bins.tile(tile).is_empty())
        };
        let (colors, depths) = target.storage_mut();
        colors
            .par_chunks_mut(TILE_PIXELS)
            .zip(depths.par_chunks_mut(TILE_PIXELS))
            .enumerate()
            // One tile per task: left to split by halves, rayon gave each thread long
            // runs of tiles it could no longer share, and one core idled while the other
            // finished the busier half of the screen (torus 100k at 1920x1080: 4.5 of
            // 9.4 ms).
            .with_max_len(1)
            .for_each(|(tile, (color, depth))| {
                if untouched(tile) {
                    return;
                }
                let w = rayon::current_thread_index().unwrap_or(0) % workers.len();
                let mut state = workers[w].0.lock().unwrap_or_else(|e| e.into_inner());
                let (buf, stats, times, costs) = &mut *state;
                let start = Instant::now();
                match clear {
                    Some(c) => buf.clear(c),
                    None => buf.load(color, depth, encoding),
                }
                if let Some(peel) = peel {
                    let range = tile * TILE_PIXELS..(tile + 1) * TILE_PIXELS;
                    // No peel depth (the sizes differ): -inf, which no fragment lies
                    // behind, so nothing passes.
                    match peel.get(range) {
                        Some(d) => buf.load_peel(d),
                        None => {
                            buf.peel.clear();
                            buf.peel.resize(TILE_PIXELS, f32::NEG_INFINITY);
                        }
                    }
                }
                let ox = ((tile % tiles_x) * TILE) as i32;
                let oy = ((tile / tiles_x) * TILE) as i32;
                let mut counters = Counters { stats, costs };
                tiles.raster(buf, tile, ox, oy, &mut counters);
                let rastered = Instant::now();
                buf.resolve(color, depth, &encoder);
                times.raster += rastered - start;
                times.resolve += rastered.elapsed();
            });
    }

    /// Sums the workers' per-draw costs, in worker order, into `self.costs`, back in
    /// submission order (`order_draws` left the frame's order in `sort_keys`).
    fn gather_costs(&mut self, n: usize) {
        self.costs.clear();
        if !self.count_costs {
            return;
        }
        self.costs.resize(n, DrawCost::default());
        for w in &mut self.workers {
            let (_, _, _, costs) = w.0.get_mut().unwrap_or_else(|e| e.into_inner());
            for (k, c) in costs.iter().enumerate() {
                if let Some(&(_, _, submitted)) = self.sort_keys.get(k) {
                    if let Some(slot) = self.costs.get_mut(submitted as usize) {
                        *slot += *c;
                    }
                }
            }
        }
    }
}

/// Transforms the vertices of `infos` into `pos` and `vary`, which hold exactly those
/// draws' vertices and varyings, laid out from `infos[0].vert_base` and
/// `infos[0].vary_base` on as the draws' bases say. The draws are split in two runs of
/// about equal vertex counts, done in parallel, down to single draws or runs of at most
/// one chunk of vertices (most of a scene's draws are far smaller than a chunk, and one at
/// a time they kept one core idle).
fn transform_draws(
    infos: &[DrawInfo<'_>],
    clip_from_world: Mat4,
    vp: &Viewport,
    pos: &mut [VertexPos],
    vary: &mut [f32],
) {
    let Some(first) = infos.first() else {
        return;
    };
    let (v0, f0) = (first.vert_base, first.vary_base);
    if infos.len() == 1 || pos.len() <= vertex::CHUNK {
        for info in infos {
            let (p, f) = (info.vert_base - v0, info.vary_base - f0);
            let n = info.mesh.positions.len();
            let s = info.layout.stride();
            vertex::transform(
                info.mesh,
                info.transform,
                clip_from_world,
                info.layout,
                vp,
                &mut pos[p..p + n],
                &mut vary[f..f + n * s],
            );
        }
        return;
    }
    let half = v0 + pos.len() / 2;
    let m = infos
        .partition_point(|i| i.vert_base < half)
        .clamp(1, infos.len() - 1);
    let (pos_a, pos_b) = pos.split_at_mut(infos[m].vert_base - v0);
    let (vary_a, vary_b) = vary.split_at_mut(infos[m].vary_base - f0);
    rayon::join(
        || transform_draws(&infos[..m], clip_from_world, vp, pos_a, vary_a),
        || transform_draws(&infos[m..], clip_from_world, vp, pos_b, vary_b),
    );
}

mod cull;
mod lowres;
mod order;
mod tiles;

#[cfg(test)]
mod tests;
