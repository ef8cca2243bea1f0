//! A counting global allocator for the test binary: every thread tracks the bytes it holds
//! now and the most it held, so a test can measure the peak of a single-threaded call.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// `System`, counting per thread.
pub struct Counting;

thread_local! {
    static CURRENT: Cell<usize> = const { Cell::new(0) };
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

fn add(n: usize) {
    // try_with: the thread's slots may be gone while it is being torn down.
    let _ = CURRENT.try_with(|c| {
        let now = c.get().saturating_add(n);
        c.set(now);
        let _ = PEAK.try_with(|p| p.set(p.get().max(now)));
    });
}

fn sub(n: usize) {
    // Memory freed on another thread than it was allocated on: never below zero.
    let _ = CURRENT.try_with(|c| c.set(c.get().saturating_sub(n)));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            add(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            add(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        sub(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            // Counted as the old block and the new one side by side: a copying realloc
            // holds both for a moment.
            add(new_size);
            sub(layout.size());
        }
        p
    }
}

/// Runs `f` and returns its result and the most bytes this thread held during it beyond
/// what it held before.
pub fn peak_during<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let base = CURRENT.with(|c| c.get());
    PEAK.with(|p| p.set(base));
    let r = f();
    let peak = PEAK.with(|p| p.get());
    (r, peak.saturating_sub(base))
}

#[test]
fn counts_an_allocation() {
    let (v, peak) = peak_during(|| vec![1u8; 10 << 20]);
    assert_eq!(v.len(), 10 << 20);
    assert!((10 << 20..11 << 20).contains(&peak), "peak {peak}");
    drop(v);
    let ((), small) = peak_during(|| {});
    assert!(small < 1 << 10, "nothing allocated, peak {small}");
}
