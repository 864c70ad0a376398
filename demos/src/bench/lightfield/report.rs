//! The light-field sweep as the CLI runs it ([`LightfieldSweep`]: its rows printed) and its
//! charts: error against `uv` density and `st` resolution per lookup, error against
//! compression, error against frame time beside the geometry (the outline from geometry
//! with and without), and frame time against
//! resolution and against the object's triangles.

use super::{Row, LOOKUPS, NO_OUTLINE, OUTLINE};
use crate::bench::{Progress, RunFlags, Sweep};
use crate::chart::{Chart, Line, Lines};
use ibr::metrics::ImageError;

/// The error pooled over the rows' eyes (PSNR, capped at 99 dB).
fn pooled(rows: &[&Row]) -> f64 {
    ImageError::pooled(rows.iter().filter_map(|r| r.error.as_ref()))
        .map_or(f64::NAN, |e| e.psnr_capped(99.0))
}

/// The rows of one series.
fn of<'a>(rows: &'a [Row], series: &'a str) -> impl Iterator<Item = &'a Row> + 'a {
    rows.iter().filter(move |r| r.series == series)
}

/// Per lookup and eye class: PSNR pooled over the eyes at each value of `x` of a series.
fn knob(rows: &[Row], series: &str, x: fn(&Row) -> u32) -> Vec<Line> {
    let mut lines = Vec::new();
    for (name, _, _) in LOOKUPS {
        for class in ["between", "away"] {
            let mut xs: Vec<u32> = of(rows, series).map(x).collect();
            xs.dedup();
            let points = xs
                .iter()
                .map(|&v| {
                    let at: Vec<&Row> = of(rows, series)
                        .filter(|r| x(r) == v && r.method == name && r.eye_class == class)
                        .collect();
                    (f64::from(v), pooled(&at))
                })
                .collect();
            lines.push(Line::new(format!("{name}, eyes {class}"), points));
        }
    }
    lines
}

/// The slab's size of a series, as a title's suffix.
fn slab_of(rows: &[Row], series: &str) -> String {
    of(rows, series)
        .next()
        .map_or(String::new(), |r| format!(" ({}x{})", r.width, r.height))
}

/// Compression: one point per quantised setting of a series.
fn compression(rows: &[Row], series: &str) -> Line {
    let mut keys: Vec<(u32, String)> = of(rows, series)
        .map(|r| (r.codewords, r.tile.clone()))
        .collect();
    keys.dedup();
    let points = keys
        .iter()
        .map(|(k, t)| {
            let at: Vec<&Row> = of(rows, series)
                .filter(|r| r.codewords == *k && &r.tile == t)
                .collect();
            let r = at[0];
            (
                r.raw_file_bytes as f64 / r.file_bytes.max(1) as f64,
                pooled(&at),
            )
        })
        .collect();
    let labels = keys.iter().map(|(k, t)| format!("{k} x {t}")).collect();
    Line {
        labels,
        ..Line::new(
            if series == "codebook" {
                "2x2x2x2 tiles, codewords varied"
            } else {
                "tile shapes"
            },
            points,
        )
    }
}

/// The raw light field's point on the compression chart (1:1).
fn raw_point(rows: &[Row]) -> Line {
    let raw_dc: Vec<&Row> = of(rows, "density")
        .filter(|r| r.method == "quadrilinear-dc")
        .filter(|r| {
            of(rows, "codebook")
                .next()
                .is_some_and(|c| c.uv == r.uv && c.st == r.st)
        })
        .collect();
    Line::new("raw (1:1)", vec![(1.0, pooled(&raw_dc))])
}

