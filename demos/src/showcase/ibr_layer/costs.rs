//! Where a tour frame goes by draw (`showcase --headless --draw-costs`): each draw of the
//! main pass labelled with its group (forest sprites and meshes, terrain, city geometry and
//! impostors, statue, clouds, effects, other), the engine's per-draw costs
//! ([`Renderer::draw_costs`]) summed per group, and the image passes' work (the statue's
//! light-field composite, the flare's sprites) added to their technique's group, so the
//! groups' fragments sum to the frame's [`FrameStats`].

use super::IbrLayer;
use engine::{AlphaMode, Draw, DrawCost, FrameStats, Material, Scene, Target};
use ibr::technique::{Counters, FrameView, Observed, Technique};
use std::cell::Cell;

/// The groups of a tour frame's draws, the columns' prefixes of `DIR/tour_draws.csv`.
pub const GROUPS: [&str; 9] = [
    "forest_sprites",
    "forest_meshes",
    "terrain",
    "city_geometry",
    "city_impostors",
    "statue",
    "clouds",
    "effects",
    "other",
];
const FOREST_SPRITES: usize = 0;
const FOREST_MESHES: usize = 1;
const TERRAIN: usize = 2;
const CITY_GEOMETRY: usize = 3;
const CITY_IMPOSTORS: usize = 4;
const STATUE: usize = 5;
const CLOUDS: usize = 6;
/// Lasers, explosions and smoke, and the lens flare.
const EFFECTS: usize = 7;
/// The scene's own objects: plaza, props, house, its trees and rocks, turrets.
const OTHER: usize = 8;

/// The group of each technique of [`IbrLayer::render`]'s list (forest, lasers, effects,
/// impostors, statue, flare), for its image passes' work.
const PASS_GROUPS: [usize; 6] = [
    FOREST_SPRITES,
    EFFECTS,
    EFFECTS,
    CITY_IMPOSTORS,
    STATUE,
    EFFECTS,
];

/// One group's cost in a frame: integer counts (the same at any thread count) and the
/// raster and shade time of its draws summed over the workers (image passes untimed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GroupCost {
    /// Draws submitted (culled ones included).
    pub draws: u64,
    pub fragments_tested: u64,
    pub fragments_shaded: u64,
    /// Of the shaded fragments, those of blended draws (and blended image passes).
    pub fragments_blended: u64,
    pub rows_shaded: u64,
    pub ns: u64,
}

/// The last frame's cost per group of [`GROUPS`], and the labels' scratch memory.
#[derive(Debug, Default)]
pub struct DrawGroups {
    /// Per group, in [`GROUPS`] order.
    pub groups: [GroupCost; GROUPS.len()],
    /// Why the last frame's draws could not be grouped (its groups then all zero).
    pub error: Option<String>,
    /// Per group, its sums over the frames grouped since counting started.
    pub run: [GroupCost; GROUPS.len()],
    /// Frames summed in `run`.
    pub frames: u64,
    labels: Vec<usize>,
    blended: Vec<bool>,
    city_materials: Vec<usize>,
}

impl DrawGroups {
    /// The header of `DIR/tour_draws.csv`: the frame, then per group its draws, fragments
    /// tested, shaded and blended, rows shaded and raster nanoseconds.
    pub fn csv_header() -> String {
        let mut s = String::from("frame");
        for g in GROUPS {
            for c in ["draws", "tested", "shaded", "blended", "rows", "ns"] {
                s.push_str(&format!(",{g}_{c}"));
            }
        }
        s.push('\n');
        s
    }

    /// Frame `i`'s row of [`DrawGroups::csv_header`].
    pub fn csv_row(&self, i: usize) -> String {
        let mut s = i.to_string();
        for g in &self.groups {
            let cols = [
                g.draws,
                g.fragments_tested,
                g.fragments_shaded,
                g.fragments_blended,
                g.rows_shaded,
                g.ns,
            ];
            for c in cols {
                s.push_str(&format!(",{c}"));
            }
        }
        s.push('\n');
        s
    }

    /// The last frame's groups summed.
    pub fn total(&self) -> GroupCost {
        let mut t = GroupCost::default();
        self.groups.iter().for_each(|g| t += *g);
        t
    }

    /// The run's mean frame, a line per group: draws, fragments tested, shaded and
    /// blended, rows, the group's share of the summed raster time and its nanoseconds per
    /// fragment shaded.
    pub fn lines(&self) -> Vec<String> {
        let n = self.frames.max(1) as f64;
        let ns: u64 = self.run.iter().map(|g| g.ns).sum();
        let mut out = vec![format!(
            "{:<15} {:>6} {:>9} {:>9} {:>9} {:>8} {:>6} {:>6}",
            "group", "draws", "tested", "shaded", "blended", "rows", "time%", "ns/fr"
        )];
        for (name, g) in GROUPS.iter().zip(&self.run) {
            out.push(format!(
                "{name:<15} {:>6.1} {:>9.0} {:>9.0} {:>9.0} {:>8.0} {:>6.1} {:>6.1}",
                g.draws as f64 / n,
                g.fragments_tested as f64 / n,
                g.fragments_shaded as f64 / n,
                g.fragments_blended as f64 / n,
                g.rows_shaded as f64 / n,
                100.0 * g.ns as f64 / ns.max(1) as f64,
                g.ns as f64 / g.fragments_shaded.max(1) as f64
            ));
        }
        out
    }
}

