//! The viewer's heap policy: large buffers go back to the system when freed.
//!
//! glibc's malloc gives a block of at least `M_MMAP_THRESHOLD` bytes its own
//! mapping, unmapped on free; but by default the threshold rises to the size
//! of each such block freed (up to 32 MiB), after which the per-pixel buffers
//! of the next window size (tens of MiB; the old ones are freed on every
//! resize, screenshot and frame) come from the per-thread arenas, and the
//! arenas keep the freed pages resident: the soak's RSS rose with every new
//! size although the live heap did not (docs/performance.md, "Viewer memory").
//! A fixed threshold turns the rise off, so every buffer of 1 MiB or more
//! (a window of about 40 000 pixels) is its own mapping.

/// Blocks of this many bytes or more are mapped on their own.
pub const LARGE_BLOCK: usize = 1 << 20;

/// Fixes glibc's mmap threshold at [`LARGE_BLOCK`]; true when it was set
/// (false on other C libraries, whose allocators have no such rise).
pub fn return_large_blocks() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only sets one of malloc's tuning numbers; it takes
        // no pointer and glibc serialises it with the arenas' own locks.
        unsafe { libc::mallopt(libc::M_MMAP_THRESHOLD, LARGE_BLOCK as libc::c_int) == 1 }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

#[cfg(all(test, target_os = "linux", target_env = "gnu"))]
mod tests {
    use super::*;

    /// Whether glibc serves `b` with its own mapping: a mapped block has
    /// the rest of its last page to spare, an arena block at most 24 bytes.
    fn mapped(b: &[u8]) -> bool {
        // SAFETY: `b` is a live block of the global allocator, which is the
        // system's malloc here (no #[global_allocator] in this binary; align 1).
        let usable = unsafe { libc::malloc_usable_size(b.as_ptr() as *mut libc::c_void) };
        usable >= b.len() + 1024
    }

    #[test]
    fn a_large_block_stays_mapped_after_a_larger_one_was_freed() {
        assert!(return_large_blocks());
        // Without the fixed threshold, freeing this 8 MiB mapping would
        // raise it to 8 MiB and the 2 MiB block below would come from an arena.
        let big = vec![1u8; 8 << 20];
        assert!(mapped(&big));
        drop(big);
        let next = vec![1u8; 2 << 20];
        assert!(mapped(&next), "a 2 MiB block came from an arena");
        let small = vec![1u8; LARGE_BLOCK / 4];
        assert!(!mapped(&small), "a 256 KiB block was mapped on its own");
    }
}
