//! The showcase's image-based layer: a forest of axial-billboard trees baked from the tree
//! meshes, a laser exchange between two turrets with explosions where the bolts hit, a sun
//! with a lens flare occluded by whatever is drawn in front of it, the impostored sky of
//! clouds and the planned city district ([`crate::showcase::impostors`]), and a statue drawn
//! from its light field ([`crate::showcase::lightfield`]).
//!
//! Everything here is driven by absolute time, so a headless run is deterministic: bolts
//! are fired on a fixed schedule and the effects are stepped by the time since the last
//! pose.

use crate::showcase::impostors::{self, Impostors};
use crate::showcase::lightfield::Statue;
use bands::{bands, forest_draws, Forest};
use costs::Metered;
pub use costs::{DrawGroups, GroupCost, GROUPS};
use engine::procedural::{self, Terrain, TreeKind, XorShift};
use engine::{
    Camera, Draw, FrameOptions, FrameStats, Light, Lighting, Material, Mesh, Renderer, Rgba, Scene,
    Shading, Target,
};
use glam::{Mat4, Vec2, Vec3};
use ibr::billboard::ViewAtlas;
use ibr::effects::Effects;
use ibr::flare::{FlareSource, LensFlare};
use ibr::impostor::Frustum;
use ibr::laser::{Laser, LaserBatch};
use ibr::technique::{Counters, Flare, FrameLoop, FrameView, Technique};
use ibr::{Billboard, Facing};

