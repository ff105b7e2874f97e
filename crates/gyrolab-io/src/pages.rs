//! How large in-memory records are backed by the kernel.

/// Asks the kernel to back a large, not yet touched buffer with transparent huge pages
/// (`madvise(MADV_HUGEPAGE)`; Linux's default THP mode "madvise" uses them only when asked):
/// filling 80 MB then takes 40 page faults instead of 20 000, which cost about a tenth of a
/// 10 M-sample `allan` run. Only the buffer's whole 2 MiB pages are advised; a failure (no THP,
/// another OS) leaves ordinary pages. The first fault of a process on huge pages may wait for the
/// kernel to compact memory (measured at 0.2 s for 88 MB on a machine whose memory is mostly page
/// cache): it is used only where `bench/python_allan.sh` shows it pays, the Python package's
/// working buffer (calls repeated in one process find huge pages free).
pub fn advise_huge_pages(values: &mut Vec<f64>) {
    const HUGE: usize = 2 << 20;
    let bytes = values.capacity() * std::mem::size_of::<f64>();
    if bytes < 4 * HUGE {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        let start = values.as_mut_ptr() as usize;
        let first = start.next_multiple_of(HUGE);
        let end = (start + bytes) / HUGE * HUGE;
        if end > first {
            // SAFETY: the range lies inside the vector's own allocation; MADV_HUGEPAGE changes
            // how it is backed, never its contents.
            unsafe {
                libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
            }
        }
    }
}