/// Error against time: every light-field point, and the geometry.
fn scatter(rows: &[Row]) -> Vec<Line> {
    let mut scatter: Vec<Line> = LOOKUPS
        .iter()
        .map(|(name, _, _)| {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| (r.series == "density" || r.series == "st") && r.method == *name)
                .collect();
            let points = (of.iter())
                .map(|r| {
                    (
                        r.time.median_ms,
                        r.error.map_or(f64::NAN, |e| e.psnr_capped(99.0)),
                    )
                })
                .collect();
            // Labelled with the setting: uv x st samples.
            let labels = of.iter().map(|r| format!("{}x{}", r.uv, r.st)).collect();
            Line::new(format!("{name} (uv and st varied)"), points).labelled(labels)
        })
        .collect();
    scatter.push(Line::new(
        "quantised, quadrilinear-dc",
        rows.iter()
            .filter(|r| r.series == "codebook" || r.series == "tile")
            .map(|r| {
                (
                    r.time.median_ms,
                    r.error.map_or(f64::NAN, |e| e.psnr_capped(99.0)),
                )
            })
            .collect(),
    ));
    for (method, name) in [
        (NO_OUTLINE, "raw base slab, quadrilinear-dc, no outline"),
        (
            OUTLINE,
            "raw base slab, quadrilinear-dc, outline from geometry",
        ),
    ] {
        let of: Vec<&Row> = of(rows, "outline").filter(|r| r.method == method).collect();
        scatter.push(Line::new(
            name,
            (of.iter())
                .map(|r| {
                    (
                        r.time.median_ms,
                        r.error.map_or(f64::NAN, |e| e.psnr_capped(99.0)),
                    )
                })
                .collect(),
        ));
    }
    scatter.push(Line::new(
        "geometry (the reference)",
        of(rows, "geometry")
            .map(|r| (r.time.median_ms, 99.0))
            .collect(),
    ));
    scatter
}

/// Frame time against `x` of a series: the light field and the geometry.
fn against(rows: &[Row], series: &str, x: fn(&Row) -> f64) -> Vec<Line> {
    ["quadrilinear-dc", "geometry"]
        .iter()
        .map(|m| {
            let name = if *m == "geometry" {
                "geometry"
            } else {
                "light field, quadrilinear-dc"
            };
            Line::new(
                name,
                of(rows, series)
                    .filter(|r| r.method == *m)
                    .map(|r| (x(r), r.time.median_ms))
                    .collect(),
            )
        })
        .collect()
}

/// Sparse: one point per photograph count (0: dense), pooled over the eyes.
fn sparse(rows: &[Row]) -> Vec<Line> {
    let mut ns: Vec<usize> = of(rows, "sparse").map(|r| r.photographs).collect();
    ns.dedup();
    let at = |n: usize| {
        of(rows, "sparse")
            .filter(|r| r.photographs == n)
            .collect::<Vec<&Row>>()
    };
    let dense = Line::new(
        "dense capture (every camera of the slab)",
        ns.iter()
            .filter(|&&n| n == 0)
            .map(|_| (1.0, pooled(&at(0))))
            .collect(),
    );
    let rebinned: Vec<usize> = ns.iter().copied().filter(|&n| n > 0).collect();
    let psnr = Line {
        labels: rebinned
            .iter()
            .map(|&n| format!("{:.1}% invented", at(n)[0].invented * 100.0))
            .collect(),
        ..Line::new(
            "photographs rebinned with their depth",
            rebinned
                .iter()
                .map(|&n| (n as f64, pooled(&at(n))))
                .collect(),
        )
    };
    vec![psnr, dense]
}

