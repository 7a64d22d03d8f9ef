//! Whether an encoder's memory can be had, asked before encoding: a refused allocation
//! inside an encoder aborts the process.

use std::io;

/// Whether an encoder's `bytes` for a `w × h` picture can be allocated now: a refused
/// allocation inside an encoder aborts the process (16 384² under `ulimit -v 4000000`), where
/// this is an error naming the file.
pub fn encoding_fits(bytes: u64, (w, h): (u32, u32)) -> io::Result<()> {
    if can_allocate(bytes) {
        return Ok(());
    }
    Err(io::Error::new(
        io::ErrorKind::OutOfMemory,
        format!(
            "encoding its {w}×{h} picture takes up to {} MiB, more than this process can \
             allocate now",
            bytes.div_ceil(1 << 20)
        ),
    ))
}

/// The library's probe ([`can_allocate`](manylight::scene::alloc_probe::can_allocate)), which
/// a test here may limit.
pub(super) fn can_allocate(bytes: u64) -> bool {
    #[cfg(test)]
    if ALLOCATABLE
        .with(std::cell::Cell::get)
        .is_some_and(|most| bytes > most)
    {
        return false;
    }
    manylight::scene::alloc_probe::can_allocate(bytes)
}

#[cfg(test)]
thread_local! {
    /// Most bytes [`can_allocate`] grants on this thread (tests of a memory limit).
    pub(super) static ALLOCATABLE: std::cell::Cell<Option<u64>> =
        const { std::cell::Cell::new(None) };
}
