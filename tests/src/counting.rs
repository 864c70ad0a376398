//! A counting global allocator for the "allocates nothing once warm" tests: a test binary
//! installs [`Counting`] as its `#[global_allocator]` and wraps the work it checks in
//! [`count`]. Only allocations (and reallocations) made by threads taking part are counted:
//! the calling thread and the workers of a pool built with [`tracked_pool`]. Set
//! `ALLOC_BACKTRACE=1` to keep where the first few counted allocations came from
//! ([`traces`]).
//!
//! Each such test binary holds a single test, so no other test allocates in the process
//! while it counts. This is the only `unsafe` outside `engine/src/simd.rs`: a global
//! allocator needs `unsafe impl GlobalAlloc`, and it only forwards to the system allocator.

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// The counting allocator: install with `#[global_allocator] static A: Counting = Counting;`.
#[derive(Debug)]
pub struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static COUNT: AtomicUsize = AtomicUsize::new(0);
static BACKTRACES: AtomicBool = AtomicBool::new(false);
static TRACES: Mutex<Vec<String>> = Mutex::new(Vec::new());
/// The sizes of the first counted allocations (0: none), kept without backtraces (cheap,
/// so a rare allocation that a backtrace's cost would hide still says its size).
static SIZES: [AtomicUsize; 4] = [const { AtomicUsize::new(0) }; 4];
const MAX_TRACES: usize = 8;

thread_local! {
    /// This thread's allocations count (the counting thread and a tracked pool's workers).
    static TRACKED: Cell<bool> = const { Cell::new(false) };
    /// Inside the allocator's own bookkeeping (capturing a backtrace allocates).
    static INSIDE: Cell<bool> = const { Cell::new(false) };
}

fn note(size: usize) {
    if !COUNTING.load(Ordering::SeqCst) || !TRACKED.with(Cell::get) || INSIDE.with(Cell::get) {
        return;
    }
    let k = COUNT.fetch_add(1, Ordering::SeqCst);
    if let Some(slot) = SIZES.get(k) {
        slot.store(size, Ordering::SeqCst);
    }
    if BACKTRACES.load(Ordering::SeqCst) {
        INSIDE.with(|i| i.set(true));
        if let Ok(mut t) = TRACES.lock() {
            if t.len() < MAX_TRACES {
                let bt = std::backtrace::Backtrace::force_capture();
                t.push(format!("allocation of {size} bytes:\n{bt}"));
            }
        }
        INSIDE.with(|i| i.set(false));
    }
}

// SAFETY: every method forwards its arguments unchanged to `System`, which upholds the
// `GlobalAlloc` contract; the counting only touches atomics and thread-locals.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        System.alloc_zeroed(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

/// A pool of `threads` workers whose allocations count, warmed up: each worker has taken a
/// job from its own queue once. A worker's first steal registers it with the work-stealing
/// deque's epoch collector (crossbeam-epoch), a one-time allocation of 2,304 bytes; a
/// worker that happened not to steal while a test warmed up would otherwise make it while
/// the test counts (seen in about one run in twenty).
pub fn tracked_pool(threads: usize) -> rayon::ThreadPool {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| TRACKED.with(|t| t.set(true)))
        .build()
        .expect("pool");
    // A broadcast reaches every worker through its own queue, which it steals from.
    pool.broadcast(|_| ());
    pool
}

/// Runs `f` with counting on for this thread (and tracked pools' workers); returns its
/// result and the allocations counted. With `ALLOC_BACKTRACE=1`, keeps backtraces.
pub fn count<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let traces = std::env::var("ALLOC_BACKTRACE").is_ok_and(|v| v == "1");
    TRACKED.with(|t| t.set(true));
    if let Ok(mut t) = TRACES.lock() {
        t.clear();
    }
    BACKTRACES.store(traces, Ordering::SeqCst);
    COUNT.store(0, Ordering::SeqCst);
    for slot in &SIZES {
        slot.store(0, Ordering::SeqCst);
    }
    COUNTING.store(true, Ordering::SeqCst);
    let r = f();
    COUNTING.store(false, Ordering::SeqCst);
    BACKTRACES.store(false, Ordering::SeqCst);
    (r, COUNT.load(Ordering::SeqCst))
}

/// The sizes of the first allocations the last [`count`] counted, and the backtraces it
/// kept (none unless `ALLOC_BACKTRACE=1`).
pub fn traces() -> String {
    let sizes: Vec<usize> = SIZES
        .iter()
        .map(|s| s.load(Ordering::SeqCst))
        .take_while(|&s| s > 0)
        .collect();
    let kept = TRACES.lock().map(|t| t.join("\n")).unwrap_or_default();
    format!("sizes of the first allocations: {sizes:?}\n{kept}")
}
