//! A global allocator that refuses (a null pointer) every allocation past a size a test sets,
//! as the system does past an address-space limit: a buffer grown without asking the
//! allocator first then aborts the test program, so the test fails. A test program installs
//! it with `#[global_allocator]` and includes this file with `#[path]` (it is no module of
//! `common`, whose other programs keep the system allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, refusing any allocation larger than the limit set.
pub struct Refusing;

/// Largest allocation granted, in bytes.
static LARGEST: AtomicUsize = AtomicUsize::new(usize::MAX);

fn granted(bytes: usize) -> bool {
    bytes <= LARGEST.load(Ordering::Relaxed)
}

unsafe impl GlobalAlloc for Refusing {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        match granted(layout.size()) {
            true => unsafe { System.alloc(layout) },
            false => std::ptr::null_mut(),
        }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        match granted(layout.size()) {
            true => unsafe { System.alloc_zeroed(layout) },
            false => std::ptr::null_mut(),
        }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        match granted(new_size) {
            true => unsafe { System.realloc(ptr, layout, new_size) },
            false => std::ptr::null_mut(),
        }
    }
}

/// Runs `f` with no allocation past `largest` bytes granted. The limit is the whole
/// program's: call it holding [`serial`].
pub fn refusing_past<T>(largest: usize, f: impl FnOnce() -> T) -> T {
    LARGEST.store(largest, Ordering::Relaxed);
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    LARGEST.store(usize::MAX, Ordering::Relaxed);
    result.unwrap_or_else(|panic| std::panic::resume_unwind(panic))
}

/// Held by each test for its whole run: the limit is the whole program's.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}