/// Billboard trees in the forest ring.
pub const FOREST_TREES: usize = 2400;
/// Side of each of a tree's baked views, texels (framing its bounding sphere).
pub const SPRITE_PX: u32 = 256;
/// Directions about the vertical each tree is baked from at each of [`SPRITE_ELEVATIONS`]:
/// a tree shows the side it is seen from (lit or in shade), the bake nearest the eye's
/// direction (a single side bake showed its sunlit side from everywhere and lay down when
/// seen from above: 14.6 dB against the meshes). The trees are turned about the vertical
/// ([`lathe`]) and lit by one sun, so the azimuth changes only their shading, mirrored
/// about the sun's azimuth ([`ViewAtlas::bake_turned`]): these 12 span the half turn from
/// the sun, 16.4 degrees apart (as 22 around), the other half their mirror images. 8
/// around (45 degrees apart) measured 24.6 / 19.5 dB on the 640 x 360 tour; 12 over the
/// half turn +0.4 dB mean, as 24 around, for 50 MB more resident where 24 around took
/// 200 MB (session 14).
pub const SPRITE_AZIMUTHS: usize = 12;
/// Each tree kind's point up its axis the view is chosen from ([`AIM`] times it), in
/// the unit-tall mesh's units above its sphere's centre: the broadleaf's crown's centre
/// (0.7 up, the sphere's centre 0.485), the pine's a little above its centre. Until
/// session 30 the views also stood on the plane through it ([`ViewAtlas::pivot`], and for
/// the pine a lower one seen from above, `ViewAtlas::pivot_steep`), where the outline's
/// surface lies: a flat sprite's correction for perspective, which the nailboards'
/// parallax search ([`PARALLAX_TOLERANCE`]) makes texel by texel (session 14: 24.6 / 19.3
/// dB on the 640 x 360 tour through the sphere's centre, 25.3 / 21.3 through these).
const CROWN_PIVOT: f32 = 0.2;
const PINE_PIVOT: f32 = 0.1;
/// A tree shows the view baked nearest the eye's direction from the point `AIM` times its
/// pivot ([`CROWN_PIVOT`], [`PINE_PIVOT`]) above its centre (up in the crown) rather than
/// from the centre: from above, the crown's top is seen from lower than the centre, and its
/// sunlit rim showed brighter than the mesh's (session 14, 640 x 360 tour: from the centre 25.31 / 21.26 dB, from one pivot
/// up 25.42 / 21.54; with the mirrored views, one pivot up 25.84 / 21.72, two 25.89 /
/// 21.99).
const AIM: f32 = 2.0;
/// Elevations (degrees) each tree is baked from, 5 apart: a view shown at most 2.5 degrees
/// of elevation off, where the turned crowns' outlines still change (10 apart: 24.8 / 18.2
/// dB on the 640 x 360 tour with 12 azimuths; 5 apart with 12 azimuths 25.0 / 20.0 for
/// 220 MB more resident). From 10 degrees below the horizon: from the plaza the eye is
/// below the crowns of the trees on the hills, and the view is aimed from up in the crown
/// ([`AIM`]); from 0 such a crown showed the view from above it, its sunlit cap reaching
/// too far down (session 16, 640 x 360 tour: 25.98 / 22.95 dB from 0, 26.17 / 22.95 from
/// -10, the same from -15 and -30; frames 20 to 28 gained 0.8 to 1.4 dB).
pub const SPRITE_ELEVATIONS: [f32; 20] = [
    -10.0, -5.0, 0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0, 50.0, 55.0, 60.0, 65.0,
    70.0, 75.0, 80.0, 85.0,
];
/// A tree nearer the eye than this many of its quad's sides is drawn as its mesh: up
/// close the quad through its centre no longer covers what the tree does in perspective
/// (its near side reaches out toward the eye), and at 1280 x 720 and the showcase's field of
/// view its sprite would be magnified (taller than [`SPRITE_PX`] on screen) off to the
/// side of the view.
pub const NEAR_SIZES: f32 = 3.5;
/// The forest's nailboards show each fragment the texel whose surface lies on its ray
/// ([`ViewAtlas::parallax`]; reached with an offset this close, in fractions of the
/// offsets' span, 3 radii) rather than the one straight behind it on the view's plane.
/// A view is orthographic and the tour sees it in perspective: a pine's lowest rim,
/// nearer the eye than the plane, showed a third of a pixel high, and the outlines' tops
/// and bottoms carried 41% of the forest's squared error on frames 0 to 49 (session 30).
/// 640 x 360 tour (120 frames, with [`SPRITE_MAX_LOD`], the colour blended across two
/// levels): 29.38 / 25.34 dB without, 31.02 / 26.47 with; tolerance 0.02 30.94 / 25.49,
/// 0.04 30.98 / 26.26, 0.05 30.86 / 24.07. 1280 x 720: 30.56 / 23.77 at 0.01, 30.70 /
/// 24.70 at 0.02, 30.83 / 25.97 at 0.03, 30.82 / 26.09 at 0.04. As committed (the colour
/// read on one level): 31.00 / 26.44 and 30.82 / 26.01.
pub const PARALLAX_TOLERANCE: f32 = 0.03;
/// The coarsest mip level the forest's sprites read ([`ViewAtlas::max_lod`]): the meshes
/// they stand for are drawn one sample a pixel, sharper than a view prefiltered over the
/// pixel's footprint (2 to 3 levels down at 640 x 360). Without parallax, 640 x 360:
/// 28.66 / 24.55 dB at every level, 28.96 / 24.54 at 2, 29.38 / 25.34 at 1.5, 29.39 /
/// 25.23 at 1.25, 29.36 / 25.28 at 1; reading level 0 only, 29.16 / 25.01. 1280 x 720:
/// 29.22 / 25.00 at every level, 29.30 / 25.00 at 1.5, 29.29 / 24.85 at 1.
pub const SPRITE_MAX_LOD: f32 = 1.5;
/// Seconds between bolts fired from turret B at turret A.
const BOLT_PERIOD: f32 = 1.6;
/// Bolt speed (units per second) and length.
const BOLT_SPEED: f32 = 24.0;
const BOLT_LENGTH: f32 = 2.5;
/// Height of a turret's emitter above its base.
const TURRET_HEIGHT: f32 = 4.4;

