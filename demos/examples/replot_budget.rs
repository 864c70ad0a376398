//! Redraws the `bench budget` charts from a `budget.csv` the sweep wrote, without
//! re-running it (the full sweep takes about 20 minutes): the figures stay those of the run
//! that wrote the CSV; only the drawing is new.
//!
//! ```sh
//! cargo run --release -p demos --example replot_budget -- docs/bench/budget.csv docs/bench
//! ```

use demos::bench::budget::{charts, Row};
use demos::timing::Summary;
use std::collections::HashMap;
use std::path::Path;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [csv, out] = args.as_slice() else {
        return Err("usage: replot_budget BUDGET_CSV OUT_DIR".into());
    };
    let text = std::fs::read_to_string(csv).map_err(|e| format!("{csv}: {e}"))?;
    let rows = parse(&text).map_err(|e| format!("{csv}: {e}"))?;
    std::fs::create_dir_all(out).map_err(|e| format!("{out}: {e}"))?;
    for (file, chart) in charts(&rows) {
        let path = Path::new(out).join(file);
        demos::chart::draw(&path, &chart).map_err(|e| format!("{}: {e}", path.display()))?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

/// The rows of a `budget.csv`, by its header's column names.
fn parse(text: &str) -> Result<Vec<Row>, String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty file")?.split(',').collect();
    let mut rows = Vec::new();
    for (n, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let cells: HashMap<&str, &str> = header.iter().copied().zip(line.split(',')).collect();
        let text = |k: &str| {
            cells
                .get(k)
                .copied()
                .ok_or_else(|| format!("row {}: no column {k}", n + 2))
        };
        let num = |k: &str| -> Result<f64, String> {
            text(k)?
                .parse::<f64>()
                .map_err(|e| format!("row {}: column {k}: {e}", n + 2))
        };
        let later = |k: &str| match cells.contains_key(k) {
            true => num(k),
            false => Ok(0.0),
        };
        // The chart code keys series by these names; the CSV holds few distinct ones.
        let leak = |s: &str| -> &'static str { Box::leak(s.to_string().into_boxed_str()) };
        rows.push(Row {
            scene: leak(text("scene")?),
            method: leak(text("method")?),
            budget: num("budget")? as f32,
            objects: num("objects")? as usize,
            triangles: num("triangles")? as usize,
            width: num("width")? as u32,
            height: num("height")? as u32,
            time: Summary {
                frames: num("frames")? as usize,
                median_ms: num("median_ms")?,
                mean_ms: num("mean_ms")?,
                ..Summary::default()
            },
            measured_mean: num("measured_mean")?,
            measured_p99: num("measured_p99")?,
            within: num("within")?,
            objects_over: num("objects_over")?,
            psnr_db: num("psnr_db")?,
            predicted_mean: num("predicted_mean")?,
            predicted_max: num("predicted_max")?,
            predicted_bound: num("predicted_bound")?,
            spread_fit: num("spread_fit")?,
            geometry_per_frame: num("geometry_per_frame")?,
            images_per_frame: num("images_per_frame")?,
            mix: text("mix")?.to_string(),
            switches_per_frame: num("switches_per_frame")?,
            rebuilds_per_frame: num("rebuilds_per_frame")?,
            memory_mb: num("memory_mb")?,
            planning_ms: num("planning_ms")?,
            // Columns added in session 12: 0 in older files.
            planning_p99_ms: later("planning_p99_ms")?,
            planning_max_ms: later("planning_max_ms")?,
            planning_within: later("planning_within")?,
            // Session 19: 0 in older files.
            covered: later("covered")?,
            sky: later("sky")?,
        });
    }
    Ok(rows)
}
