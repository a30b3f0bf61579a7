//! The global allocator of the Python extension: mimalloc for small blocks, the system
//! allocator for large ones.
//!
//! A 4-state Riccati solve makes about fifty short-lived matrices of a few hundred bytes,
//! aligned to 64 bytes as faer's matrices are. glibc's malloc serves aligned requests through
//! its slow path (`_int_memalign`, with chunk splitting and consolidation): 17 % of the whole
//! solve. mimalloc's thread-local size classes take a fraction of that, and serve rayon's
//! worker threads in the batch kernels without contention.
//!
//! Blocks of [`LARGE_BLOCK`] bytes and more go to the system allocator, whose cost is
//! negligible beside the O(n^3) work on a matrix that size, and which refuses an impossible
//! request at once: the core meets one when a caller passes a broadcast array of 10^10 entries,
//! and turns the refusal into MemoryError (mimalloc reserves address space for such a request
//! instead, and the tests that make one stalled).
//!
//! mimalloc reserves the address space of its arenas 1 GiB at a time by default, which made
//! `import aerocontrol` take 1.2 GB of address space, and a process under an address-space limit
//! (`ulimit -v`) short of it. The small blocks need a few megabytes; [`ARENA_RESERVE_KIB`] is
//! set when the library is loaded, before its first allocation.

use std::alloc::{GlobalAlloc, Layout, System};

/// The address space mimalloc reserves for an arena at a time, in KiB (its option
/// `arena_reserve`; it grows the reservation for later arenas).
pub const ARENA_RESERVE_KIB: std::ffi::c_long = 8 << 10;

/// `mi_option_arena_reserve` in the `mi_option_t` of the mimalloc that libmimalloc-sys 0.1.49
/// builds (v3; the crate's Rust constants stop before it). Cargo.toml pins that version.
const MI_OPTION_ARENA_RESERVE: libmimalloc_sys::mi_option_t = 23;

/// Sets mimalloc's options; runs when the library is loaded.
extern "C" fn configure_mimalloc() {
    // SAFETY: mi_option_set only stores the value of a valid option index.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_ARENA_RESERVE, ARENA_RESERVE_KIB) }
}

/// Runs [`configure_mimalloc`] when the shared library is loaded (an ELF initialiser), before
/// any code of the library allocates.
#[cfg(target_os = "linux")]
#[used]
#[unsafe(link_section = ".init_array")]
static CONFIGURE_MIMALLOC: extern "C" fn() = configure_mimalloc;

/// The same, as a Mach-O module initialiser.
#[cfg(target_os = "macos")]
#[used]
#[unsafe(link_section = "__DATA,__mod_init_func")]
static CONFIGURE_MIMALLOC: extern "C" fn() = configure_mimalloc;

/// Blocks of this many bytes or more come from the system allocator (a 90 x 90 matrix of
/// f64 is 64 800 bytes, below it).
pub const LARGE_BLOCK: usize = 1 << 16;

/// Small blocks from mimalloc, large ones from the system; a block is freed by the allocator
/// that made it, which its layout's size (the same at allocation and release) identifies.
pub struct SmallBlockAllocator;

fn is_small(layout: &Layout) -> bool {
    layout.size() < LARGE_BLOCK
}

// SAFETY: every method forwards to one of two allocators that uphold GlobalAlloc's contract,
// and a block always returns to (or is resized by) the allocator that made it: the routing
// depends only on the layout's size, which the caller passes unchanged to dealloc and realloc.
unsafe impl GlobalAlloc for SmallBlockAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded with the caller's guarantees (a layout of non-zero size).
        unsafe {
            if is_small(&layout) {
                mimalloc::MiMalloc.alloc(layout)
            } else {
                System.alloc(layout)
            }
        }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as for alloc.
        unsafe {
            if is_small(&layout) {
                mimalloc::MiMalloc.alloc_zeroed(layout)
            } else {
                System.alloc_zeroed(layout)
            }
        }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: ptr came from the allocator that the same layout selects.
        unsafe {
            if is_small(&layout) {
                mimalloc::MiMalloc.dealloc(ptr, layout)
            } else {
                System.dealloc(ptr, layout)
            }
        }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: ptr and layout are the caller's block; a resize within one allocator is
        // forwarded, a move between them copies the smaller of the two sizes and frees the old
        // block with the allocator that made it.
        unsafe {
            let new_layout = Layout::from_size_align_unchecked(new_size, layout.align());
            match (is_small(&layout), is_small(&new_layout)) {
                (true, true) => mimalloc::MiMalloc.realloc(ptr, layout, new_size),
                (false, false) => System.realloc(ptr, layout, new_size),
                _ => {
                    let new_ptr = self.alloc(new_layout);
                    if !new_ptr.is_null() {
                        std::ptr::copy_nonoverlapping(ptr, new_ptr, layout.size().min(new_size));
                        self.dealloc(ptr, layout);
                    }
                    new_ptr
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_move_between_the_allocators_intact() {
        let allocator = SmallBlockAllocator;
        let layout = Layout::from_size_align(1024, 64).expect("valid layout");
        // SAFETY: layouts of non-zero size; each block is freed once with its current layout.
        unsafe {
            let small = allocator.alloc(layout);
            assert!(!small.is_null());
            for i in 0..1024 {
                *small.add(i) = (i % 251) as u8;
            }
            let large = allocator.realloc(small, layout, 2 * LARGE_BLOCK);
            assert!(!large.is_null());
            assert!((0..1024).all(|i| *large.add(i) == (i % 251) as u8));
            let large_layout = Layout::from_size_align(2 * LARGE_BLOCK, 64).expect("valid");
            let back = allocator.realloc(large, large_layout, 512);
            assert!(!back.is_null());
            assert!((0..512).all(|i| *back.add(i) == (i % 251) as u8));
            allocator.dealloc(back, Layout::from_size_align(512, 64).expect("valid"));
        }
    }

    #[test]
    fn arenas_are_reserved_in_small_steps() {
        configure_mimalloc();
        // SAFETY: reads the value of a valid option index.
        let reserve = unsafe { libmimalloc_sys::mi_option_get(MI_OPTION_ARENA_RESERVE) };
        assert_eq!(reserve, ARENA_RESERVE_KIB);
    }

    #[test]
    fn an_impossible_request_is_refused() {
        let layout = Layout::from_size_align(1 << 46, 64).expect("valid layout");
        // SAFETY: a layout of non-zero size; a null result needs no release.
        let block = unsafe { SmallBlockAllocator.alloc(layout) };
        assert!(block.is_null());
    }
}
