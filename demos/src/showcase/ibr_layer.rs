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
use engine::procedural::{self, Terrain, TreeKind, XorShift};
use engine::{
    AlphaMode, Camera, Draw, FrameOptions, FrameStats, Material, Mesh, Renderer, Rgba, Scene,
    Target,
};
use glam::{Mat4, Vec2, Vec3};
use ibr::effects::Effects;
use ibr::flare::{FlareSource, LensFlare};
use ibr::impostor::Frustum;
use ibr::laser::{Laser, LaserBatch};
use ibr::sprites::{self, BakedSprite};
use ibr::technique::{Counters, Flare, FrameLoop, FrameView, Technique};
use ibr::{AxialFallback, Billboard, BillboardBatch, Facing};

/// Billboard trees in the forest ring.
pub const FOREST_TREES: usize = 2400;
/// Height of the trees' baked side view, texels: a tree stays at or under a texel per
/// screen pixel until it is this many pixels tall (at 1280 x 720 and the showcase's
/// field of view, nearer than about 1.2 of its heights, which the tour never comes).
pub const SPRITE_PX: u32 = 512;
/// Elevations (degrees) over which an upright tree hands over to its top-down sprite: it
/// is gone before it is seen squashed (the default 55 to 75 showed trees lying on their
/// sides), in a narrow band so the two are seen together briefly.
pub const FADE_DEGREES: [f32; 2] = [30.0, 42.0];
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
    forest: Vec<BillboardBatch>,
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
        let mut layer = IbrLayer {
            forest,
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
        self.forest.iter().map(|b| b.items.len()).sum()
    }

    /// Where the billboard trees stand.
    pub fn tree_positions(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.forest
            .iter()
            .flat_map(|b| b.items.iter().map(|t| t.position))
    }

    /// Appends the forest's billboard draws as the last frame prepared them.
    pub fn forest_draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.forest.draws(out);
    }

    /// Appends the forest as geometry: each tree's mesh (the one its sprite was baked
    /// from, as it stands, unturned) at its billboard's place and height, tinted as its
    /// billboard, the trees outside `camera`'s view left out.
    pub fn forest_geometry<'a>(&'a self, camera: &Camera, out: &mut Vec<Draw<'a>>) {
        let frustum = Frustum::new(camera.clip_from_world());
        let t = &self.trees;
        for (i, &(kind, at)) in t.trees.iter().enumerate() {
            let b = t.bounds[kind];
            if frustum.sees(at.transform_point3(b.center), b.radius * at.x_axis.length()) {
                out.push(Draw {
                    mesh: &t.meshes[kind],
                    material: &t.materials[i],
                    transform: at,
                });
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
        // Blended impostors, clouds and smoke write no depth: the flare captures them once
        // more around the sun to see how much light they let through.
        let mut techniques: [&mut dyn Technique; 6] = [
            &mut self.forest,
            &mut self.lasers,
            &mut self.effects,
            &mut self.impostors,
            &mut self.statue.object,
            &mut self.flare,
        ];
        self.frame.render(
            renderer,
            scene.draws(),
            &mut techniques,
            &view,
            target,
            opts,
        )
    }

    /// Each technique's work in the last frame: forest, lasers, effects, impostors, the
    /// light-field statue, flare.
    pub fn counters(&self) -> &[Counters] {
        &self.frame.counters
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

/// A sphere holding `mesh`'s (finite) vertices: about their bounding box's centre.
fn sphere_around(mesh: &Mesh) -> engine::Sphere {
    let finite = || mesh.positions.iter().filter(|p| p.is_finite());
    let (lo, hi) = finite().fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    let center = (lo + hi) * 0.5;
    let radius = finite().map(|p| p.distance(center)).fold(0.0, f32::max);
    engine::Sphere { center, radius }
}

/// The billboard forest: sprites baked from a pine and a broadleaf tree (side view plus a
/// top view for the over-the-top fallback), alpha-blended back to front (their soft edges
/// and the hand-over to the top view fade smoothly, with no screen-door pattern) and
/// writing depth where they are at least half opaque (they hide the sun's flare and take
/// the soft smoke's fade), placed on the hills outside the city district.
/// Also returns the trees' geometry ([`ForestGeometry`]).
fn forest(scene: &Scene, terrain: &Terrain) -> (Vec<BillboardBatch>, ForestGeometry) {
    let bake = |mesh: &Mesh| -> BakedSprite {
        let material = Material::lit(Rgba::WHITE);
        sprites::bake_upright(
            mesh,
            &material,
            &scene.lighting,
            Vec3::new(1.0, 0.0, 0.6),
            SPRITE_PX,
        )
    };
    let mut rng = XorShift::new(4242);
    let mut batches = Vec::new();
    let mut trees = ForestGeometry::default();
    for (kind, seed) in [(TreeKind::Pine, 1), (TreeKind::Broadleaf, 3)] {
        let mesh: Mesh = procedural::tree(kind, 1.0, seed);
        let sprite = bake(&mesh);
        let k = trees.meshes.len();
        trees.bounds.push(sphere_around(&mesh));
        trees.meshes.push(mesh);
        let material = Material {
            alpha_mode: AlphaMode::Blend,
            blend_depth: Some(0.5),
            vertex_colors: true,
            ..Material::unlit(Rgba::WHITE).with_texture(sprite.texture.clone())
        };
        let facing = Facing::Axial {
            axis: Vec3::Y,
            fallback: AxialFallback {
                fade_start: FADE_DEGREES[0],
                fade_end: FADE_DEGREES[1],
                top: Some(sprite.top),
            },
        };
        let mut batch = BillboardBatch::new(material);
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
            // The sprite's quad is `sprite.size` scaled to `h` tall, the mesh's origin at
            // its pivot: the mesh scaled alike with its origin at the foot.
            let scale = Mat4::from_scale(Vec3::splat(h / sprite.size.y));
            trees.trees.push((k, Mat4::from_translation(foot) * scale));
            trees
                .materials
                .push(Material::lit(Rgba::new(shade, shade, shade, 1.0)));
            batch.push(Billboard {
                pivot: sprite.pivot,
                tint: Rgba::new(shade, shade, shade, 1.0),
                region: sprite.side,
                ..Billboard::new(
                    foot,
                    facing,
                    Vec2::new(sprite.size.x / sprite.size.y, 1.0) * h,
                )
            });
        }
        batches.push(batch);
    }
    (batches, trees)
}

#[cfg(test)]
mod tests;