/// The image-based part of the showcase.
#[derive(Debug)]
pub struct IbrLayer {
    /// Per tree kind, its views and the sprites drawn from them this frame.
    forest: Vec<TreeSprites>,
    /// Every tree's billboard, per forest batch; each frame the batches get those not
    /// drawn as meshes ([`near`]).
    billboards: Vec<Vec<Billboard>>,
    /// The trees drawn as meshes in the last frame (indices into the forest's geometry).
    near: Vec<usize>,
    /// The squared distances of the frame's sprites, both kinds (scratch, reused).
    distances: Vec<f32>,
    /// The tree meshes the forest's sprites were baked from, where its billboards stand
    /// (what the forest is measured against, never drawn in the tour).
    trees: ForestGeometry,
    lasers: LaserBatch,
    effects: Effects,
    flare: Flare,
    /// The clouds, drawn through runtime impostors, and the city, through a planner
    /// choosing among geometry, impostors and image layers.
    pub impostors: Impostors,
    /// The statue on the plaza, drawn from its light field.
    pub statue: Statue,
    /// Emitter positions of turret A (beam source) and turret B (bolt source).
    pub turrets: [Vec3; 2],
    t: f32,
    dt: f32,
    bolts_fired: u32,
    /// The frame loop's memory, reused frame to frame.
    frame: FrameLoop,
    /// The last frame's image passes' work, per technique of the frame's list.
    passes: [FrameStats; 6],
}

impl IbrLayer {
    /// Builds the layer for `scene` on `terrain`: bakes the tree sprites under the scene's
    /// lighting, places the forest, and adds the turret meshes to the scene.
    pub fn new(scene: &mut Scene, terrain: &Terrain) -> Self {
        let turrets = [Vec3::new(-9.0, 0.0, 7.5), Vec3::new(9.5, 0.0, -8.5)].map(|p| {
            let base = Vec3::new(p.x, terrain.height_at(p.x, p.z), p.z);
            add_turret(scene, base);
            base + Vec3::Y * TURRET_HEIGHT
        });
        let sun = scene.lighting.sun().map_or(Vec3::Y, |(d, _)| -d);
        let (forest, trees) = forest(scene, terrain);
        let billboards = forest.iter().map(|b| b.items.clone()).collect();
        let mut layer = IbrLayer {
            forest,
            billboards,
            near: Vec::new(),
            distances: Vec::new(),
            trees,
            lasers: LaserBatch::new(),
            effects: Effects::new(77),
            flare: Flare {
                lens: LensFlare::default(),
                source: FlareSource::Directional(sun),
            },
            impostors: Impostors::new(terrain, &scene.lighting),
            statue: Statue::new(&scene.lighting),
            turrets,
            t: 0.0,
            dt: 0.0,
            bolts_fired: 0,
            frame: FrameLoop::new(),
            passes: Default::default(),
        };
        layer
            .effects
            .add_smoke(turrets[0] + Vec3::new(0.3, -0.6, 0.0));
        layer
            .effects
            .add_sparks(turrets[1] + Vec3::new(0.0, 0.2, 0.0));
        layer.pose(0.0);
        layer
    }

    /// The number of billboard trees.
    pub fn tree_count(&self) -> usize {
        self.billboards.iter().map(Vec::len).sum()
    }

    /// Where the billboard trees stand (their feet on the ground).
    pub fn tree_positions(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.trees.trees.iter().map(|(_, at)| at.w_axis.truncate())
    }

    /// The forest's sprites and the triangles of their outlines in the last frame.
    pub fn forest_work(&self) -> (usize, usize) {
        let sprites = self.forest.iter().map(|f| f.items.len()).sum();
        let meshes = self.forest.iter().flat_map(|f| &f.meshes);
        let triangles = meshes.map(|m| m.indices.len() / 3).sum();
        (sprites, triangles)
    }

    /// Every tree's billboard, per kind (those drawn as meshes too).
    pub fn forest_billboards(&self) -> &[Vec<Billboard>] {
        &self.billboards
    }

