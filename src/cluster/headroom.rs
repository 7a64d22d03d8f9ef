//! Buffers that keep room to spare, so that frames stop allocating once each buffer has seen
//! its peak (soak test: no allocation per frame in steady state, on any number of cores): the
//! assignment's and the packed textures' bytes.

/// The least room one of `parts` bands or chunks keeps for its part of `total` (the last
/// assignment's runs or lights): all of it with up to four parts or up to [`WHOLE_UP_TO`],
/// else four even shares, since each part's share moves with the split and the view.
pub(crate) fn share_of(total: usize, parts: usize) -> usize {
    (4 * total / parts.max(1)).max(WHOLE_UP_TO).min(total)
}

/// Entries a part keeps room for all of, whatever its share: 32 KiB of runs.
pub(crate) const WHOLE_UP_TO: usize = 4096;

/// Empties `buffer` for a new frame, keeping room for a quarter more than it held or than
/// `share`, whichever is more, so a size that wanders stops allocating at its peak.
pub(crate) fn clear_with_room_for<T>(buffer: &mut Vec<T>, share: usize) {
    let len = buffer.len().max(share);
    buffer.clear();
    // Grown by half again when it grows, so the peaks of a wandering size stop allocating.
    room_for(buffer, len + len / 4);
}

/// Makes room in `buffer` for `len` elements, by half again when it must grow, so a grid a
/// little finer than any before (the automatic grid's next choice) does not allocate again.
pub(crate) fn room_for<T>(buffer: &mut Vec<T>, len: usize) {
    if buffer.capacity() < len {
        buffer.reserve((len + len / 2).saturating_sub(buffer.len()));
    }
}

/// Makes `buffer` `len` default values (zeros), with [`room_for`]'s room to grow: for
/// per-frame buffers filled afresh, whose length wanders with the view and the lights.
pub(crate) fn zeroed_with_room<T: Clone + Default>(buffer: &mut Vec<T>, len: usize) {
    buffer.clear();
    room_for(buffer, len);
    buffer.resize(len, T::default());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_up_to_a_quarter_larger_than_the_last_or_its_share_does_not_allocate() {
        let mut runs: Vec<u32> = (0..1000).collect();
        clear_with_room_for(&mut runs, 0);
        let capacity = runs.capacity();
        assert!(capacity >= 1250, "{capacity}");
        runs.extend(0..1250);
        assert_eq!(runs.capacity(), capacity, "grew within its headroom");
        // A band that held little keeps room for its share of the whole.
        let mut band: Vec<u32> = (0..10).collect();
        clear_with_room_for(&mut band, 1000);
        assert!(band.capacity() >= 1250, "{}", band.capacity());
    }

    #[test]
    fn a_share_is_all_with_few_parts_or_runs_else_four_even_shares() {
        assert_eq!(share_of(100_000, 2), 100_000);
        assert_eq!(share_of(100_000, 4), 100_000);
        assert_eq!(share_of(100_000, 8), 50_000);
        assert_eq!(share_of(3000, 8), 3000);
        assert_eq!(share_of(20_000, 8), 10_000);
        assert_eq!(share_of(0, 0), 0);
    }

    #[test]
    fn a_grid_up_to_half_again_as_fine_does_not_allocate() {
        let mut cells: Vec<u32> = Vec::new();
        room_for(&mut cells, 1000);
        let capacity = cells.capacity();
        assert!(capacity >= 1500, "{capacity}");
        room_for(&mut cells, 1400);
        cells.resize(1400, 0);
        assert_eq!(cells.capacity(), capacity);
        // Zeroed afresh, with the same room.
        let mut bytes: Vec<u8> = vec![7; 10];
        zeroed_with_room(&mut bytes, 1000);
        assert!(bytes.len() == 1000 && bytes.iter().all(|&b| b == 0));
        let capacity = bytes.capacity();
        assert!(capacity >= 1500, "{capacity}");
        zeroed_with_room(&mut bytes, 1400);
        assert_eq!(bytes.capacity(), capacity);
    }
}
