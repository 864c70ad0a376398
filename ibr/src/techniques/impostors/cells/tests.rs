//! The covered cells' mesh: it covers every texel within a texel of a covered one, no
//! empty cell beyond, and its edges meet without T-junctions.

use super::*;

use proptest::prelude::*;

/// The mesh over `covered` (texels of a `side` image) in texel coordinates, with the rect
/// the refresh clips it to (the covered bounds grown by one texel).
fn mesh_of(side: u32, covered: &[(u32, u32)]) -> (Mesh, f32) {
    let mut cells = Cells::new(side);
    for y in 0..side {
        cells.mark_row(y, covered.iter().filter(|p| p.1 == y).map(|p| p.0));
    }
    let (x0, y0) = covered
        .iter()
        .fold((u32::MAX, u32::MAX), |a, p| (a.0.min(p.0), a.1.min(p.1)));
    let (x1, y1) = covered
        .iter()
        .fold((0, 0), |a, p| (a.0.max(p.0 + 1), a.1.max(p.1 + 1)));
    let rect = Rect::new(x0, y0, x1 - x0, y1 - y0).grow(1, side, side);
    let s = side as f32;
    let mut m = Mesh::default();
    let share = cells.write(rect, |uv| Vec3::new(uv.x * s, uv.y * s, 0.0), &mut m);
    (m, share)
}

/// How many of `m`'s triangles hold the point `p` (inside or on an edge: the caller keeps
/// `p` off every edge, as a rasteriser's fill rule would).
fn holders(m: &Mesh, p: Vec2) -> usize {
    let cross = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
    m.indices
        .chunks(3)
        .filter(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| m.positions[t[k] as usize].truncate());
            let area = cross(a, b, c);
            let (e0, e1, e2) = (cross(a, b, p), cross(b, c, p), cross(c, a, p));
            area != 0.0
                && ((e0 >= 0.0 && e1 >= 0.0 && e2 >= 0.0) || (e0 <= 0.0 && e1 <= 0.0 && e2 <= 0.0))
        })
        .count()
}

/// Whether texel `(x, y)` is within one texel (either way, diagonals too) of a covered one.
fn near(covered: &[(u32, u32)], x: u32, y: u32) -> bool {
    covered
        .iter()
        .any(|p| p.0.abs_diff(x) <= 1 && p.1.abs_diff(y) <= 1)
}

fn check(side: u32, covered: &[(u32, u32)]) -> Result<(), TestCaseError> {
    let (m, share) = mesh_of(side, covered);
    let cells = Cells::new(side);
    let mut area = 0;
    for y in 0..side {
        for x in 0..side {
            // Off the texel's centre, which a fan's diagonal may pass through.
            let n = holders(&m, Vec2::new(x as f32 + 0.5137, y as f32 + 0.5071));
            prop_assert!(n <= 1, "texel ({x}, {y}) drawn {n} times");
            area += n;
            if near(covered, x, y) {
                prop_assert_eq!(n, 1, "texel ({}, {}) by a covered one is not drawn", x, y);
            }
            // A texel drawn lies in a cell that holds a texel by a covered one.
            let (cx, cy) = (cells.cell(x), cells.cell(y));
            let cell_needed = (0..side).any(|ty| {
                (0..side)
                    .any(|tx| cells.cell(tx) == cx && cells.cell(ty) == cy && near(covered, tx, ty))
            });
            if n == 1 {
                prop_assert!(cell_needed, "texel ({x}, {y}) drawn in an empty cell");
            }
        }
    }
    prop_assert!((share - area as f32 / (side * side) as f32).abs() < 1e-5);
    // No T-junction: no vertex strictly inside another triangle's edge.
    let pts: Vec<Vec2> = m.positions.iter().map(|p| p.truncate()).collect();
    for t in m.indices.chunks(3) {
        for k in 0..3 {
            let (a, b) = (pts[t[k] as usize], pts[t[(k + 1) % 3] as usize]);
            for &v in &pts {
                let on = (b - a).perp_dot(v - a) == 0.0;
                let inside = (v - a).dot(b - a) > 0.0 && (v - b).dot(a - b) > 0.0;
                prop_assert!(!(on && inside), "vertex {v} inside edge {a} {b}");
            }
        }
    }
    Ok(())
}

#[test]
fn scattered_patches_are_drawn_alone_and_a_single_texel_within_its_fringe() {
    // Two patches in opposite corners of a 64-texel image: 2 of 64 cells' worth, not the
    // whole square their bounds span.
    let covered = [(3, 4), (4, 4), (60, 58), (61, 59)];
    check(64, &covered).unwrap();
    let (m, share) = mesh_of(64, &covered);
    assert!(share < 0.04, "{share}");
    assert!(!m.indices.is_empty());
    // One texel: its 3 x 3 fringe, not its cell.
    let (_, share) = mesh_of(64, &[(20, 20)]);
    assert!((share - 9.0 / 4096.0).abs() < 1e-6, "{share}");
}

#[test]
fn a_full_image_is_one_rectangle() {
    let covered: Vec<(u32, u32)> = (0..16).flat_map(|y| (0..16).map(move |x| (x, y))).collect();
    let (m, share) = mesh_of(16, &covered);
    assert_eq!(share, 1.0);
    assert_eq!(m.indices.len(), 6, "{m:?}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn the_mesh_covers_the_fringe_once_and_only_needed_cells(
        side in 1u32..40,
        picks in prop::collection::vec((0u32..40, 0u32..40), 1..12),
    ) {
        let covered: Vec<(u32, u32)> = picks.iter().map(|p| (p.0 % side, p.1 % side)).collect();
        check(side, &covered)?;
    }
}

#[test]
fn neighbouring_bands_meet_vertex_to_vertex() {
    // Band rows of different runs above and below a wider one (a fan from its corner had
    // an edge along its top through the run above's end).
    check(6, &[(1, 2), (2, 0)]).unwrap();
    check(16, &[(2, 2), (12, 3), (7, 8), (1, 14), (14, 14)]).unwrap();
}

#[test]
fn rows_past_the_side_do_not_panic() {
    let mut cells = Cells::new(8);
    cells.mark_row(20, [3, 30].into_iter());
    let mut m = Mesh::default();
    let share = cells.write(Rect::new(0, 0, 8, 8), |uv| uv.extend(0.0), &mut m);
    assert!(share > 0.0 && share <= 1.0, "{share}");
}
