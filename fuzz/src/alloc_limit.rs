//! A global allocator that aborts on any single request over [`LIMIT`] bytes,
//! so that huge allocations are findings even when their memory is never touched.

use std::alloc::{GlobalAlloc, Layout, System};

/// The largest single allocation allowed: 2 GiB, the campaign's `-rss_limit_mb`.
pub const LIMIT: usize = 2 << 30;

struct Limited;

#[cold]
fn too_large(size: usize) -> ! {
    // No allocation here: format into a fixed buffer, then abort (a crash for libFuzzer).
    use std::io::Write;
    let mut buf = [0u8; 96];
    let mut w = &mut buf[..];
    let _ = write!(w, "abgs-fuzz: allocation of {size} bytes exceeds 2 GiB\n");
    let n = 96 - w.len();
    let _ = std::io::stderr().write_all(&buf[..n]);
    std::process::abort();
}

// SAFETY: forwards to the system allocator; only refuses (by aborting) large requests.
unsafe impl GlobalAlloc for Limited {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.size() > LIMIT {
            too_large(layout.size());
        }
        // SAFETY: forwarded contract.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() > LIMIT {
            too_large(layout.size());
        }
        // SAFETY: forwarded contract.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded contract.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > LIMIT {
            too_large(new_size);
        }
        // SAFETY: forwarded contract.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Limited = Limited;