    /// Appends the forest's billboards alone, as the last frame prepared them.
    pub fn forest_sprites<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        forest_draws(&self.forest, out);
    }

    /// Appends the meshes of the trees the last frame drew as meshes (the near ones).
    pub fn forest_near<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        out.extend(self.near.iter().map(|&i| self.trees.draw(i)));
    }

    /// Appends the forest as geometry: each tree's mesh (the one its sprite was baked
    /// from, as it stands, unturned) at its billboard's place and height, tinted as its
    /// billboard, the trees outside `camera`'s view left out, and with `sprites_only` the
    /// trees the last frame drew as meshes.
    pub fn forest_geometry<'a>(
        &'a self,
        camera: &Camera,
        sprites_only: bool,
        out: &mut Vec<Draw<'a>>,
    ) {
        let frustum = Frustum::new(camera.clip_from_world());
        let t = &self.trees;
        for (i, &(kind, at)) in t.trees.iter().enumerate() {
            if sprites_only && self.near.contains(&i) {
                continue;
            }
            let b = t.bounds[kind];
            if frustum.sees(at.transform_point3(b.center), b.radius * at.x_axis.length()) {
                out.push(t.draw(i));
            }
        }
    }

    /// Moves to time `t` seconds: lasers pulse, bolts fly, arriving bolts explode. Time
    /// going backwards (a restarted path) only re-poses the lasers.
    pub fn pose(&mut self, t: f32) {
        let dt = t - self.t;
        self.dt = if dt.is_finite() && dt > 0.0 { dt } else { 0.0 };
        self.t = t;
        let [a, b] = self.turrets;
        let mut lasers = std::mem::take(&mut self.lasers.lasers);
        lasers.clear();
        // Turret A's continuous beam, pulsing.
        lasers.push(Laser {
            a,
            b: b - (b - a).normalize() * 0.6,
            width: 0.35,
            color: Rgba::new(1.0, 0.25, 0.15, 1.0),
            intensity: 1.2 + 0.4 * (t * 9.0).sin(),
        });
        // Turret B's bolts in flight; each explodes on arrival.
        let flight = a.distance(b) / BOLT_SPEED;
        let dir = (a - b).normalize();
        let fired = (t / BOLT_PERIOD).floor().max(0.0) as u32 + 1;
        for k in fired.saturating_sub(3)..fired {
            let age = t - k as f32 * BOLT_PERIOD;
            if (0.0..flight).contains(&age) {
                let head = b + dir * (age * BOLT_SPEED);
                lasers.push(Laser {
                    a: head - dir * BOLT_LENGTH.min(age * BOLT_SPEED),
                    b: head,
                    width: 0.25,
                    color: Rgba::new(0.2, 1.0, 0.35, 1.0),
                    intensity: 2.0,
                });
            }
            if age >= flight && k >= self.bolts_fired && self.dt > 0.0 {
                self.effects.spawn_explosion(a - dir * 0.8);
                self.bolts_fired = k + 1;
            }
        }
        self.lasers.lasers = lasers;
    }

    /// Renders `scene` with the layer: updates the impostors (refreshing the worst within
    /// their budgets), then the opaque and blended passes with the billboards, lasers,
    /// effects, clouds, buildings and the light-field statue, then the lens flare over the
    /// result.
    pub fn render(
        &mut self,
        scene: &Scene,
        renderer: &mut Renderer,
        camera: &Camera,
        target: &mut Target,
        opts: &FrameOptions,
    ) -> FrameStats {
        let view = FrameView {
            camera,
            width: target.width(),
            height: target.height(),
            lighting: &scene.lighting,
            time: self.t,
            dt: self.dt,
        };
        let eye = camera.eye();
        let frustum = Frustum::new(camera.clip_from_world());
        self.near.clear();
        let mut first = 0;
        for (batch, all) in self.forest.iter_mut().zip(&self.billboards) {
            batch.items.clear();
            for (i, b) in all.iter().enumerate() {
                if near(b, eye) {
                    self.near.push(first + i);
                } else if let ibr::billboard::Size::World(size) = b.size {
                    // Sprites out of the view make no triangles (the quad's corner
                    // distance bounds its relief's vertices).
                    if frustum.sees(b.position, batch.atlas.reach(size)) {
                        // The view baked nearest the eye's direction from the crown's
                        // upper part (AIM).
                        let aim = b.position + Vec3::Y * (AIM * batch.pivot * 0.5 * size.y);
                        batch.items.push(Billboard {
                            region: batch.atlas.region(eye - aim),
                            ..*b
                        });
                    }
                }
            }
            ViewAtlas::order(&mut batch.items, eye);
            first += all.len();
        }
        bands(&mut self.forest, eye, &mut self.distances);
        let trees = &self.trees;
        let near_trees = self.near.iter().map(|&i| trees.draw(i));
        // Blended impostors, clouds and smoke write no depth: the flare captures them once
        // more around the sun to see how much light they let through.
        let mut forest = Forest(&mut self.forest);
        let mut metered = [
            Metered::new(&mut forest),
            Metered::new(&mut self.lasers),
            Metered::new(&mut self.effects),
            Metered::new(&mut self.impostors),
            Metered::new(&mut self.statue.object),
            Metered::new(&mut self.flare),
        ];
        let mut techniques = metered.each_mut().map(|m| m as &mut dyn Technique);
        let stats = self.frame.render(
            renderer,
            scene.draws().chain(near_trees),
            &mut techniques,
            &view,
            target,
            opts,
        );
        self.passes = metered.map(|m| m.passes.get());
        stats
    }

    /// Each technique's work in the last frame: forest, lasers, effects, impostors, the
    /// light-field statue, flare.
    pub fn counters(&self) -> &[Counters] {
        &self.frame.counters
    }

    /// The frame loop, for where the last frame's time went ([`FrameLoop::times`],
    /// [`FrameLoop::prepares`] in the order of [`IbrLayer::counters`]).
    pub fn frame_loop(&self) -> &FrameLoop {
        &self.frame
    }

    /// The flare's displayed visibility (0 hidden .. 1 in full view).
    pub fn flare_visibility(&self) -> f32 {
        self.flare.lens.visibility()
    }

    /// The lens flare as of the last frame.
    pub fn flare(&self) -> &LensFlare {
        &self.flare.lens
    }

    /// The light the flare follows.
    pub fn sun(&self) -> FlareSource {
        self.flare.source
    }
}

