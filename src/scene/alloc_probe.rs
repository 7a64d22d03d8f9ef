//! Whether memory can be allocated now, asked before work that allocates inside a library
//! (`tobj`, `image`, `serde`), where a refused allocation aborts the process instead of
//! returning an error.

/// Whether `bytes` can be allocated now: asked of the allocator and given back at once.
/// Under an address-space limit, or a kernel that refuses what it could never back, work that
/// could not finish is refused before it starts.
pub fn can_allocate(bytes: u64) -> bool {
    #[cfg(test)]
    if ALLOCATABLE
        .with(std::cell::Cell::get)
        .is_some_and(|most| bytes > most)
    {
        return false;
    }
    let Ok(bytes) = usize::try_from(bytes) else {
        return false;
    };
    let mut probe = Vec::<u8>::new();
    let granted = probe.try_reserve_exact(bytes).is_ok();
    // Kept opaque: the optimiser may otherwise drop an allocation nothing reads.
    std::hint::black_box(&mut probe);
    granted
}

#[cfg(test)]
thread_local! {
    /// Most bytes [`can_allocate`] grants on this thread ([`with_allocatable`]).
    static ALLOCATABLE: std::cell::Cell<Option<u64>> = const { std::cell::Cell::new(None) };
}

/// Runs `f` as if at most `bytes` could be allocated (tests of what a memory limit refuses,
/// without a child process under one).
#[cfg(test)]
pub(crate) fn with_allocatable<T>(bytes: u64, f: impl FnOnce() -> T) -> T {
    let before = ALLOCATABLE.with(|a| a.replace(Some(bytes)));
    let result = f();
    ALLOCATABLE.with(|a| a.set(before));
    result
}

/// Refuses work needing `bytes` that this process cannot allocate now. `what` says what
/// needs them and ends in its verb ("parsing its 12 JSON objects and arrays takes"), so the
/// error reads "… takes about N MiB, more than this process can allocate now".
pub(crate) fn ask(bytes: u64, what: std::fmt::Arguments<'_>) -> Result<(), String> {
    if can_allocate(bytes) {
        return Ok(());
    }
    Err(format!(
        "{what} about {} MiB, more than this process can allocate now",
        bytes.div_ceil(1 << 20)
    ))
}

/// An empty buffer with room for a copy of `len` bytes of a file without its metadata (an
/// image's, before it is decoded), or the error saying it cannot be had here.
pub(crate) fn room_for_copy(len: usize) -> Result<Vec<u8>, String> {
    let mut room = Vec::new();
    if !can_allocate(len as u64) || room.try_reserve_exact(len).is_err() {
        return Err(format!(
            "could not be decoded (a copy of its {} MiB without its metadata cannot be \
             allocated here)",
            (len as u64).div_ceil(1 << 20)
        ));
    }
    Ok(room)
}

#[cfg(test)]
mod tests {
    use super::{ask, can_allocate};

    #[test]
    fn small_requests_are_granted_and_impossible_ones_refused() {
        assert!(can_allocate(1 << 20));
        assert!(!can_allocate(u64::MAX));
        assert!(!can_allocate(1 << 62));
    }

    #[test]
    fn a_refusal_names_what_needs_the_memory_and_how_much() {
        assert_eq!(ask(1 << 20, format_args!("a test takes")), Ok(()));
        let refusal = ask(1 << 62, format_args!("a test takes")).unwrap_err();
        assert_eq!(
            refusal,
            "a test takes about 4398046511104 MiB, more than this process can allocate now"
        );
        // Less than a MiB is said as one, not as 0.
        let refusal = super::with_allocatable(0, || ask(1000, format_args!("a test takes")));
        assert!(refusal.unwrap_err().starts_with("a test takes about 1 MiB"));
    }
}
