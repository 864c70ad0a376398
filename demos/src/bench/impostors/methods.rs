//! The `method` series on the orbit: geometry (measured against itself), runtime
//! impostors, and baked octahedral impostors.

use super::row::{geometry_row, impostor_row, mean_ms, Errors, Row};
use super::scene::{
    fly_shape, frame_camera, frame_options, frame_view, measure_draws, run_geometry, Policy,
};
use super::Settings;
use crate::city::{City, Path as CityPath};
use crate::timing::Summary;
use engine::{Renderer, Target};
use ibr::impostor::Shape;
use ibr::octahedral::{Layout, OctahedralImpostor};
use ibr::subject::Subject;
use ibr::technique::FrameLoop;
use std::time::Instant;

/// What runtime impostors' images are drawn on in the `method` series, and their rows'
/// policy: a quad through the centre, a relief on the captured depths, the building's box.
pub const SHAPES: [(Shape, &str); 3] = [
    (Shape::Quad, "runtime"),
    (Shape::Relief, "runtime_relief"),
    (Shape::Box, "runtime_box"),
];

/// The `method` rows: geometry, runtime impostors on each of [`SHAPES`] at each of
/// [`Settings::method_tolerances`] (the same frames), and each octahedral configuration of
/// [`Settings::octahedral`].
pub(super) fn methods(
    settings: &Settings,
    city: &mut City,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let path = CityPath::Orbit;
    let n = city.buildings.len();
    tick("method geometry".into());
    let (times, tris) = run_geometry(
        city,
        path,
        settings.orbit_span,
        settings.frames,
        settings.size,
    );
    let mut row = geometry_row("method", path, settings, n, &times, tris);
    // The reference against itself, measured like every other method.
    let mut renderer = Renderer::new();
    let mut frames = Vec::new();
    for f in 1..settings.frames {
        let camera = frame_camera(
            city,
            path,
            settings.orbit_span,
            f,
            settings.frames,
            settings.size,
        );
        let mut frame = Vec::new();
        for b in &city.buildings {
            let (mut truth, mut image) = (Vec::new(), Vec::new());
            b.draws(&mut truth);
            b.draws(&mut image);
            if let Some(e) = measure_draws(
                &mut renderer,
                truth,
                image,
                &camera,
                settings.size,
                &city.lighting,
                b.bounds(),
            ) {
                frame.push(e);
            }
        }
        frames.push(frame);
    }
    row.errors = Some(Errors::of_frames(&frames));
    rows.push(row);
    for &tol in &settings.method_tolerances {
        for (shape, policy) in SHAPES {
            tick(format!("method {} {tol} deg", policy.replace('_', " ")));
            let out = fly_shape(settings, city, path, Policy::Error(tol), shape);
            rows.push(impostor_row(
                "method",
                path,
                policy.into(),
                Some(tol),
                settings,
                n,
                &out,
            ));
        }
    }
    octahedral_methods(settings, city, tick, rows);
}

/// The octahedral `method` rows: every building baked ([`Layout::Hemi`]) for each
/// configuration of [`Settings::octahedral`], then flown like the runtime impostors, the
/// impostors as one technique of the [`FrameLoop`]. An impostor whose bounding sphere is
/// off the image is neither updated nor drawn ([`OctahedralImpostor::update_in_view`]).
/// `refreshes` counts recomposed images.
fn octahedral_methods(
    settings: &Settings,
    city: &mut City,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let path = CityPath::Orbit;
    let span = settings.span(path);
    let n = city.buildings.len();
    let lighting = city.lighting.clone();
    let opts = frame_options();
    let mut ground = Vec::new();
    city.ground.draws(&mut ground);
    for &(grid, px) in &settings.octahedral {
        tick(format!("method octahedral {grid}x{grid} views of {px} px"));
        let t0 = Instant::now();
        let mut imps: Vec<OctahedralImpostor> = city
            .buildings
            .iter_mut()
            .map(|b| OctahedralImpostor::bake(b, &lighting, grid, px, Layout::Hemi))
            .collect();
        let bake = t0.elapsed();
        let memory: usize = imps.iter().map(|i| i.bytes()).sum();
        let (mut renderer, mut measurer) = (Renderer::new(), Renderer::new());
        let mut frame_loop = FrameLoop::new();
        let mut target = Target::new(settings.size.0, settings.size.1);
        let (mut times, mut update, mut frames) = (Vec::new(), Vec::new(), Vec::new());
        let (mut recomposed, mut triangles) = (0u64, 0u64);
        for f in 0..settings.frames {
            let camera = frame_camera(city, path, span, f, settings.frames, settings.size);
            let view = frame_view(&camera, &lighting, settings.size);
            let stats = frame_loop.render(
                &mut renderer,
                ground.iter().copied(),
                &mut [&mut imps],
                &view,
                &mut target,
                &opts,
            );
            if f == 0 {
                continue;
            }
            times.push(frame_loop.times.total);
            update.push(frame_loop.times.prepare);
            recomposed += frame_loop.counters[0].refreshes;
            triangles = stats.triangles_set_up;
            let mut frame = Vec::new();
            for (imp, b) in imps.iter().zip(&city.buildings).filter(|x| x.0.in_view()) {
                let mut truth = Vec::new();
                b.draws(&mut truth);
                if let Some(e) = measure_draws(
                    &mut measurer,
                    truth,
                    [imp.draw()],
                    &camera,
                    settings.size,
                    &lighting,
                    b.bounds(),
                ) {
                    frame.push(e);
                }
            }
            frames.push(frame);
        }
        rows.push(Row {
            frames: times.len(),
            refreshes: recomposed,
            time: Some(Summary::of(&times)),
            update_ms: Some(mean_ms(&update)),
            errors: Some(Errors::of_frames(&frames)),
            memory_bytes: Some(memory as u64),
            setup_ms: Some(bake.as_secs_f64() * 1e3),
            triangles,
            octahedral: Some((grid, px)),
            ..Row::empty(
                "method",
                path,
                format!("octahedral_{grid}x{px}"),
                settings,
                n,
            )
        });
    }
}

/// A method row's short name: `geometry`, `runtime 0.125 deg`, `octahedral 8x64`.
pub fn method_label(r: &Row) -> String {
    match (r.octahedral, r.tolerance_deg) {
        (Some((grid, px)), _) => format!("octahedral {grid}x{grid}x{px}px"),
        (None, Some(t)) if r.policy.starts_with("runtime") => {
            format!("{} {t} deg", r.policy.replace('_', " "))
        }
        (None, _) => r.policy.replace('_', " "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_come_from_the_rows_parameters() {
        let settings = Settings::tiny();
        let base = Row::empty("method", CityPath::Orbit, "geometry".into(), &settings, 9);
        assert_eq!(method_label(&base), "geometry");
        let runtime = Row {
            policy: "runtime".into(),
            tolerance_deg: Some(0.125),
            ..base.clone()
        };
        assert_eq!(method_label(&runtime), "runtime 0.125 deg");
        let boxed = Row {
            policy: "runtime_box".into(),
            ..runtime.clone()
        };
        assert_eq!(method_label(&boxed), "runtime box 0.125 deg");
        // The parameters, not the policy's spelling, make the label.
        let octahedral = Row {
            policy: "anything".into(),
            octahedral: Some((8, 64)),
            ..base
        };
        assert_eq!(method_label(&octahedral), "octahedral 8x8x64px");
    }
}
