//! Tests of the view atlas (`views`): bakes, cells, and sprites against their meshes.

use super::*;
use crate::core::{BillboardBatch, Facing, View};
use engine::{procedural, Camera, FrameOptions, Renderer, Target};
use glam::Mat4;

/// A ball of radius 0.5, unlit red, in a sphere of 0.6: every cell shows it.
fn atlas(azimuths: usize, elevations: &[f32]) -> ViewAtlas {
    let mesh = procedural::uv_sphere(0.5, 8, 16);
    let material = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
    let draw = Draw {
        mesh: &mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let bounds = Sphere {
        center: Vec3::ZERO,
        radius: 0.6,
    };
    ViewAtlas::bake(
        &[draw],
        &Lighting::default(),
        bounds,
        azimuths,
        elevations,
        16,
    )
}

#[test]
fn the_cell_is_the_nearest_baked_direction() {
    let a = atlas(4, &[0.0, 0.6, 1.2]);
    assert_eq!(a.cell(Vec3::X), (0, 0));
    assert_eq!(a.cell(Vec3::new(0.1, 0.0, 1.0)), (1, 0));
    assert_eq!(a.cell(Vec3::new(-1.0, 0.0, -0.1)), (2, 0));
    assert_eq!(a.cell(Vec3::new(0.0, 0.0, -1.0)), (3, 0));
    // 45 degrees up is nearest 0.6 rad (34 degrees); straight up, the last row.
    assert_eq!(a.cell(Vec3::new(1.0, 1.0, 0.0)), (0, 1));
    assert_eq!(a.cell(Vec3::new(0.01, 1.0, 0.0)).1, 2);
    assert_eq!(a.cell(Vec3::ZERO), (0, 0));
    assert_eq!(a.cell(Vec3::NAN), (0, 0));
    let r = a.region(Vec3::new(-1.0, 0.7, 0.0));
    assert_eq!(r.min, Vec2::new(0.5, 1.0 / 3.0));
    assert_eq!(r.max, Vec2::new(0.75, 2.0 / 3.0));
}

#[test]
fn every_cell_holds_its_view_framed_with_a_clear_margin() {
    let a = atlas(3, &[0.0, 1.0]);
    let t = &a.texture.levels()[0];
    assert_eq!((a.texture.width(), a.texture.height()), (48, 32));
    for (cy, cx) in [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (1, 2)] {
        let at = |x: u32, y: u32| t.texels[((cy * 16 + y) * 48 + cx * 16 + x) as usize];
        // The ball covers the cell's centre, opaque red (shaded; linear bytes, 32 is
        // sRGB 100); its corners stay clear.
        let c = at(8, 8).to_le_bytes();
        assert!(
            c[0] > 32 && c[1] < 8 && c[3] == 255,
            "cell {cx},{cy}: {c:?}"
        );
        for (x, y) in [(0, 0), (15, 0), (0, 15), (15, 15)] {
            assert_eq!(at(x, y), 0, "cell {cx},{cy} corner {x},{y}");
        }
    }
}

/// Fragments shaded drawing `items` (in the order given, with `material`) from `cam`.
fn shaded(cam: &Camera, material: Material, items: &[Billboard]) -> (u64, Target) {
    let mut batch = BillboardBatch::new(material);
    batch.items.extend_from_slice(items);
    batch.build(&View::new(cam, 120));
    let mut target = Target::new(160, 120);
    let stats = Renderer::new().render(
        [batch.draw()],
        cam,
        &Lighting::default(),
        &mut target,
        &FrameOptions {
            clear: Some(Rgba::TRANSPARENT),
            ..FrameOptions::default()
        },
    );
    (stats.fragments_shaded, target)
}

#[test]
fn a_row_of_cutouts_near_to_far_shades_about_one_sprite() {
    let a = atlas(4, &[0.0]);
    let (eye, side) = (Vec3::new(0.0, 0.0, 2.5), 2.0 * a.bounds.radius);
    let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.8, 160.0 / 120.0);
    // Eight balls in a row straight away from the eye, 0.25 apart, pushed far to near.
    let row: Vec<Billboard> = (0..8)
        .map(|k| {
            let p = Vec3::new(0.0, 0.0, -0.25 * k as f32);
            Billboard {
                region: a.region(eye - p),
                ..Billboard::new(p, Facing::World { up: Vec3::Y }, Vec2::splat(side))
            }
        })
        .rev()
        .collect();
    let mut sorted = row.clone();
    ViewAtlas::order(&mut sorted, eye);
    assert_eq!(sorted[0].position, Vec3::ZERO, "nearest first");
    // The reference: the nearest sprite drawn alone.
    let (one, alone) = shaded(&cam, a.material(), &sorted[..1]);
    let solid = (0..120)
        .flat_map(|y| (0..160).map(move |x| (x, y)))
        .filter(|&(x, y)| alone.pixel(x, y).is_some_and(|c| c >> 24 == 255))
        .count() as u64;
    assert!(one > 2000 && solid * 2 > one, "{one} {solid}");
    let (cut, image) = shaded(&cam, a.material(), &sorted);
    let blended = Material {
        alpha_mode: AlphaMode::Blend,
        ..a.material()
    };
    let (blend, _) = shaded(&cam, blended, &row);
    let (far_first, _) = shaded(&cam, a.material(), &row);
    // Near to far, a farther sprite (smaller on screen, its ball inside the nearer
    // balls) shades at most the clear part of its quad, no more than the nearest's;
    // blended or far to near, every quad shades whole.
    assert!(cut <= one + 7 * (one - solid), "{cut}: {one} {solid}");
    assert!(
        cut * 2 < blend && cut * 2 < far_first,
        "{cut} {blend} {far_first}"
    );
    assert!(blend * 10 > one * 40, "{blend} vs {one}");
    // And the row looks as its nearest sprite does where that one is opaque.
    assert_eq!(image.pixel(80, 60), alone.pixel(80, 60));
}

