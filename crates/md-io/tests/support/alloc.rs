//! A counting global allocator for test binaries: live and peak heap bytes per thread, a soft
//! cap that is recorded when crossed, and a hard cap past which an allocation is refused (the
//! process then aborts with std's "memory allocation of N bytes failed" instead of trying to
//! touch gigabytes).
//!
//! Std only, so any crate's tests can use it: a test binary declares
//! `#[global_allocator] static A: CountingAlloc = CountingAlloc;` and wraps the code under test
//! in [`measure`]. Counters are per thread (const thread-locals, which allocate nothing), so
//! tests running in parallel in one binary do not see each other's allocations.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

/// Refuse any allocation that would take a thread past this many live bytes while measured.
pub const HARD_CAP: usize = 1 << 30;

thread_local! {
    static LIVE: Cell<isize> = const { Cell::new(0) };
    static PEAK: Cell<isize> = const { Cell::new(0) };
    static ARMED: Cell<bool> = const { Cell::new(false) };
}

/// Counts every allocation of the thread that makes it, then hands it to the system allocator.
pub struct CountingAlloc;

/// Adds `n` bytes to the thread's live count; false if that crosses the hard cap while armed.
fn grow(n: usize) -> bool {
    LIVE.try_with(|live| {
        let v = live.get() + n as isize;
        if ARMED.try_with(Cell::get).unwrap_or(false) && v > HARD_CAP as isize {
            return false;
        }
        live.set(v);
        let _ = PEAK.try_with(|p| p.set(p.get().max(v)));
        true
    })
    .unwrap_or(true)
}

fn shrink(n: usize) {
    let _ = LIVE.try_with(|live| live.set(live.get() - n as isize));
}

// SAFETY: every call is forwarded to `System` with the same layout; the counters only observe.
unsafe impl GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if !grow(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: the caller's layout contract is passed on unchanged.
        let p = unsafe { System.alloc(layout) };
        if p.is_null() {
            shrink(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if !grow(layout.size()) {
            return std::ptr::null_mut();
        }
        // SAFETY: as in `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        if p.is_null() {
            shrink(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) };
        shrink(layout.size());
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let old = layout.size();
        if new_size > old && !grow(new_size - old) {
            return std::ptr::null_mut();
        }
        // SAFETY: `ptr` came from `System` with `layout`; the caller guarantees `new_size`.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            if new_size > old {
                shrink(new_size - old);
            }
        } else if new_size < old {
            shrink(old - new_size);
        }
        p
    }
}

/// Runs `f` on this thread and returns its result and the most heap bytes it held at once
/// (beyond what the thread held before). Allocations past [`HARD_CAP`] are refused meanwhile.
pub fn measure<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.with(Cell::get);
    PEAK.with(|p| p.set(base));
    ARMED.with(|a| a.set(true));
    let out = f();
    ARMED.with(|a| a.set(false));
    let peak = PEAK.with(Cell::get) - base;
    (out, peak.max(0) as usize)
}
