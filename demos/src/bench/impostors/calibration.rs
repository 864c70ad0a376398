//! The `calibration` series: images age without refresh along `translate`, and each
//! image's predicted parallax is set against its measured error.

use super::row::{Errors, PredictedStats, Row};
use super::scene::{fly, Policy};
use super::Settings;
use crate::bench::scaling::fit_line;
use crate::chart::{Line, Lines};
use crate::city::{City, Path as CityPath};

/// One `calibration` row per image per frame after warm-up of a run along `translate`
/// with refreshes disabled after the warm-up.
pub(super) fn run(
    settings: &Settings,
    city: &mut City,
    tick: &mut dyn FnMut(String),
    rows: &mut Vec<Row>,
) {
    tick("calibration".into());
    let n = city.buildings.len();
    let path = CityPath::Translate;
    let out = fly(settings, city, path, Policy::Frozen);
    for (k, frame) in out.measured.iter().enumerate() {
        for &(i, p, e) in frame {
            rows.push(Row {
                frame: Some(k + 1),
                impostor: Some(i),
                frames: 1,
                errors: Some(Errors::of_frames(&[vec![e]])),
                predicted: Some(PredictedStats {
                    deg_mean: p.degrees as f64,
                    deg_max: p.degrees as f64,
                    px_mean: p.pixels as f64,
                    levels_mean: p.levels as f64,
                }),
                ..Row::empty("calibration", path, "frozen".into(), settings, n)
            });
        }
    }

    // Methods on the orbit.
}

/// The calibration scatter: predicted parallax against each image's measured error, and
/// the means of 8 equal-width bins of predicted parallax.
pub fn calibration_chart(rows: &[Row]) -> Lines {
    let pts = calibration_points(rows);
    let bins = calibration_bins(&pts, 8);
    Lines::new(
        "Predicted parallax vs measured error (translate, no refresh after warm-up)",
        "predicted parallax (degrees)",
        "measured mean abs. error (8-bit levels)",
        vec![
            Line::new("one image in one frame", pts),
            Line::new(
                "mean of a bin of predicted parallax",
                bins.iter().map(|b| (b.0, b.1)).collect(),
            ),
        ],
    )
}

/// The calibration rows' (predicted degrees, measured mean absolute error) pairs.
pub fn calibration_points(rows: &[Row]) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.series == "calibration")
        .filter_map(|r| Some((r.predicted?.deg_mean, r.errors?.mae_mean)))
        .collect()
}

/// The calibration pairs in `bins` equal-width bins of predicted degrees (empty bins left
/// out): mean predicted degrees, mean measured error, and the pairs in the bin.
pub fn calibration_bins(points: &[(f64, f64)], bins: usize) -> Vec<(f64, f64, usize)> {
    let hi = points.iter().map(|p| p.0).fold(0.0, f64::max);
    let bins = bins.max(1);
    let mut acc = vec![(0.0, 0.0, 0usize); bins];
    for &(x, y) in points {
        let k = if hi > 0.0 {
            ((x / hi * bins as f64) as usize).min(bins - 1)
        } else {
            0
        };
        acc[k].0 += x;
        acc[k].1 += y;
        acc[k].2 += 1;
    }
    acc.into_iter()
        .filter(|a| a.2 > 0)
        .map(|(x, y, n)| (x / n as f64, y / n as f64, n))
        .collect()
}

