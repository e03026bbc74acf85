//! The program's memory: large blocks advised onto the kernel's transparent huge pages.
//!
//! Building the world of a million-triangle mesh writes ~300 MB of memory fresh from the
//! kernel: at 4 KiB a page, ~78,000 page faults, a fifth of the build's time on our test
//! machine (`BENCHMARKS.md`, session 28). Asking the kernel to back large blocks with 2 MiB
//! pages (`madvise(MADV_HUGEPAGE)`, as Embree does for its BVH memory and glibc's
//! `glibc.malloc.hugetlb=1` tunable does for every block it maps) leaves 14,000–16,000. The advice is
//! a hint: no byte of any result depends on it, and where the kernel has no huge pages to give
//! (or transparent huge pages are off, or this is not Linux) the allocator is the system's.
//!
//! The binary opts in: `#[global_allocator] static A: LargePageAlloc = LargePageAlloc;`.

use std::alloc::{GlobalAlloc, Layout, System};

/// Blocks at least this large are advised: smaller ones would hold at most one huge page.
pub const LARGE_BLOCK: usize = 4 << 20;
/// The size of a transparent huge page on x86-64 and most other processors Linux runs on.
const HUGE_PAGE: usize = 2 << 20;

/// The system allocator, with blocks of [`LARGE_BLOCK`] bytes or more advised onto huge pages.
#[derive(Clone, Copy, Debug, Default)]
pub struct LargePageAlloc;

#[allow(unsafe_code)]
// SAFETY: every block comes from and returns to `System` unchanged; `advise` only gives the
// kernel a hint about pages inside a block just allocated.
unsafe impl GlobalAlloc for LargePageAlloc {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is `System`'s.
        let p = unsafe { System.alloc(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as `alloc`.
        let p = unsafe { System.alloc_zeroed(layout) };
        advise(p, layout.size());
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        // SAFETY: `p` came from `System` with `layout`.
        unsafe { System.dealloc(p, layout) }
    }

    unsafe fn realloc(&self, p: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: `p` came from `System` with `layout`; the caller's contract is `System`'s.
        let q = unsafe { System.realloc(p, layout, new_size) };
        advise(q, new_size);
        q
    }
}

/// Advises the whole huge pages inside the `size` bytes at `p` onto huge pages, for blocks of
/// at least [`LARGE_BLOCK`] bytes. A failed advice changes nothing, so its result is ignored.
fn advise(p: *mut u8, size: usize) {
    if p.is_null() || size < LARGE_BLOCK {
        return;
    }
    let (start, end) = ((p as usize).next_multiple_of(HUGE_PAGE), (p as usize + size) / HUGE_PAGE * HUGE_PAGE);
    if end <= start {
        return;
    }
    #[cfg(target_os = "linux")]
    #[allow(unsafe_code)]
    // SAFETY: `start..end` lies inside a block this process owns; MADV_HUGEPAGE changes how
    // the kernel backs those pages, never their contents.
    unsafe {
        libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Large blocks keep what is written to them, come zeroed when asked, grow with their
    /// contents, and (on Linux with transparent huge pages) are marked for huge pages.
    #[test]
    #[allow(unsafe_code)]
    fn large_blocks_work_and_are_advised() {
        let size = 3 * LARGE_BLOCK;
        let layout = Layout::from_size_align(size, 64).unwrap();
        // SAFETY: a nonzero layout; the block is freed below with the layout it has then.
        unsafe {
            let p = LargePageAlloc.alloc_zeroed(layout);
            assert!(!p.is_null());
            let block = std::slice::from_raw_parts_mut(p, size);
            assert!(block.iter().all(|&b| b == 0));
            block.iter_mut().enumerate().for_each(|(i, b)| *b = i as u8);
            #[cfg(target_os = "linux")]
            if std::path::Path::new("/sys/kernel/mm/transparent_hugepage/enabled").exists() {
                assert!(advised(p as usize + HUGE_PAGE), "the block's middle is advised onto huge pages");
            }
            let q = LargePageAlloc.realloc(p, layout, 2 * size);
            let grown = std::slice::from_raw_parts(q, size);
            assert!(grown.iter().enumerate().all(|(i, &b)| b == i as u8));
            LargePageAlloc.dealloc(q, Layout::from_size_align(2 * size, 64).unwrap());
        }
        // Small blocks are the system's.
        let v: Vec<u8> = Vec::with_capacity(100);
        assert!(v.capacity() >= 100);
    }

    /// The mapping holding `address` has the kernel's huge-page advice flag (`hg` in its
    /// `VmFlags` in `/proc/self/smaps`).
    #[cfg(target_os = "linux")]
    fn advised(address: usize) -> bool {
        let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
        let mut inside = false;
        for line in smaps.lines() {
            if let Some((range, _)) = line.split_once(' ')
                && let Some((lo, hi)) = range.split_once('-')
                && let (Ok(lo), Ok(hi)) = (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
            {
                inside = (lo..hi).contains(&address);
            } else if inside && let Some(flags) = line.strip_prefix("VmFlags:") {
                return flags.split_whitespace().any(|f| f == "hg");
            }
        }
        false
    }
}
