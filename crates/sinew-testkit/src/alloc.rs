//! A counting global allocator: every allocation a test binary makes is counted, so a test can
//! show that evaluating a configuration allocates nothing once the workspace exists.
//!
//! Install it once per test binary, then count around the calls:
//!
//! ```
//! use sinew_testkit::alloc::{CountingAllocator, assert_counting, count};
//!
//! #[global_allocator]
//! static GLOBAL: CountingAllocator = CountingAllocator;
//!
//! fn main() {
//!     assert_counting();
//!     let buffer = vec![1.0_f64; 8];
//!     let (allocations, sum) = count(|| buffer.iter().sum::<f64>());
//!     assert_eq!((allocations, sum), (0, 8.0));
//! }
//! ```
//!
//! The counter is global (every thread), as the allocations it must catch may happen on any
//! thread. So a counting test binary is a plain one (`harness = false` for its `[[test]]` in
//! Cargo.toml, its checks called one after another from `main`): libtest's own thread
//! allocates for its bookkeeping (starting a test, recording a result) while a test runs, and
//! the counter would count it, now and then (about one run in 200 on a loaded machine).
// The workspace denies unsafe code; `GlobalAlloc` is an unsafe trait, and this module is the
// one place it is implemented, forwarding every call unchanged to the system allocator.
#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

/// The system allocator, counting allocations and reallocations (frees are not counted).
#[derive(Debug, Clone, Copy, Default)]
pub struct CountingAllocator;

// SAFETY: forwards to the system allocator; only counts.
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as the caller's.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

/// Allocations counted so far (0 for ever when [`CountingAllocator`] is not the global one).
pub fn allocations() -> usize {
    ALLOCATIONS.load(Ordering::SeqCst)
}

/// Run `f` and return the allocations it made (with its result).
pub fn count<R>(f: impl FnOnce() -> R) -> (usize, R) {
    let before = allocations();
    let result = f();
    (allocations() - before, result)
}

/// Panic unless `CountingAllocator` is the global allocator of this binary: allocate once and
/// check that the counter saw it, so that a zero count means something.
pub fn assert_counting() {
    let (n, v) = count(|| std::hint::black_box(vec![0u8; 64]));
    drop(v);
    assert!(n > 0, "the counter counts nothing: is CountingAllocator the #[global_allocator]?");
}
