//! Frame-time statistics: median, minimum, 90th percentile and mean of a set of samples.
//!
//! The binaries time `Renderer::render` with `std::time::Instant` and summarise here, so
//! the showcase, the bench CLI and the tests agree on what "median" and "p90" mean
//! (nearest-rank percentiles on the sorted samples). [`Usage`] is what a stretch of work
//! cost the process in CPU time and page faults: on this shared 2-core machine wall times
//! move with the other processes' load, these much less.

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

/// What the process has used so far: the CPU time of all its threads (their
/// `/proc/self/task/*/schedstat` run times, nanoseconds; idle pool workers' spinning
/// counts), that of the calling thread alone (`/proc/thread-self/schedstat`: work it did
/// itself, not waiting on the pool, which sleeps) and the process's minor page faults
/// (`/proc/self/stat`). Zero where `/proc` cannot be read (not Linux). [`Usage::since`]
/// makes it the cost of a stretch of work.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Usage {
    pub cpu: Duration,
    pub caller_cpu: Duration,
    pub faults: u64,
}

/// The first number of a `schedstat` file: the time its thread ran, nanoseconds.
fn run_ns(path: impl AsRef<std::path::Path>) -> Option<u64> {
    let s = std::fs::read_to_string(path).ok()?;
    s.split_whitespace().next()?.parse().ok()
}

impl Usage {
    /// The process's usage now.
    pub fn now() -> Usage {
        let tasks = std::fs::read_dir("/proc/self/task").into_iter().flatten();
        let cpu: u64 = (tasks.flatten())
            .filter_map(|t| run_ns(t.path().join("schedstat")))
            .sum();
        let caller = run_ns("/proc/thread-self/schedstat").unwrap_or(0);
        // The fields after the command's closing parenthesis start at the third (state);
        // minor faults are the tenth.
        let faults = std::fs::read_to_string("/proc/self/stat")
            .ok()
            .and_then(|s| {
                s.rsplit_once(')')?
                    .1
                    .split_whitespace()
                    .nth(7)?
                    .parse()
                    .ok()
            })
            .unwrap_or(0);
        Usage {
            cpu: Duration::from_nanos(cpu),
            caller_cpu: Duration::from_nanos(caller),
            faults,
        }
    }

    /// What was used from `earlier` to `self` (zero where a count went back: a thread
    /// that ended took its CPU time with it).
    pub fn since(self, earlier: Usage) -> Usage {
        Usage {
            cpu: self.cpu.saturating_sub(earlier.cpu),
            caller_cpu: self.caller_cpu.saturating_sub(earlier.caller_cpu),
            faults: self.faults.saturating_sub(earlier.faults),
        }
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

    #[test]
    fn usage_counts_cpu_and_faults_of_work() {
        let before = Usage::now();
        // Fresh pages touched (a page fault each), and some CPU spent on them.
        let mut v = vec![0u8; 64 << 20];
        for b in v.iter_mut().step_by(4096) {
            *b = 1;
        }
        let sum: u64 = v.iter().map(|&b| b as u64).sum();
        let used = Usage::now().since(before);
        assert_eq!(sum, 64 << 8);
        if cfg!(target_os = "linux") {
            assert!(used.faults >= 1000, "{used:?}");
            assert!(used.cpu > Duration::ZERO, "{used:?}");
            // The work was this thread's own.
            assert!(used.caller_cpu > Duration::ZERO, "{used:?}");
        }
        assert_eq!(before.since(Usage::now()).faults, 0);
    }
}
