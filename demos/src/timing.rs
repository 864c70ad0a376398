//! Frame-time statistics: median, minimum, 90th percentile and mean of a set of samples.
//!
//! The binaries time `Renderer::render` with `std::time::Instant` and summarise here, so
//! the showcase, the bench CLI and the tests agree on what "median" and "p90" mean
//! (nearest-rank percentiles on the sorted samples).

use std::time::Duration;

/// A summary of frame times, in milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    pub frames: usize,
    pub median_ms: f64,
    pub min_ms: f64,
    pub p90_ms: f64,
    pub mean_ms: f64,
}

/// Nearest-rank percentile `q` in [0, 1] of sorted samples.
fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (q * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

impl Summary {
    /// Summarises samples (any order); all zeros when there are none.
    pub fn of(samples: &[Duration]) -> Summary {
        let mut ms: Vec<f64> = samples.iter().map(|d| d.as_secs_f64() * 1e3).collect();
        ms.sort_by(f64::total_cmp);
        if ms.is_empty() {
            return Summary::default();
        }
        let median = if ms.len() % 2 == 1 {
            ms[ms.len() / 2]
        } else {
            0.5 * (ms[ms.len() / 2 - 1] + ms[ms.len() / 2])
        };
        Summary {
            frames: ms.len(),
            median_ms: median,
            min_ms: ms[0],
            p90_ms: percentile(&ms, 0.9),
            mean_ms: ms.iter().sum::<f64>() / ms.len() as f64,
        }
    }
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} frames: median {:.2} ms, min {:.2} ms, p90 {:.2} ms, mean {:.2} ms",
            self.frames, self.median_ms, self.min_ms, self.p90_ms, self.mean_ms
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: &[u64]) -> Vec<Duration> {
        v.iter().map(|&m| Duration::from_millis(m)).collect()
    }

    #[test]
    fn median_min_p90() {
        let s = Summary::of(&ms(&[5, 1, 3, 2, 4, 10, 6, 7, 8, 9]));
        assert_eq!(s.frames, 10);
        assert_eq!(s.min_ms, 1.0);
        assert_eq!(s.median_ms, 5.5);
        assert_eq!(s.p90_ms, 9.0);
        let odd = Summary::of(&ms(&[3, 1, 2]));
        assert_eq!(odd.median_ms, 2.0);
        assert_eq!(odd.p90_ms, 3.0);
        assert_eq!(Summary::of(&[]), Summary::default());
    }
}
