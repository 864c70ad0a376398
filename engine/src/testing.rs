//! Test support shared by the engine's unit tests: work run on a pool of a chosen number of
//! threads (how the tests check that a frame has the same pixels at any thread count).

/// Runs `f` on a new pool of `threads` threads and returns what it returns.
pub(crate) fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}