/// Mean absolute reversed depth difference from `truth` over the pixels both cover,
/// and how many.
fn depth_error(a: &Target, truth: &Target) -> (f32, usize) {
    let (mut sum, mut n) = (0.0, 0);
    for y in 0..a.height() {
        for x in 0..a.width() {
            let (p, q) = (a.depth_reversed(x, y), truth.depth_reversed(x, y));
            if let (Some(p), Some(q)) = (p, q) {
                if p > 0.0 && q > 0.0 {
                    sum += (p - q).abs();
                    n += 1;
                }
            }
        }
    }
    (sum / n.max(1) as f32, n)
}

#[test]
fn a_relief_sprite_stands_where_the_mesh_does() {
    let a = atlas(4, &[0.0, 0.6]);
    // The centre node: the ball's front, 0.5 in front of the centre plane, in radii of
    // the atlas's (margin-enlarged) sphere.
    let g = &a.depth[0];
    let inner = [g[RELIEF * RELIEF / 2]];
    let want = 0.5 / a.bounds.radius;
    for o in inner {
        assert!((o - want).abs() < 0.05, "{o} vs {want}: {g:?}");
    }
    // A corner's share only grazes the ball's outline, where its surface meets the
    // centre plane.
    assert!((0.0..0.15).contains(&g[0]), "corner {}", g[0]);
    // Seen from the first bake's direction, in perspective: the relief's depth is
    // the ball's, where the flat quad's is its centre's.
    let eye = Vec3::new(3.0, 0.0, 0.0);
    let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.6, 160.0 / 120.0);
    let view = View::new(&cam, 120);
    let side = 2.0 * a.bounds.radius;
    let item = Billboard {
        region: a.region(eye),
        ..Billboard::new(Vec3::ZERO, Facing::World { up: Vec3::Y }, Vec2::splat(side))
    };
    let mut mesh = Mesh::default();
    assert_eq!(a.relief(&[item], &view, &mut mesh), 1);
    assert_eq!(mesh.positions.len(), RELIEF * RELIEF);
    let material = a.material().double_sided(true);
    let ball = procedural::uv_sphere(0.5, 8, 16);
    let red = Material::unlit(Rgba::new(1.0, 0.0, 0.0, 1.0));
    let render = |draw: Draw<'_>| {
        let mut t = Target::new(160, 120);
        Renderer::new().render(
            [draw],
            &cam,
            &Lighting::default(),
            &mut t,
            &FrameOptions {
                clear: Some(Rgba::TRANSPARENT),
                ..FrameOptions::default()
            },
        );
        t
    };
    let at = |mesh| Draw {
        mesh,
        material: &material,
        transform: Mat4::IDENTITY,
    };
    let relief = render(at(&mesh));
    let mut flat = BillboardBatch::new(material.clone());
    flat.push(item);
    flat.build(&view);
    let flat = render(flat.draw());
    let truth = render(Draw {
        mesh: &ball,
        material: &red,
        transform: Mat4::IDENTITY,
    });
    let (e_relief, n_relief) = depth_error(&relief, &truth);
    let (e_flat, n_flat) = depth_error(&flat, &truth);
    assert!(n_relief > 1000 && n_flat > 1000, "{n_relief} {n_flat}");
    assert!(e_relief * 3.0 < e_flat, "relief {e_relief}, flat {e_flat}");
    // The same texels on screen: the relief's colour is the flat quad's but for the
    // texture's interpolation across its tilted triangles (a fraction of a texel,
    // seen along the outline of this magnified 16-texel view: 5.8% measured).
    let off = (0..120)
        .flat_map(|y| (0..160).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let (p, q) = (relief.pixel(x, y), flat.pixel(x, y));
            let (p, q) = (p.unwrap_or(0).to_le_bytes(), q.unwrap_or(0).to_le_bytes());
            p.iter().zip(q).any(|(a, b)| a.abs_diff(b) > 24)
        })
        .count();
    assert!(off * 100 < n_flat * 8, "{off} of {n_flat} pixels differ");
}

