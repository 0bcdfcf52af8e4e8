//! Large geometry arrays on transparent huge pages. Incoherent rays touch BVH nodes and
//! triangles all over tens of megabytes, and with 4 KiB pages most of those reads also miss
//! the TLB. Linux backs a fresh mapping with 2 MiB pages when asked (`madvise(MADV_HUGEPAGE)`,
//! honoured when `/sys/kernel/mm/transparent_hugepage/enabled` is `always` or `madvise`), as
//! Embree does for its BVH. Memory the allocator hands out again has usually been touched
//! already, so such arrays get a mapping of their own. Elsewhere, for small arrays, or when
//! the mapping fails, this is an ordinary `Vec`.

use std::ops::{Deref, DerefMut};

/// Arrays smaller than this stay on the heap.
#[cfg(target_os = "linux")]
const MIN_BYTES: usize = 4 << 20;

#[cfg(target_os = "linux")]
const HUGE_PAGE: usize = 2 << 20;

/// A fixed-length array of `Copy` items, on huge pages where available.
pub(super) struct HugeArray<T: Copy> {
    heap: Vec<T>,
    /// (mapping start, mapping bytes, items) when the items live in a mapping of their own.
    #[cfg(target_os = "linux")]
    mapped: Option<(*mut libc::c_void, usize, *mut T, usize)>,
}

// SAFETY: the mapping is owned exclusively, like a Vec's buffer.
unsafe impl<T: Copy + Send> Send for HugeArray<T> {}
// SAFETY: shared access only reads, like a Vec's buffer.
unsafe impl<T: Copy + Sync> Sync for HugeArray<T> {}

impl<T: Copy> Default for HugeArray<T> {
    fn default() -> Self {
        Self {
            heap: Vec::new(),
            #[cfg(target_os = "linux")]
            mapped: None,
        }
    }
}

impl<T: Copy> HugeArray<T> {
    /// The items of `items`, of which there must be `n` (any beyond are dropped, fewer leave
    /// the array shorter).
    pub fn collect(n: usize, items: impl IntoIterator<Item = T>) -> Self {
        #[cfg(target_os = "linux")]
        {
            let bytes = n.saturating_mul(std::mem::size_of::<T>());
            if bytes >= MIN_BYTES && std::mem::align_of::<T>() <= HUGE_PAGE {
                let len = bytes.next_multiple_of(HUGE_PAGE) + HUGE_PAGE;
                // SAFETY: an anonymous private mapping; the result is checked.
                let base = unsafe {
                    libc::mmap(
                        std::ptr::null_mut(),
                        len,
                        libc::PROT_READ | libc::PROT_WRITE,
                        libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
                        -1,
                        0,
                    )
                };
                if base != libc::MAP_FAILED {
                    let start = (base as usize).next_multiple_of(HUGE_PAGE);
                    let span = bytes.next_multiple_of(HUGE_PAGE);
                    // SAFETY: [start, start + span) lies within the mapping; the advice only
                    // changes how its (untouched) pages are backed, and failure is harmless.
                    unsafe { libc::madvise(start as *mut libc::c_void, span, libc::MADV_HUGEPAGE) };
                    let ptr = start as *mut T;
                    let mut k = 0;
                    for item in items.into_iter().take(n) {
                        // SAFETY: k < n items of T fit in [start, start + bytes), aligned.
                        unsafe { ptr.add(k).write(item) };
                        k += 1;
                    }
                    return Self {
                        heap: Vec::new(),
                        mapped: Some((base, len, ptr, k)),
                    };
                }
            }
        }
        let mut heap = Vec::with_capacity(n);
        heap.extend(items.into_iter().take(n));
        Self {
            heap,
            #[cfg(target_os = "linux")]
            mapped: None,
        }
    }

    /// Bytes held (the mapping, or the heap buffer).
    pub fn memory_bytes(&self) -> usize {
        #[cfg(target_os = "linux")]
        if let Some((_, len, _, _)) = self.mapped {
            return len;
        }
        self.heap.capacity() * std::mem::size_of::<T>()
    }
}

impl<T: Copy> Deref for HugeArray<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        #[cfg(target_os = "linux")]
        if let Some((_, _, ptr, k)) = self.mapped {
            // SAFETY: the first k items of the mapping were written in `collect`.
            return unsafe { std::slice::from_raw_parts(ptr, k) };
        }
        &self.heap
    }
}

impl<T: Copy> DerefMut for HugeArray<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        #[cfg(target_os = "linux")]
        if let Some((_, _, ptr, k)) = self.mapped {
            // SAFETY: the first k items of the mapping were written in `collect`, and `&mut
            // self` makes this the only reference to them.
            return unsafe { std::slice::from_raw_parts_mut(ptr, k) };
        }
        &mut self.heap
    }
}

impl<T: Copy> Drop for HugeArray<T> {
    fn drop(&mut self) {
        #[cfg(target_os = "linux")]
        if let Some((base, len, _, _)) = self.mapped.take() {
            // SAFETY: the mapping was made in `collect` and nothing refers to it any more.
            unsafe { libc::munmap(base, len) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_large_arrays_hold_their_items() {
        for n in [0usize, 10, 3 << 20] {
            let a = HugeArray::collect(n, (0..n).map(|i| i as u32 ^ 0x5a5a));
            assert_eq!(a.len(), n);
            assert!(a.iter().enumerate().all(|(i, &v)| v == i as u32 ^ 0x5a5a));
            assert!(a.memory_bytes() >= n * 4);
        }
        // Fewer items than announced leave the array shorter; more are dropped.
        assert_eq!(HugeArray::collect(4, 0..2u8).len(), 2);
        assert_eq!(HugeArray::collect(2 << 20, 0..(3u32 << 20)).len(), 2 << 20);
    }
}
