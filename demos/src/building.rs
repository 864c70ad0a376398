//! A procedural building for LDI portals: a closed hall (the near room, always geometry) whose
//! wall has three doorways, each opening into a furnished room whose triangle count is
//! chosen (from a few thousand to over a million), and a walkthrough along the hall and
//! through the middle door.
//!
//! Axes: the hall spans z in [0, 4] (the near side of the doorways), the rooms z in
//! [-6, 0]; y up; the doorways are 1.2 wide and 2.1 high, centred at x = -4, 0 and 4.

use engine::procedural::{self, XorShift};
use engine::{Light, Lighting, Material, Mesh, Rgba};
use glam::{Mat4, Vec3};
use ibr::portal::{Opening, Portal};
use ibr::subject::{MeshGroup, Part};
use std::sync::Arc;

/// Doorway centres along x.
pub const DOORS: [f32; 3] = [-4.0, 0.0, 4.0];
const DOOR_W: f32 = 1.2;
const DOOR_H: f32 = 2.1;
const HALL_DEPTH: f32 = 4.0;
const ROOM_DEPTH: f32 = 6.0;
const HEIGHT: f32 = 3.0;
const HALF_LENGTH: f32 = 6.5;

/// The hall, the rooms behind its doorways, and the light.
#[derive(Clone, Debug)]
pub struct Building {
    /// The hall: floor, ceiling, walls (the doorway wall with its openings) and its ends.
    pub hall: MeshGroup,
    /// Each doorway and the room behind it.
    pub rooms: Vec<(Opening, MeshGroup)>,
    pub lighting: Lighting,
}

/// A lit material for closed solids (boxes, rings): single-sided, as only their outside
/// can be seen, so their back faces are culled before they are set up and shaded.
fn lit(r: f32, g: f32, b: f32) -> Arc<Material> {
    Arc::new(Material::lit(Rgba::new(r, g, b, 1.0)))
}

/// A box of `size` whose bottom centre is at `at`.
fn block(group: MeshGroup, size: Vec3, at: Vec3, material: &Arc<Material>) -> MeshGroup {
    group.with(
        Arc::new(procedural::cuboid(size)),
        material.clone(),
        Mat4::from_translation(at + Vec3::Y * size.y * 0.5),
    )
}

impl Building {
    /// The building with about `triangles` triangles of furniture in each room (at least
    /// a few hundred: the rooms' walls and plain furniture), deterministic for `seed`.
    pub fn new(triangles: u32, seed: u64) -> Building {
        let wall = lit(0.82, 0.78, 0.68);
        // The doorway wall is an open sheet: seen from both sides.
        let sheet = Arc::new(Material::clone(&wall).double_sided(true));
        let hall = MeshGroup::new()
            .with(
                Arc::new(procedural::doorway_wall(
                    -HALF_LENGTH,
                    HALF_LENGTH,
                    HEIGHT,
                    &DOORS.map(|d| (d, DOOR_W, DOOR_H)),
                )),
                sheet,
                Mat4::IDENTITY,
            )
            .with(
                Arc::new(procedural::cuboid(Vec3::new(
                    2.0 * HALF_LENGTH,
                    0.1,
                    HALL_DEPTH,
                ))),
                lit(0.45, 0.4, 0.35),
                Mat4::from_translation(Vec3::new(0.0, -0.05, HALL_DEPTH / 2.0)),
            )
            .with(
                Arc::new(procedural::cuboid(Vec3::new(
                    2.0 * HALF_LENGTH,
                    0.1,
                    HALL_DEPTH,
                ))),
                lit(0.9, 0.9, 0.88),
                Mat4::from_translation(Vec3::new(0.0, HEIGHT + 0.05, HALL_DEPTH / 2.0)),
            )
            .with(
                Arc::new(procedural::cuboid(Vec3::new(
                    2.0 * HALF_LENGTH,
                    HEIGHT,
                    0.1,
                ))),
                wall.clone(),
                Mat4::from_translation(Vec3::new(0.0, HEIGHT / 2.0, HALL_DEPTH + 0.05)),
            );
        // The hall's two ends, so no view out of it shows the clear colour.
        let hall = [-1.0, 1.0].into_iter().fold(hall, |hall, side| {
            hall.with(
                Arc::new(procedural::cuboid(Vec3::new(0.1, HEIGHT, HALL_DEPTH))),
                wall.clone(),
                Mat4::from_translation(Vec3::new(
                    side * (HALF_LENGTH + 0.05),
                    HEIGHT / 2.0,
                    HALL_DEPTH / 2.0,
                )),
            )
        });
        let mut rng = XorShift::new(seed);
        let rooms = DOORS
            .iter()
            .enumerate()
            .map(|(k, &x)| {
                let opening = Opening::upright(Vec3::new(x, 0.0, 0.0), DOOR_W, DOOR_H, Vec3::Z);
                (opening, room(x, k, triangles, &mut rng))
            })
            .collect();
        Building {
            hall,
            rooms,
            lighting: Lighting {
                ambient: Rgba::new(0.35, 0.35, 0.38, 1.0),
                lights: vec![Light::Directional {
                    direction: Vec3::new(-0.35, -1.0, -0.45).normalize(),
                    color: Rgba::new(0.9, 0.88, 0.8, 1.0),
                }],
            },
        }
    }

