//! Whether memory can be allocated now, asked before work that allocates inside a library
//! (`tobj`, `image`, `serde`), where a refused allocation aborts the process instead of
//! returning an error.

/// Whether `bytes` can be allocated now: asked of the allocator and given back at once.
/// Under an address-space limit, or a kernel that refuses what it could never back, work that
/// could not finish is refused before it starts.
pub(crate) fn can_allocate(bytes: u64) -> bool {
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
mod tests {
    use super::can_allocate;

    #[test]
    fn small_requests_are_granted_and_impossible_ones_refused() {
        assert!(can_allocate(1 << 20));
        assert!(!can_allocate(u64::MAX));
        assert!(!can_allocate(1 << 62));
    }
}