/// One tree kind's billboards: its views, the sprites shown this frame (set in
/// [`IbrLayer::render`], near to far), where each of the frame's [`bands`] ends among them,
/// and the mesh each band makes, each sprite its view's outline with per-texel depth
/// ([`ViewAtlas::nailboards`]) so sprites and meshes hide one another where the trees'
/// surfaces do.
#[derive(Debug)]
struct TreeSprites {
    /// Where the view is chosen from ([`CROWN_PIVOT`], [`PINE_PIVOT`]), in the atlas's
    /// radii above the sprite's centre.
    pivot: f32,
    atlas: ViewAtlas,
    material: Material,
    items: Vec<Billboard>,
    ends: Vec<usize>,
    meshes: Vec<Mesh>,
}

impl TreeSprites {
    /// This kind's sprites as their bands' meshes (a nailboard's outline, 8 triangles,
    /// whatever its size on screen: the grid of nodes that small sprites took every 2nd
    /// column of is not drawn).
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.meshes.resize_with(self.ends.len(), Mesh::default);
        let seen = view.billboard_view();
        let mut start = 0;
        for (mesh, &end) in self.meshes.iter_mut().zip(&self.ends) {
            self.atlas.relief(&self.items[start..end], &seen, mesh);
            start = end;
        }
    }
}

/// The impostored clouds and the planned city as one technique (one update of both per
/// frame).
impl Technique for Impostors {
    fn name(&self) -> &str {
        "impostors"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.update(view);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        Impostors::draws(self, out);
    }
    fn counters(&self) -> Counters {
        let r = self.readout();
        Counters {
            quads: r.images() as u64,
            images: r.images() as u64,
            refreshes: r.refreshes() as u64,
            geometry: r.geometry() as u64,
            ..Counters::default()
        }
    }
}