/// `(file, chart)` for every chart of the sweep.
pub fn charts(rows: &[Row]) -> Vec<(&'static str, Chart)> {
    let y_psnr = "PSNR against geometry (dB, pooled over the eyes)";
    vec![
        (
            "lightfield_density.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Error against camera-plane density{}",
                        slab_of(rows, "density")
                    ),
                    "uv samples per side",
                    y_psnr,
                    knob(rows, "density", |r| r.uv),
                )
                .log(true, false),
            ),
        ),
        (
            "lightfield_st.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Error against focal-plane resolution{}",
                        slab_of(rows, "st")
                    ),
                    "st samples per side",
                    y_psnr,
                    knob(rows, "st", |r| r.st),
                )
                .log(true, false),
            ),
        ),
        (
            "lightfield_compression.png",
            Chart::Lines(
                Lines::new(
                    "Error against compression (VQ then zstd; quadrilinear, depth-corrected)",
                    "compression ratio (raw file bytes / compressed file bytes)",
                    y_psnr,
                    vec![
                        compression(rows, "codebook"),
                        compression(rows, "tile"),
                        raw_point(rows),
                    ],
                )
                .log(true, false),
            ),
        ),
        (
            "lightfield_sparse.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Sparse capture rebinned against dense capture{}",
                        slab_of(rows, "sparse")
                    ),
                    "photographs (the dense capture at 1)",
                    y_psnr,
                    sparse(rows),
                )
                .log(true, false),
            ),
        ),
        (
            "lightfield_time_error.png",
            Chart::Scatter(
                Lines::new(
                    format!(
                        "Error against frame time, each eye and setting{}",
                        slab_of(rows, "geometry")
                    ),
                    "median frame time (ms); labels: uv x st samples",
                    "PSNR against geometry (dB)",
                    scatter(rows),
                )
                .log(true, false)
                .exact_at(99.0),
            ),
        ),
        (
            "lightfield_resolution.png",
            Chart::Lines(
                Lines::new(
                    "Frame time against resolution",
                    "pixels",
                    "median frame time (ms)",
                    against(rows, "resolution", |r| f64::from(r.width * r.height)),
                )
                .log(true, true),
            ),
        ),
        (
            "lightfield_triangles.png",
            Chart::Lines(
                Lines::new(
                    format!(
                        "Frame time against the object's triangles{}",
                        slab_of(rows, "triangles")
                    ),
                    "object triangles",
                    "median frame time (ms)",
                    against(rows, "triangles", |r| f64::from(r.triangles)),
                )
                .log(true, true),
            ),
        ),
    ]
}

/// The `lightfield` sweep (the module docs of [`super`]).
#[derive(Clone, Copy, Debug)]
pub struct LightfieldSweep;

impl Sweep for LightfieldSweep {
    const NAME: &'static str = "lightfield";
    const ABOUT: &'static str = "Light slabs against the geometry: error against sampling, lookup and compression; time against resolution and triangles";
    const ROWS: &'static str = "points";
    type Flags = RunFlags;
    type Settings = super::Settings;
    type Row = Row;

    fn settings(&self, flags: &RunFlags) -> Result<super::Settings, String> {
        Ok(flags.pick(
            super::Settings::tiny,
            super::Settings::quick,
            super::Settings::full,
        ))
    }

    fn rows(
        &self,
        settings: &super::Settings,
        _: &RunFlags,
        progress: Progress,
    ) -> Result<Vec<Row>, String> {
        Ok(super::run(settings, progress))
    }

    fn line(&self, r: &Row) -> Option<String> {
        let err = r.error.map_or(String::new(), |e| {
            format!(
                "PSNR {:>6.2} dB  off {:>5.2}%",
                e.psnr_capped(99.0),
                e.frac_over * 100.0
            )
        });
        let size = if r.file_bytes > 0 {
            format!(
                "  {:>6.1}:1 in memory  {:>7.1}:1 file  trained {:.1} s",
                r.raw_bytes as f64 / r.bytes.max(1) as f64,
                r.raw_file_bytes as f64 / r.file_bytes as f64,
                r.quantise_s
            )
        } else {
            String::new()
        };
        Some(format!(
            "{:<10} {:<15} {:<7} {} uv {:>2} st {:>3} K {:>5} {:<7} {:>7} tris {:>4}x{:<4} median {:>8.3} ms  {err}{size}",
            r.series,
            r.method,
            r.eye_class,
            r.eye,
            r.uv,
            r.st,
            r.codewords,
            r.tile,
            r.triangles,
            r.width,
            r.height,
            r.time.median_ms,
        ))
    }

    fn charts(&self, rows: &[Row]) -> Vec<(&'static str, Chart)> {
        charts(rows)
    }
}
