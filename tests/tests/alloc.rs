//! Zero allocations after the first frame: once a renderer has drawn a scene into a target,
//! drawing the same scene again allocates nothing.
//!
//! A counting global allocator counts allocations (and reallocations) made while
//! `COUNTING` is on by threads marked as taking part: the thread calling `render` and the
//! rayon pool's workers. Set `ALLOC_BACKTRACE=1` to print where the first few counted
//! allocations came from.
//!
//! This file holds a single test, so no other test runs in the process while it counts.

// A global allocator needs `unsafe impl GlobalAlloc`; the unsafe here only forwards to the
// system allocator.
#![allow(unsafe_code)]

use engine::{FrameOptions, Renderer, Rgba, Target};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use tests::busy::busy_scene;

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static COUNT: AtomicUsize = AtomicUsize::new(0);
static BACKTRACES: AtomicBool = AtomicBool::new(false);
static TRACES: Mutex<Vec<String>> = Mutex::new(Vec::new());
const MAX_TRACES: usize = 8;

thread_local! {
    /// This thread's allocations count (the render thread and the pool's workers).
    static TRACKED: Cell<bool> = const { Cell::new(false) };
    /// Inside the allocator's own bookkeeping (capturing a backtrace allocates).
    static INSIDE: Cell<bool> = const { Cell::new(false) };
}

fn note(size: usize) {
    if !COUNTING.load(Ordering::SeqCst) || !TRACKED.with(Cell::get) || INSIDE.with(Cell::get) {
        return;
    }
    COUNT.fetch_add(1, Ordering::SeqCst);
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
// `GlobalAlloc` contract; the counting only touches atomics and a thread-local flag.
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

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Renders the busy scene once while counting (to show the counter works), `warmup - 1`
/// more times, then once more while counting (with backtraces if asked for). Returns the
/// first and the last frame's counts.
fn check_second_frame_allocations(threads: usize, warmup: usize) -> (usize, usize) {
    let want_traces = std::env::var("ALLOC_BACKTRACE").is_ok_and(|v| v == "1");
    let (w, h) = (320, 200);
    let (scene, camera) = busy_scene(w, h);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| TRACKED.with(|t| t.set(true)))
        .build()
        .expect("pool");
    let mut renderer = Renderer::new();
    let mut target = Target::new(w, h);
    let opts = FrameOptions {
        clear: Some(Rgba::new(0.1, 0.1, 0.1, 1.0)),
        ..Default::default()
    };
    pool.install(|| {
        TRACKED.with(|t| t.set(true));
        let mut counted = |traces: bool| {
            BACKTRACES.store(traces, Ordering::SeqCst);
            COUNT.store(0, Ordering::SeqCst);
            COUNTING.store(true, Ordering::SeqCst);
            let stats = renderer.render_scene(&scene, &camera, &mut target, &opts);
            COUNTING.store(false, Ordering::SeqCst);
            BACKTRACES.store(false, Ordering::SeqCst);
            assert!(stats.fragments_written > 0, "{stats:?}");
            COUNT.load(Ordering::SeqCst)
        };
        let first = counted(false);
        for _ in 1..warmup {
            counted(false);
        }
        (first, counted(want_traces))
    })
}

#[test]
fn second_frame_allocates_nothing() {
    let (first, second) = check_second_frame_allocations(2, 1);
    assert!(
        first > 0,
        "the counter saw no allocation in the first frame: it is not counting"
    );
    let traces = TRACES.lock().map(|t| t.join("\n")).unwrap_or_default();
    assert_eq!(
        second, 0,
        "the second frame allocated {second} times (run with ALLOC_BACKTRACE=1 to see where)\n{traces}"
    );
}