/// Pearson's correlation of the pairs (`None` for fewer than 2 or a constant coordinate).
pub fn correlation(points: &[(f64, f64)]) -> Option<f64> {
    let n = points.len() as f64;
    if points.len() < 2 {
        return None;
    }
    let (mx, my) = (
        points.iter().map(|p| p.0).sum::<f64>() / n,
        points.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for &(x, y) in points {
        sxy += (x - mx) * (y - my);
        sxx += (x - mx) * (x - mx);
        syy += (y - my) * (y - my);
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

/// Least-squares slope of y on x (`None` for fewer than 2 points or a constant x).
pub fn slope(points: &[(f64, f64)]) -> Option<f64> {
    fit_line(points).map(|f| f.slope)
}
/// Per impostor of the calibration run: (impostor, Pearson r, slope in levels per
/// degree, pairs), for impostors with at least 3 pairs.
pub fn calibration_per_impostor(rows: &[Row]) -> Vec<(usize, f64, f64, usize)> {
    let mut by: std::collections::BTreeMap<usize, Vec<(f64, f64)>> = Default::default();
    for r in rows.iter().filter(|r| r.series == "calibration") {
        if let (Some(i), Some(p), Some(e)) = (r.impostor, r.predicted, r.errors) {
            by.entry(i).or_default().push((p.deg_mean, e.mae_mean));
        }
    }
    by.into_iter()
        .filter(|(_, v)| v.len() >= 3)
        .filter_map(|(i, v)| Some((i, correlation(&v)?, slope(&v)?, v.len())))
        .collect()
}

/// A paragraph on the calibration run: correlation over all pairs and per impostor, and
/// binned means.
pub fn calibration_summary(rows: &[Row]) -> Option<String> {
    let pts = calibration_points(rows);
    if pts.is_empty() {
        return None;
    }
    let mut s = format!(
        "calibration: {} images; Pearson r (predicted degrees, measured MAE) = {}",
        pts.len(),
        correlation(&pts).map_or("n/a".into(), |r| format!("{r:.3}"))
    );
    let per = calibration_per_impostor(rows);
    if !per.is_empty() {
        let mut r: Vec<f64> = per.iter().map(|p| p.1).collect();
        let mut k: Vec<f64> = per.iter().map(|p| p.2).collect();
        r.sort_by(f64::total_cmp);
        k.sort_by(f64::total_cmp);
        s += &format!(
            "\n  per impostor ({}): r min {:.3}, median {:.3}; slope {:.3} to {:.3} levels per degree (median {:.3})",
            per.len(),
            r[0],
            r[r.len() / 2],
            k[0],
            k[k.len() - 1],
            k[k.len() / 2]
        );
    }
    for (x, y, n) in calibration_bins(&pts, 8) {
        s += &format!("\n  predicted {x:>7.3} deg: measured MAE {y:>7.3} ({n} images)");
    }
    let lv = calibration_levels(rows);
    let under = lv.iter().filter(|p| p.1 <= p.0).count();
    s += &format!(
        "\n  in image units: Pearson r (predicted MAE, measured MAE) = {}; measured at most \
         predicted on {under} of {} images ({:.1}%)",
        correlation(&lv).map_or("n/a".into(), |r| format!("{r:.3}")),
        lv.len(),
        100.0 * under as f64 / lv.len().max(1) as f64
    );
    Some(s)
}

/// The calibration rows' (predicted image error, measured mean absolute error) pairs, both
/// in 8-bit levels.
pub fn calibration_levels(rows: &[Row]) -> Vec<(f64, f64)> {
    rows.iter()
        .filter(|r| r.series == "calibration")
        .filter_map(|r| Some((r.predicted?.levels_mean, r.errors?.mae_mean)))
        .collect()
}

/// The calibration in image units: each image's predicted against measured error, with
/// the line where they are equal (the prediction should lie above almost every point).
pub fn calibration_levels_chart(rows: &[Row]) -> Lines {
    let pts = calibration_levels(rows);
    let hi = pts.iter().map(|p| p.0.max(p.1)).fold(0.0, f64::max);
    Lines::new(
        "Predicted vs measured image error (translate, no refresh after warm-up)",
        "predicted mean abs. error (8-bit levels)",
        "measured mean abs. error (8-bit levels)",
        vec![
            Line::new("one image in one frame", pts),
            Line::reference("measured = predicted", vec![(0.0, 0.0), (hi, hi)]),
        ],
    )
}
