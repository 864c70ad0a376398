//! The `trees_nailboard` series' forest: the sweep's trees drawn as the showcase draws its
//! forest, as [`ViewAtlas`] nailboards with the parallax search, with its settings. Each
//! kind is baked once from [`SPRITE_AZIMUTHS`] directions over the half turn from the sun
//! (the other half mirrored) at each of [`SPRITE_ELEVATIONS`]; every tree is one flat
//! outline (8 triangles) showing the view baked nearest the eye's direction, its fragments
//! at the depth of the texel whose surface lies on their ray
//! ([`engine::DepthOffset::parallax`]). Each frame (the series' `build`) chooses every
//! tree's view, puts the trees near to far and writes each kind's outlines into one mesh.
//!
//! The views are chosen in the world's frame, as if every tree stood unturned (as the
//! `trees_billboard` series shows one baked side): the mesh forest turns its trees about
//! the vertical, and a tree's bake carries the sun's light from its own side, so a view
//! chosen in a turned tree's frame would show the light from the wrong side. The
//! procedural trees are alike from every side but for their jitter.

use crate::showcase::ibr_layer::{
    PARALLAX_TOLERANCE, SPRITE_AZIMUTHS, SPRITE_ELEVATIONS, SPRITE_MAX_LOD,
};
use engine::{Draw, Lighting, Material, Mesh};
use glam::{Mat4, Vec2, Vec3};
use ibr::billboard::ViewAtlas;
use ibr::technique::{Counters, FrameView, Technique};
use ibr::{Billboard, Facing};
use rayon::prelude::*;

/// One tree kind: its views, its trees (views not yet chosen), this frame's sprites and
/// their mesh.
struct Kind {
    atlas: ViewAtlas,
    material: Material,
    trees: Vec<Billboard>,
    items: Vec<Billboard>,
    mesh: Mesh,
}

/// The forest as nailboards, one technique of the frame loop.
pub(super) struct NailboardForest {
    kinds: Vec<Kind>,
}

impl NailboardForest {
    /// `meshes` (standing on their origin, drawn with `material` under `lighting`) baked
    /// `px` texels a view; no trees yet ([`NailboardForest::plant`]).
    pub(super) fn new(
        meshes: &[Mesh],
        material: &Material,
        lighting: &Lighting,
        px: u32,
    ) -> NailboardForest {
        let elevations = SPRITE_ELEVATIONS.map(f32::to_radians);
        let kinds = meshes
            .iter()
            .map(|mesh| {
                let bounds = mesh.bounding_sphere();
                let draw = Draw {
                    mesh,
                    material,
                    transform: Mat4::IDENTITY,
                };
                let mut atlas = ViewAtlas::bake_turned(
                    &[draw],
                    lighting,
                    bounds,
                    SPRITE_AZIMUTHS,
                    &elevations,
                    px,
                );
                atlas.nailboard = true;
                atlas.parallax = Some(PARALLAX_TOLERANCE);
                atlas.max_lod = SPRITE_MAX_LOD;
                Kind {
                    material: atlas.material().double_sided(true),
                    atlas,
                    trees: Vec::new(),
                    items: Vec::new(),
                    mesh: Mesh::default(),
                }
            })
            .collect();
        NailboardForest { kinds }
    }

    /// Replaces the trees by `trees` (position of the foot, kind, scale of the mesh).
    pub(super) fn plant(&mut self, trees: &[(Vec3, usize, f32)]) {
        for (k, kind) in self.kinds.iter_mut().enumerate() {
            let bounds = kind.atlas.bounds;
            kind.trees.clear();
            kind.trees
                .extend(trees.iter().filter(|t| t.1 == k).map(|&(p, _, s)| {
                    Billboard::new(
                        p + bounds.center * s,
                        Facing::World { up: Vec3::Y },
                        Vec2::splat(2.0 * bounds.radius * s),
                    )
                }));
        }
    }

    /// Triangles of the last frame's outlines.
    pub(super) fn triangles(&self) -> u64 {
        let n = |k: &Kind| k.mesh.triangle_count() as u64;
        self.kinds.iter().map(n).sum()
    }
}

impl Technique for NailboardForest {
    fn name(&self) -> &str {
        "billboards"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        let eye = view.camera.eye();
        let seen = view.billboard_view();
        // Each kind's views, order and outlines on its own (the kinds share nothing).
        self.kinds.par_iter_mut().for_each(|k| {
            k.items.clear();
            let atlas = &k.atlas;
            k.items.extend(k.trees.iter().map(|b| Billboard {
                region: atlas.region(eye - b.position),
                ..*b
            }));
            ViewAtlas::order(&mut k.items, eye);
            k.atlas.relief(&k.items, &seen, &mut k.mesh);
        });
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        out.extend(self.kinds.iter().map(|k| Draw {
            mesh: &k.mesh,
            material: &k.material,
            transform: Mat4::IDENTITY,
        }));
    }
    fn counters(&self) -> Counters {
        Counters {
            quads: self.kinds.iter().map(|k| k.items.len() as u64).sum(),
            ..Counters::default()
        }
    }
}
