//! The tolerance sweep (error-driven refresh at each tolerance, beside geometry, on
//! `translate` and `rotate`) and the fixed-interval refresh matched to it.

use super::row::{geometry_row, impostor_row, Row};
use super::scene::{fly, path_name, run_geometry, Policy};
use super::Settings;
use crate::city::{City, Path as CityPath};

/// The `geometry` reference and the `sweep` rows on `translate` and `rotate`.
pub(super) fn sweep(
    settings: &Settings,
    city: &mut City,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let n = city.buildings.len();
    for path in [CityPath::Translate, CityPath::Rotate] {
        tick(format!("geometry {}", path_name(path)));
        let (times, tris) = run_geometry(
            city,
            path,
            settings.span(path),
            settings.frames,
            settings.size,
        );
        rows.push(geometry_row("geometry", path, settings, n, &times, tris));
        for &tol in &settings.tolerances {
            tick(format!("sweep {} {tol} deg", path_name(path)));
            let policy = Policy::Error(tol);
            let out = fly(settings, city, path, policy);
            let row = impostor_row("sweep", path, "error".into(), Some(tol), settings, n, &out);
            rows.push(row);
        }
    }
}

/// The `fixed` rows: a fixed-interval policy at each `translate` sweep run's refresh
/// count.
pub(super) fn fixed(
    settings: &Settings,
    city: &mut City,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    let n = city.buildings.len();
    let translate: Vec<(f32, u64, usize)> = rows
        .iter()
        .filter(|r| r.series == "sweep" && r.path == "translate")
        .map(|r| (r.tolerance_deg.unwrap_or(0.0) as f32, r.refreshes, r.frames))
        .collect();
    let path = CityPath::Translate;
    for (tol, refreshes, frames) in translate {
        tick(format!("fixed interval matching {tol} deg"));
        let rate = refreshes as f64 / frames.max(1) as f64;
        let policy = Policy::Fixed { rate };
        let out = fly(settings, city, path, policy);
        let mut row = impostor_row("fixed", path, "fixed".into(), Some(tol), settings, n, &out);
        row.interval_frames = (rate > 0.0).then(|| n as f64 / rate);
        rows.push(row);
    }
}