    /// The rooms as portals.
    pub fn portals(&self) -> Vec<Portal> {
        self.rooms
            .iter()
            .map(|(o, r)| Portal::new(*o, r.clone()))
            .collect()
    }

    /// Triangles behind the doorways.
    pub fn room_triangles(&self) -> usize {
        self.rooms
            .iter()
            .flat_map(|(_, r)| &r.parts)
            .map(|p| p.mesh.indices.len() / 3)
            .sum()
    }

    /// The walkthrough at `t` in [0, 1]: eye and look-at point. Along the hall past the
    /// doors (looking into them), then through the middle door into its room.
    pub fn path(t: f32) -> (Vec3, Vec3) {
        let t = t.clamp(0.0, 1.0);
        if t < 0.6 {
            // Along the hall from x = -5 to x = 3, 2.8 from the doorway wall.
            let s = t / 0.6;
            let x = -5.0 + 8.0 * s;
            let eye = Vec3::new(x, 1.6, 2.8);
            (eye, Vec3::new(x - 1.0, 1.2, -2.0))
        } else {
            // Turn to the middle door and walk through it.
            let s = (t - 0.6) / 0.4;
            let from = Vec3::new(3.0, 1.6, 2.8);
            let door = Vec3::new(0.0, 1.6, 2.4);
            let eye = if s < 0.4 {
                from.lerp(door, s / 0.4)
            } else {
                door.lerp(Vec3::new(0.0, 1.6, -3.0), (s - 0.4) / 0.6)
            };
            (eye, Vec3::new(0.0, 1.2, -6.0))
        }
    }
}

/// Triangles of the statue rings' levels of detail, finest first (those under the ring's
/// own count are used): each halves the one before, so the level chosen by screen size
/// (the portals' [`ibr::portal::PortalConfig::lod_px`]) is never more than twice the
/// triangles the deviation allows.
pub const RING_LODS: [u32; 8] = [32_000, 16_000, 8_000, 4_000, 2_000, 1_000, 500, 250];

/// The levels of detail of a ring of `n` triangles ([`RING_LODS`] coarser than it), each
/// with its deviation from the full ring: both tori's bounds from the true torus summed
/// ([`procedural::torus_deviation`]).
pub fn ring_lods(n: u32) -> Vec<(Arc<Mesh>, f32)> {
    let full = procedural::torus_deviation(n);
    RING_LODS
        .iter()
        .filter(|&&k| k < n)
        .map(|&k| {
            let mesh = Arc::new(procedural::torus_with_triangles(k));
            (mesh, procedural::torus_deviation(k) + full)
        })
        .collect()
}

