//! The forest's sprites drawn in bands by distance from the eye: each tree kind is a mesh a
//! band, and the draws go band by band across the kinds, so the alpha-tested sprites of one
//! kind far off are not shaded before the other kind's near ones hide them (one mesh a kind
//! drew every pine before any broadleaf tree).

use super::TreeSprites;
use engine::Draw;
use glam::{Mat4, Vec3};
use ibr::technique::{Counters, FrameView, Technique};
use ibr::Billboard;

/// Bands a frame's sprites are split into, each about an equal share of the sprites of both
/// kinds (640 x 360 tour, session 18: the forest's fragments shaded a frame 102,099 in one
/// band a kind, 96,978 in 4, 95,885 in 8, 94,788 in 16; the same pixels).
pub(super) const FOREST_BANDS: usize = 8;

/// The forest's tree kinds as one technique, drawn band by band ([`forest_draws`]).
pub(super) struct Forest<'f>(pub(super) &'f mut [TreeSprites]);

impl Technique for Forest<'_> {
    fn name(&self) -> &str {
        "billboards"
    }
    fn prepare(&mut self, view: &FrameView<'_>) {
        self.0.iter_mut().for_each(|k| k.prepare(view));
    }
    fn draws<'a>(&'a self, out: &mut Vec<Draw<'a>>) {
        forest_draws(self.0, out);
    }
    fn counters(&self) -> Counters {
        Counters {
            quads: self.0.iter().map(|k| k.items.len() as u64).sum(),
            ..Counters::default()
        }
    }
}

/// Sets where each of [`FOREST_BANDS`] bands ends among each kind's sprites (near to far
/// from `eye`): the same distances bound band `b` in every kind ([`split`]).
/// `distances` is scratch, reused frame to frame.
pub(super) fn bands(kinds: &mut [TreeSprites], eye: Vec3, distances: &mut Vec<f32>) {
    distances.clear();
    for k in kinds.iter() {
        distances.extend(k.items.iter().map(|b| b.position.distance_squared(eye)));
    }
    distances.sort_unstable_by(f32::total_cmp);
    for k in kinds.iter_mut() {
        split(&k.items, eye, distances, FOREST_BANDS, &mut k.ends);
    }
}

/// Writes into `ends` (cleared) where each of `n` bands ends in `items` (sorted near to far
/// from `eye`): band `b` holds the sprites nearer (squared distance) than `all`'s entry at
/// `(b + 1) / n` of its length (`all`: the squared distances of every kind's sprites,
/// sorted), the last every sprite left.
pub(super) fn split(items: &[Billboard], eye: Vec3, all: &[f32], n: usize, ends: &mut Vec<usize>) {
    ends.clear();
    for b in 1..n.max(1) {
        let edge = all.get(b * all.len() / n).copied().unwrap_or(f32::MAX);
        ends.push(items.partition_point(|s| s.position.distance_squared(eye) < edge));
    }
    ends.push(items.len());
}

/// The forest's draws, band by band near to far and within a band kind by kind (empty
/// bands left out): the renderer keeps this order among draws at the same depth (a band's
/// box reaching behind the eye sorts at depth 0), so a far band of one kind is not shaded
/// before a near band of the other hides it.
pub(super) fn forest_draws<'a>(kinds: &'a [TreeSprites], out: &mut Vec<Draw<'a>>) {
    let n = kinds.iter().map(|k| k.meshes.len()).max().unwrap_or(0);
    for b in 0..n {
        for k in kinds {
            if let Some(mesh) = k.meshes.get(b).filter(|m| !m.indices.is_empty()) {
                out.push(Draw {
                    mesh,
                    material: &k.material,
                    transform: Mat4::IDENTITY,
                });
            }
        }
    }
}