/// A turret: a dark pylon with a glowing head.
fn add_turret(scene: &mut Scene, base: Vec3) {
    let mut pylon = procedural::cylinder(0.35, TURRET_HEIGHT - 0.3, 12);
    pylon.colors.clear();
    scene.add(
        pylon,
        Material::lit(Rgba::from_srgb8(70, 74, 84)),
        Mat4::from_translation(base),
    );
    let mut head = procedural::uv_sphere(0.45, 10, 20);
    head.colors.clear();
    scene.add(
        head,
        Material::lit(Rgba::from_srgb8(150, 156, 170)),
        Mat4::from_translation(base + Vec3::Y * TURRET_HEIGHT),
    );
}

/// The forest as geometry: per kind the tree mesh (and its bounds), per tree its kind and
/// placement, and its material (the billboard's tint as base colour).
#[derive(Debug, Default)]
struct ForestGeometry {
    meshes: Vec<Mesh>,
    bounds: Vec<engine::Sphere>,
    trees: Vec<(usize, Mat4)>,
    materials: Vec<Material>,
}

impl ForestGeometry {
    /// Tree `i` as geometry.
    fn draw(&self, i: usize) -> Draw<'_> {
        let (kind, at) = self.trees[i];
        Draw {
            mesh: &self.meshes[kind],
            material: &self.materials[i],
            transform: at,
        }
    }
}

/// Whether the tree of billboard `b` (world-sized, facing the eye through its centre) is
/// drawn as its mesh from `eye`: nearer than [`NEAR_SIZES`] of its quad's side.
pub fn near(b: &Billboard, eye: Vec3) -> bool {
    let ibr::billboard::Size::World(size) = b.size else {
        return false;
    };
    b.position.distance(eye) < NEAR_SIZES * size.y
}

/// The billboard forest: a pine and a broadleaf tree, turned about the vertical
/// ([`lathe::tree`]: alike from every side, the subject billboards suit), each baked from
/// [`SPRITE_AZIMUTHS`] x [`SPRITE_ELEVATIONS`] directions under the scene's lighting
/// ([`ViewAtlas`]), drawn on quads facing the eye through each tree's centre, showing the
/// view baked nearest the eye's direction (set each frame in [`IbrLayer::render`]);
/// as cutouts near to far ([`ViewAtlas::material`], [`ViewAtlas::order`]: alpha-tested
/// with depth writes in the opaque pass, so a sprite hidden behind nearer ones or the hills
/// is never shaded; they hide the sun's flare and take the soft smoke's fade), placed on the
/// hills outside the city district.
/// Also returns the trees' geometry ([`ForestGeometry`]).
fn forest(scene: &Scene, terrain: &Terrain) -> (Vec<TreeSprites>, ForestGeometry) {
    let mut rng = XorShift::new(4242);
    let mut batches = Vec::new();
    let mut trees = ForestGeometry::default();
    let elevations = SPRITE_ELEVATIONS.map(f32::to_radians);
    for (kind, seed, pivot) in [
        (TreeKind::Pine, 1, PINE_PIVOT),
        (TreeKind::Broadleaf, 3, CROWN_PIVOT),
    ] {
        let mesh = lathe::tree(kind, seed);
        let bounds = mesh.bounding_sphere();
        let white = foliage(Rgba::WHITE);
        let lighting = bake_lighting(&scene.lighting);
        let draw = Draw {
            mesh: &mesh,
            material: &white,
            transform: Mat4::IDENTITY,
        };
        let atlas = ViewAtlas::bake_turned(
            &[draw],
            &lighting,
            bounds,
            SPRITE_AZIMUTHS,
            &elevations,
            SPRITE_PX,
        );
        let mut atlas = atlas;
        // Each sprite one flat outline whose fragments take their texel's own depth
        // (`ViewAtlas::nailboards`), not a 5 x 5 grid of moved nodes: crowns overlapping
        // crowns are ordered per texel. 640 x 360 tour, 120 frames: forest PSNR mean / worst
        // 27.34 / 24.32 dB as reliefs, 28.66 / 24.55 as nailboards; 1280 x 720: 27.57 /
        // 24.30, 29.22 / 24.9992; 8 triangles a sprite where a relief drew 16 or 32, and
        // the tour's frame no slower (BENCHMARKS.md, issue 39, session 29).
        atlas.nailboard = true;
        atlas.parallax = Some(PARALLAX_TOLERANCE);
        atlas.max_lod = SPRITE_MAX_LOD;
        let height = mesh_height(&mesh);
        let k = trees.meshes.len();
        trees.bounds.push(bounds);
        trees.meshes.push(mesh);
        let mut batch = TreeSprites {
            pivot: pivot / atlas.bounds.radius,
            material: atlas.material().double_sided(true),
            atlas,
            items: Vec::new(),
            ends: Vec::new(),
            meshes: Vec::new(),
        };
        let atlas = &batch.atlas;
        while batch.items.len() < FOREST_TREES / 2 {
            let a = rng.range(0.0, std::f32::consts::TAU);
            let r = rng.range(27.0, 58.0);
            let (x, z) = (r * a.cos(), r * a.sin());
            let h = rng.range(3.5, 7.5);
            if impostors::in_city(x, z, 2.0) {
                continue;
            }
            let shade = rng.range(0.85, 1.1);
            let foot = Vec3::new(x, terrain.height_at(x, z) - 0.1, z);
            // The mesh scaled to `h` tall with its origin at the foot; the quad through
            // its sphere's centre, as wide as the baked square.
            let s = h / height;
            let at = Mat4::from_translation(foot) * Mat4::from_scale(Vec3::splat(s));
            trees.trees.push((k, at));
            trees
                .materials
                .push(foliage(Rgba::new(shade, shade, shade, 1.0)));
            batch.items.push(Billboard {
                tint: Rgba::new(shade, shade, shade, 1.0),
                region: atlas.region(Vec3::X),
                ..Billboard::new(
                    at.transform_point3(atlas.bounds.center),
                    Facing::World { up: Vec3::Y },
                    Vec2::splat(2.0 * atlas.bounds.radius * s),
                )
            });
        }
        batches.push(batch);
    }
    (batches, trees)
}