/// A matte ball lit by a sun, baked 64 texels a view, its sprite seen in perspective
/// from far along a baked direction (the quad about as many pixels across as the
/// view's texels), against the ball's mesh from the same eye: the sprite reproduces
/// the bake. Its colour is the mesh's (the light that left the ball toward the eye,
/// baked in) and its outline too.
#[test]
fn a_sprite_seen_from_its_bake_direction_reproduces_the_mesh() {
    use engine::Light;
    let ball = procedural::uv_sphere(0.5, 24, 48);
    let matte = Material {
        shading: engine::Shading::Lit {
            specular: 0.0,
            shininess: 32.0,
        },
        ..Material::lit(Rgba::new(0.3, 0.7, 0.2, 1.0))
    };
    let draw = Draw {
        mesh: &ball,
        material: &matte,
        transform: Mat4::IDENTITY,
    };
    let lighting = Lighting {
        ambient: Rgba::new(0.2, 0.2, 0.25, 1.0),
        lights: vec![Light::Directional {
            direction: Vec3::new(-0.45, -0.75, -0.5).normalize(),
            color: Rgba::WHITE,
        }],
    };
    let bounds = Sphere {
        center: Vec3::ZERO,
        radius: 0.6,
    };
    let elevations = [0.0, 0.5];
    let a = ViewAtlas::bake(&[draw], &lighting, bounds, 6, &elevations, 64);
    let h = 120u32; // the compared renders' height
    for (k, e) in [(0, 0.0), (2, 0.0), (4, 0.5)] {
        let eye = direction(6, k, e) * 12.0;
        assert_eq!(a.cell(eye), (k, usize::from(e > 0.0)));
        // 64 texels over the quad's 2 * radius at 12 units.
        let side = 2.0 * a.bounds.radius;
        let fov = 2.0 * (0.5 * h as f32 * side / (64.0 * 12.0)).atan();
        let (both, one, mean) = super::super::compare::against_mesh(&a, draw, &lighting, eye, fov);
        assert!(both > 1500, "view {k}: {both} pixels");
        assert!(
            one * 100 < both * 4,
            "view {k}: outline off on {one} of {both}"
        );
        assert!(mean < 3.0, "view {k}: colour off by {mean} levels");
    }
}