impl std::ops::AddAssign for GroupCost {
    fn add_assign(&mut self, o: GroupCost) {
        self.draws += o.draws;
        self.fragments_tested += o.fragments_tested;
        self.fragments_shaded += o.fragments_shaded;
        self.fragments_blended += o.fragments_blended;
        self.rows_shaded += o.rows_shaded;
        self.ns += o.ns;
    }
}

impl IbrLayer {
    /// Sums the last frame's `costs` (the renderer's, one per draw of the main pass, in
    /// submission order) into `out`'s groups, the scene's instances `terrain` says are
    /// terrain in that group, and adds the image passes' work. An error if the draws
    /// labelled are not as many as `costs` (the frame's list was not rebuilt as rendered).
    pub fn draw_groups(
        &self,
        scene: &Scene,
        terrain: impl Fn(usize) -> bool,
        costs: &[DrawCost],
        out: &mut DrawGroups,
    ) -> Result<(), String> {
        let (labels, blended) = (&mut out.labels, &mut out.blended);
        labels.clear();
        blended.clear();
        let mut push = |group: usize, material: &Material| {
            labels.push(group);
            blended.push(material.alpha_mode == AlphaMode::Blend);
        };
        // As `IbrLayer::render` lists them: the scene's draws, the near trees' meshes,
        // then each technique's.
        for (k, i) in scene.instances.iter().enumerate() {
            if let (Some(_), Some(m)) = (scene.meshes.get(i.mesh), scene.materials.get(i.material))
            {
                push(if terrain(k) { TERRAIN } else { OTHER }, m);
            }
        }
        for &i in &self.near {
            push(FOREST_MESHES, self.trees.draw(i).material);
        }
        let mut draws: Vec<Draw<'_>> = Vec::new();
        super::forest_draws(&self.forest, &mut draws);
        draws.iter().for_each(|d| push(FOREST_SPRITES, d.material));
        for t in [
            &self.lasers as &dyn Technique,
            &self.effects as &dyn Technique,
        ] {
            draws.clear();
            t.draws(&mut draws);
            draws.iter().for_each(|d| push(EFFECTS, d.material));
        }
        let city = &self.impostors.city;
        let mats = &mut out.city_materials;
        mats.clear();
        let parts = city.objects.iter().flat_map(|o| &o.parts);
        mats.extend(parts.map(|p| std::sync::Arc::as_ptr(&p.material) as usize));
        mats.sort_unstable();
        draws.clear();
        city.draws(&mut draws);
        for d in &draws {
            let own = mats.binary_search(&(d.material as *const Material as usize));
            push(
                if own.is_ok() {
                    CITY_GEOMETRY
                } else {
                    CITY_IMPOSTORS
                },
                d.material,
            );
        }
        let imp = &self.impostors;
        draws.clear();
        imp.cloud_set.draws(&imp.clouds.clouds, &mut draws);
        draws.iter().for_each(|d| push(CLOUDS, d.material));
        let last: [(&dyn Technique, usize); 2] =
            [(&self.statue.object, STATUE), (&self.flare, EFFECTS)];
        for (t, group) in last {
            draws.clear();
            t.draws(&mut draws);
            draws.iter().for_each(|d| push(group, d.material));
        }
        out.groups = Default::default();
        if labels.len() != costs.len() {
            return Err(format!(
                "{} draws labelled, {} costed",
                labels.len(),
                costs.len()
            ));
        }
        for ((&g, &b), c) in out.labels.iter().zip(&out.blended).zip(costs) {
            let s = &mut out.groups[g];
            s.draws += 1;
            s.fragments_tested += c.fragments_tested;
            s.fragments_shaded += c.fragments_shaded;
            s.fragments_blended += if b { c.fragments_shaded } else { 0 };
            s.rows_shaded += c.rows_shaded;
            s.ns += c.raster.as_nanos() as u64;
        }
        for (p, &g) in self.passes.iter().zip(&PASS_GROUPS) {
            let s = &mut out.groups[g];
            s.fragments_tested += p.fragments_tested;
            s.fragments_shaded += p.fragments_shaded;
            s.fragments_blended += p.fragments_shaded_blended;
            s.rows_shaded += p.rows_shaded;
        }
        for (r, g) in out.run.iter_mut().zip(&out.groups) {
            *r += *g;
        }
        out.frames += 1;
        Ok(())
    }
}

/// A technique of the frame's list whose image passes' work (its `passes` and
/// `overlay_pass`) is kept; everything else is forwarded.
pub(super) struct Metered<'t> {
    pub(super) inner: &'t mut dyn Technique,
    pub(super) passes: Cell<FrameStats>,
}

impl<'t> Metered<'t> {
    pub(super) fn new(inner: &'t mut dyn Technique) -> Self {
        Metered {
            inner,
            passes: Cell::new(FrameStats::default()),
        }
    }

    fn add(&self, s: FrameStats) -> FrameStats {
        let mut sum = self.passes.get();
        sum += s;
        self.passes.set(sum);
        s
    }
}

impl Technique for Metered<'_> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.inner.prepare(view);
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.inner.draws(out);
    }
    fn passes(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        self.add(self.inner.passes(view, target))
    }
    fn observe(&self, seen: &mut Observed<'_, '_>) -> Option<f32> {
        self.inner.observe(seen)
    }
    fn resolve(&mut self, view: &FrameView<'_>, observed: Option<f32>) {
        self.inner.resolve(view, observed);
    }
    fn overlay<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.inner.overlay(out);
    }
    fn overlay_pass(&self, view: &FrameView<'_>, target: &mut Target) -> FrameStats {
        self.add(self.inner.overlay_pass(view, target))
    }
    fn counters(&self) -> Counters {
        self.inner.counters()
    }
    fn reference<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        self.inner.reference(out);
    }
}