/// The trees' material, as the meshes and their bakes share it: lit, `color` the base,
/// matte (no highlight). A view baked from one direction carries the light that left the
/// tree toward that direction; a highlight moves with the eye, so the sprite showed the
/// bake's highlight where the mesh showed the eye's, up to half a view's spacing away
/// (specular 0.25, shininess 32, as `Material::lit`: 1.8 dB of the forest's 21.8 mean
/// at 640 x 360). Leaves scatter light: a matte crown is also the plainer tree.
pub fn foliage(color: Rgba) -> Material {
    Material {
        shading: Shading::Lit {
            specular: 0.0,
            shininess: 32.0,
        },
        ..Material::lit(color)
    }
}

/// The scene's lighting as it reaches the forest, to bake the tree views under: the
/// ambient and the directional lights. A point light shines by where it stands, and the
/// bake puts the tree at its mesh's origin, not at any tree's place: the showcase's lamp
/// orbits within 3.2 of the origin (its range 7), so baking with it lit every view orange
/// on one side, a light no tree of the forest (27 units out or more) receives
/// (`no_point_light_reaches_the_forest`). Were one to reach the forest, the trees it lit
/// could not be drawn from views baked once.
pub fn bake_lighting(lighting: &Lighting) -> Lighting {
    Lighting {
        ambient: lighting.ambient,
        lights: lighting
            .lights
            .iter()
            .filter(|l| matches!(l, Light::Directional { .. }))
            .cloned()
            .collect(),
    }
}

/// The height of `mesh`'s finite vertices (at least 1e-3).
fn mesh_height(mesh: &Mesh) -> f32 {
    let ys = mesh.positions.iter().filter(|p| p.is_finite()).map(|p| p.y);
    let (lo, hi) = ys.fold((f32::MAX, f32::MIN), |(l, h), y| (l.min(y), h.max(y)));
    (hi - lo).max(1e-3)
}

mod bands;
mod costs;
mod lathe;
#[cfg(test)]
mod tests;