/// A sprite under [`ViewAtlas::coarse_px`] tall on screen is drawn with every 2nd column
/// of its grid's nodes (16 triangles), a taller one with the whole grid (32), as is every
/// one when `coarse_px` is 0; each row ends at the trim's outline.
#[test]
fn a_sprite_small_on_screen_is_drawn_with_fewer_triangles() {
    let mut a = atlas(4, &[0.0, 0.6]);
    let side = 2.0 * a.bounds.radius;
    // 120 pixels tall at 0.6 rad: a pixel is 0.00516 units a unit away.
    let per_px = 2.0 * 0.3f32.tan() / 120.0;
    let triangles = |a: &ViewAtlas, px: f32| {
        let distance = side / (px * per_px);
        let eye = Vec3::new(distance, 0.0, 0.0);
        let cam = Camera::look_at(eye, Vec3::ZERO, Vec3::Y, 0.6, 160.0 / 120.0);
        let view = View::new(&cam, 120);
        let item = Billboard {
            region: a.region(eye),
            ..Billboard::new(Vec3::ZERO, Facing::World { up: Vec3::Y }, Vec2::splat(side))
        };
        let mut mesh = Mesh::default();
        assert_eq!(a.relief(&[item], &view, &mut mesh), 1);
        let cols = mesh.positions.len() / RELIEF;
        assert_eq!(cols * RELIEF, mesh.positions.len());
        assert_eq!(mesh.indices.len(), 6 * (cols - 1) * (RELIEF - 1));
        // Each row's ends are the trim's (as baked), whatever the columns
        // between; a cell is a quarter of the atlas wide.
        let trim = a.trims[a.view_of(item.region)];
        for row in 0..RELIEF {
            let (l, r) = (mesh.uvs[row * cols].x, mesh.uvs[row * cols + cols - 1].x);
            let w = 0.25 * (trim.right[row] - trim.left[row]);
            assert!((w - 1e-5..w + 0.07).contains(&(r - l)), "{px} px row {row}");
        }
        mesh.indices.len() / 3
    };
    assert_eq!(triangles(&a, 10.0), 32);
    a.coarse_px = 20.0;
    assert_eq!(triangles(&a, 10.0), 16);
    assert_eq!(triangles(&a, 19.0), 16);
    assert_eq!(triangles(&a, 40.0), 32);
}

/// A node's depth is the nearest surface near it ([`NODE_REACH`]), not one at the edge of
/// its share of the square: a bump half way between two nodes (a crown's front its share
/// only grazes) moves neither, where the surface at a node sets it.
#[test]
fn a_nodes_depth_is_the_surface_near_it() {
    // 40 texels, 4 bands: node `n` at texel 10 n - 0.5, a node spacing 10 texels.
    let px = 40;
    let mut offsets = vec![f32::NEG_INFINITY; px * px];
    // A low surface on the middle node (2, 2) and a high bump 4.5 to 5.5 texels to its
    // left (0.45 to 0.55 of a spacing: the old share of (2, 2) and (2, 1)).
    for y in 19..21 {
        for x in 19..21 {
            offsets[y * px + x] = 0.2;
        }
        for x in 14..16 {
            offsets[y * px + x] = 0.9;
        }
    }
    let g = grid(&offsets, px);
    assert_eq!(g[2 * RELIEF + 2], 0.2, "{g:?}");
    assert_eq!(g[2 * RELIEF + 1], 0.0, "{g:?}");
    // Within reach of a node, a surface sets it.
    offsets[20 * px + 12] = 0.7;
    assert_eq!(grid(&offsets, px)[2 * RELIEF + 1], 0.7);
}