/// The room behind the doorway at `x`: floor, ceiling, three walls (its own colour), a
/// table with chairs, shelves with boxes, and a statue carrying most of `triangles`.
fn room(x: f32, k: usize, triangles: u32, rng: &mut XorShift) -> MeshGroup {
    let palette = [(0.35, 0.5, 0.7), (0.7, 0.45, 0.35), (0.45, 0.65, 0.4)];
    let (r, g, b) = palette[k % 3];
    let walls = lit(r, g, b);
    let z = -ROOM_DEPTH / 2.0;
    let w = 3.8;
    let mut m = MeshGroup::new();
    m = block(
        m,
        Vec3::new(w, 0.1, ROOM_DEPTH),
        Vec3::new(x, -0.1, z),
        &lit(0.5, 0.42, 0.33),
    );
    m = block(
        m,
        Vec3::new(w, 0.1, ROOM_DEPTH),
        Vec3::new(x, HEIGHT, z),
        &lit(0.92, 0.92, 0.9),
    );
    m = block(
        m,
        Vec3::new(w, HEIGHT, 0.1),
        Vec3::new(x, 0.0, -ROOM_DEPTH),
        &walls,
    );
    // The side walls stop just behind the doorway wall: ending in its plane, their ends
    // would fight it for depth wherever the room is drawn as geometry.
    let gap = 0.05;
    for side in [-1.0, 1.0] {
        let at = Vec3::new(x + side * w / 2.0, 0.0, z - gap / 2.0);
        m = block(m, Vec3::new(0.1, HEIGHT, ROOM_DEPTH - gap), at, &walls);
    }
    // A table and four chairs.
    let wood = lit(0.55, 0.35, 0.2);
    let t = Vec3::new(x + rng.range(-0.6, 0.6), 0.0, -2.6 + rng.range(-0.4, 0.4));
    m = block(m, Vec3::new(1.4, 0.08, 0.8), t + Vec3::Y * 0.72, &wood);
    for (dx, dz) in [(-0.6, -0.3), (0.6, -0.3), (-0.6, 0.3), (0.6, 0.3)] {
        m = block(
            m,
            Vec3::new(0.06, 0.72, 0.06),
            t + Vec3::new(dx, 0.0, dz),
            &wood,
        );
    }
    let seat = lit(0.3, 0.3, 0.35);
    for (dx, dz) in [(-0.4, -0.7), (0.4, -0.7), (-0.4, 0.7), (0.4, 0.7)] {
        let c = t + Vec3::new(dx, 0.0, dz);
        m = block(m, Vec3::new(0.4, 0.45, 0.4), c, &seat);
        let back = c + Vec3::new(0.0, 0.45, 0.18 * dz.signum());
        m = block(m, Vec3::new(0.4, 0.5, 0.05), back, &seat);
    }
    // Shelves against the back wall, with boxes of several colours.
    let shelf = lit(0.4, 0.3, 0.2);
    for level in 0..4 {
        let y = 0.3 + 0.55 * level as f32;
        m = block(
            m,
            Vec3::new(2.0, 0.04, 0.35),
            Vec3::new(x - 0.8, y, -5.7),
            &shelf,
        );
        for i in 0..5 {
            let c = lit(
                rng.range(0.2, 0.9),
                rng.range(0.2, 0.9),
                rng.range(0.2, 0.9),
            );
            let size = Vec3::new(rng.range(0.15, 0.3), rng.range(0.15, 0.4), 0.25);
            let at = Vec3::new(x - 1.6 + 0.38 * i as f32, y + 0.04, -5.7);
            m = block(m, size, at, &c);
        }
    }
    // The statue: a torus knot of rings carrying the room's triangle budget.
    let statue = lit(0.85, 0.8, 0.7);
    let rings = 3u32;
    let per = (triangles / rings).max(64);
    let ring = Arc::new(procedural::torus_with_triangles(per));
    let lods = ring_lods(per);
    for i in 0..rings {
        let tilt = Mat4::from_rotation_y(i as f32 * 1.05) * Mat4::from_rotation_x(1.2);
        let at = Vec3::new(x + 1.2, 1.2, -4.0);
        let place = Mat4::from_translation(at) * tilt * Mat4::from_scale(Vec3::splat(0.45));
        let part = Part::new(ring.clone(), statue.clone(), place).with_lods(lods.clone());
        m.parts.push(part);
    }
    m = block(
        m,
        Vec3::new(0.6, 0.6, 0.6),
        Vec3::new(x + 1.2, 0.0, -4.0),
        &lit(0.5, 0.5, 0.5),
    );
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rooms_scale_their_triangles_and_sit_behind_their_doorways() {
        let small = Building::new(1_000, 1);
        let big = Building::new(300_000, 1);
        let (s, b) = (small.room_triangles(), big.room_triangles());
        assert!(s < 12_000, "{s}");
        assert!(b > 3 * 280_000, "{b}");
        for (opening, room) in &big.rooms {
            assert!(opening.normal().z > 0.99);
            // Every part of the room lies behind the doorway wall.
            for part in &room.parts {
                for v in &part.mesh.positions {
                    let p = part.transform.transform_point3(*v);
                    assert!(opening.side(p) <= 0.06, "{p}");
                }
            }
        }
        // The walkthrough starts in the hall and ends in the middle room.
        assert!(Building::path(0.0).0.z > 0.0 && Building::path(1.0).0.z < 0.0);
    }

    /// The frame at `t` along the walk with the hall and every room drawn as geometry, at
    /// 320x180: its bytes and the fragments shaded.
    fn as_geometry(b: &Building, t: f32) -> (Vec<u8>, u64) {
        use engine::{Camera, FrameOptions, Renderer, Target};
        use ibr::subject::Subject;
        let (w, h) = (320, 180);
        let (eye, at) = Building::path(t);
        let cam = Camera::look_at(eye, at, Vec3::Y, 1.05, 1.0)
            .with_aspect(w, h)
            .with_depth_range(0.05, 60.0);
        let mut draws = Vec::new();
        b.hall.draws(&mut draws);
        b.rooms.iter().for_each(|(_, r)| r.draws(&mut draws));
        let mut target = Target::new(w, h);
        target.clear(Rgba::new(0.05, 0.05, 0.06, 1.0));
        let opts = FrameOptions::default();
        let s = Renderer::new().render(draws, &cam, &b.lighting, &mut target, &opts);
        (target.to_rgba8(), s.fragments_shaded)
    }

    #[test]
    fn single_sided_solids_draw_the_same_pixels_with_fewer_fragments() {
        let one = Building::new(2_000, 5);
        let mut two = one.clone();
        let groups = std::iter::once(&mut two.hall).chain(two.rooms.iter_mut().map(|r| &mut r.1));
        for part in groups.flat_map(|g| g.parts.iter_mut()) {
            part.material = Arc::new(Material::clone(&part.material).double_sided(true));
        }
        let (mut fragments, mut differ, mut pixels) = ([0u64; 2], 0, 0);
        for k in 0..6 {
            let t = k as f32 / 5.0;
            let ((a, fa), (b, fb)) = (as_geometry(&one, t), as_geometry(&two, t));
            fragments[0] += fa;
            fragments[1] += fb;
            differ += a.chunks(4).zip(b.chunks(4)).filter(|(x, y)| x != y).count();
            pixels += a.len() / 4;
        }
        assert!(
            differ * 2_000 <= pixels,
            "{differ} of {pixels} pixels differ"
        );
        assert!(
            fragments[0] * 10 <= fragments[1] * 9,
            "single-sided {} against double-sided {} fragments",
            fragments[0],
            fragments[1]
        );
    }
}
