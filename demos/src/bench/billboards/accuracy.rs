//! The `accuracy_fade` and `accuracy_top` series: billboard trees against the meshes they
//! replace, by view elevation.

use super::trees::{sprite_material, tree_billboard, tree_material, tree_meshes};
use super::{Row, Settings};
use engine::{Camera, Draw, FrameOptions, FrameStats, Lighting, Mesh, Renderer, Rgba, Target};
use glam::{Mat4, Vec3};
use ibr::metrics::{self, Coverage, ImageError, Options, Region};
use ibr::sprites::{self, BakedSprite};
use ibr::{AxialFallback, BillboardBatch, Facing, View};

/// A camera `dist` from `center` at `azimuth` (degrees about +Y from +Z) and `elevation`
/// (degrees above the horizon), upright, well defined straight above too.
pub fn orbit_camera(center: Vec3, dist: f32, azimuth: f32, elevation: f32, fov: f32) -> Camera {
    let (sa, ca) = azimuth.to_radians().sin_cos();
    let (se, ce) = elevation.to_radians().sin_cos();
    let dir = Vec3::new(sa * ce, se, ca * ce);
    let up = Vec3::new(-sa * se, ce, -ca * se);
    Camera::look_at(center + dir * dist, center, up, fov, 1.0)
        .with_depth_range(dist * 0.05, dist * 4.0)
}

/// The billboard-tree error at each elevation: one `accuracy_fade` and one `accuracy_top`
/// row per elevation.
pub(super) fn accuracy(
    settings: &Settings,
    renderer: &mut Renderer,
    threads: usize,
    progress: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let lighting = Lighting::default();
    let material = tree_material();
    let trees: Vec<(Mesh, BakedSprite)> = tree_meshes()
        .into_iter()
        .map(|mesh| {
            let sprite =
                sprites::bake_upright(&mesh, &material, &lighting, Vec3::Z, settings.bake_px);
            (mesh, sprite)
        })
        .collect();
    let size = settings.accuracy_size;
    let clear = FrameOptions {
        clear: Some(Rgba::new(0.0, 0.0, 0.0, 0.0)),
        ..Default::default()
    };
    let mut truth = Target::new(size, size);
    let mut image = Target::new(size, size);
    for (series, with_top) in [("accuracy_fade", false), ("accuracy_top", true)] {
        for &elevation in &settings.elevations {
            progress(format!("{series} {elevation} deg"));
            let mut errors = Vec::new();
            let mut first: Option<(u64, FrameStats)> = None;
            for (mesh, sprite) in &trees {
                let facing = Facing::Axial {
                    axis: Vec3::Y,
                    fallback: AxialFallback {
                        top: with_top.then_some(sprite.top),
                        ..AxialFallback::default()
                    },
                };
                let mut batch = BillboardBatch::new(sprite_material(sprite));
                batch.push(tree_billboard(sprite, Vec3::ZERO, 1.0, facing));
                let center = Vec3::new(0.0, 2.5, 0.0);
                for &azimuth in &settings.azimuths {
                    let cam = orbit_camera(center, 11.0, azimuth, elevation, 40f32.to_radians());
                    let draw = Draw {
                        mesh,
                        material: &material,
                        transform: Mat4::IDENTITY,
                    };
                    renderer.render([draw], &cam, &lighting, &mut truth, &clear);
                    batch.build(&View::new(&cam, size));
                    let stats =
                        renderer.render([batch.draw()], &cam, &lighting, &mut image, &clear);
                    first.get_or_insert((batch.mesh().triangle_count() as u64, stats));
                    let rect = match (
                        metrics::covered_rect(&truth, Coverage::Alpha),
                        metrics::covered_rect(&image, Coverage::Alpha),
                    ) {
                        (None, None) => metrics::Rect::new(0, 0, size, size),
                        (a, b) => a.unwrap_or_default().union(b.unwrap_or_default()),
                    };
                    let opts = Options {
                        region: Region::Rect(rect.grow(2, size, size)),
                        ..Options::default()
                    };
                    errors.push(metrics::compare(&image, &truth, &opts).expect("same size"));
                }
            }
            let (triangles, stats) = first.unwrap_or_default();
            rows.push(Row {
                series,
                param: "elevation_deg",
                value: elevation as f64,
                width: size,
                height: size,
                items: trees.len() as u64,
                triangles,
                threads,
                times: None,
                stats,
                error: ImageError::pooled(&errors),
            });
        }
    }
}
