//! Buffers that keep room to spare, so that frames stop allocating once each buffer has seen
//! its peak (soak test: no allocation per frame in steady state, on any number of cores).

/// Empties `buffer` for a new frame, keeping room for a quarter more than it held: a buffer
/// whose size wanders with moving lights (runs, visible lights) then stops allocating once it
/// has seen its peak, also on many cores where each worker's buffer has a peak of its own.
pub(super) fn clear_with_headroom<T>(buffer: &mut Vec<T>) {
    let room = buffer.len() + buffer.len() / 4;
    buffer.clear();
    buffer.reserve(room);
}

/// Makes room in `buffer` for `len` elements, by half again when it must grow, so a grid a
/// little finer than any before (the automatic grid's next choice) does not allocate again.
pub(super) fn room_for<T>(buffer: &mut Vec<T>, len: usize) {
    if buffer.capacity() < len {
        buffer.reserve((len + len / 2).saturating_sub(buffer.len()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_up_to_a_quarter_larger_than_the_last_does_not_allocate() {
        let mut runs: Vec<u32> = (0..1000).collect();
        clear_with_headroom(&mut runs);
        let capacity = runs.capacity();
        assert!(capacity >= 1250, "{capacity}");
        runs.extend(0..1250);
        assert_eq!(runs.capacity(), capacity, "grew within its headroom");
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
    }
}
