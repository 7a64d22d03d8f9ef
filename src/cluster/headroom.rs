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
/// `share`, whichever is more, so a size that wanders stops allocating at its peak. Room the
/// allocator refuses is not kept: what fills the buffer asks again for what it needs.
pub(crate) fn clear_with_room_for<T>(buffer: &mut Vec<T>, share: usize) {
    let len = buffer.len().max(share);
    buffer.clear();
    // Grown by half again when it grows, so the peaks of a wandering size stop allocating.
    let _ = try_room_for(buffer, len.saturating_add(len / 4));
}

/// Makes room in `buffer` for `len` elements, by half again when it must grow, so a grid a
/// little finer than any before (the automatic grid's next choice) does not allocate again.
pub(crate) fn room_for<T>(buffer: &mut Vec<T>, len: usize) {
    if buffer.capacity() < len {
        buffer.reserve((len + len / 2).saturating_sub(buffer.len()));
    }
}

/// Makes room in `buffer` for `more` elements past its length, asking the allocator (twice
/// the length where it must grow, as a push would): the bytes it refused, if it did, where a
/// push past the room would abort the process.
#[inline(always)]
pub(crate) fn try_room_for_more<T>(buffer: &mut Vec<T>, more: usize) -> Result<(), u64> {
    if buffer.capacity() - buffer.len() >= more {
        return Ok(());
    }
    grow_by(buffer, more)
}

/// [`try_room_for_more`]'s growth, out of the line of a loop that mostly has the room.
#[cold]
#[inline(never)]
fn grow_by<T>(buffer: &mut Vec<T>, more: usize) -> Result<(), u64> {
    let grown = more.max(buffer.len());
    buffer.try_reserve(grown).map_err(|_| {
        let items = buffer.len().saturating_add(grown) as u64;
        items.saturating_mul(std::mem::size_of::<T>() as u64)
    })
}

/// [`room_for`], asking the allocator (the least that holds `len` where half again is
/// refused): the bytes it refused, if it did.
pub(crate) fn try_room_for<T>(buffer: &mut Vec<T>, len: usize) -> Result<(), u64> {
    if buffer.capacity() >= len {
        return Ok(());
    }
    let roomy = len.saturating_add(len / 2).saturating_sub(buffer.len());
    if buffer.try_reserve(roomy).is_ok() {
        return Ok(());
    }
    (buffer.try_reserve_exact(len - buffer.len()))
        .map_err(|_| (len as u64).saturating_mul(std::mem::size_of::<T>() as u64))
}

/// Gives back what a burst of lights grew `buffer` to, keeping [`clear_with_room_for`]'s room
/// for what it holds now, so the next frame of the same size allocates nothing. A buffer
/// within twice that keeps its store (no reallocation for a small difference).
pub(crate) fn fit<T>(buffer: &mut Vec<T>) {
    let keep = buffer.len() + buffer.len() / 4;
    if buffer.capacity() > 2 * keep.max(WHOLE_UP_TO) {
        buffer.shrink_to(keep);
    }
}

/// [`fit`] for a buffer whose contents no later frame reads (a frame's scratch): emptied
/// first, so a burst's contents left in a path the frames no longer take go too.
pub(crate) fn fit_empty<T>(buffer: &mut Vec<T>) {
    fit_keeping(buffer, false);
}

/// [`fit`] where the contents are kept (`keep`), else [`fit_empty`].
pub(crate) fn fit_keeping<T>(buffer: &mut Vec<T>, keep: bool) {
    if !keep {
        buffer.clear();
    }
    fit(buffer);
}

/// [`zeroed_with_room`], asking the allocator: the bytes it refused, if it did (`buffer` is
/// then empty).
pub(crate) fn try_zeroed_with_room<T: Clone + Default>(
    buffer: &mut Vec<T>,
    len: usize,
) -> Result<(), u64> {
    buffer.clear();
    try_room_for(buffer, len)?;
    buffer.resize(len, T::default());
    Ok(())
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
    fn a_fitted_buffer_gives_back_a_bursts_room_and_keeps_its_contents_and_headroom() {
        let mut burst: Vec<u32> = Vec::with_capacity(100_000);
        burst.extend(0..20_000);
        fit(&mut burst);
        assert_eq!(burst, (0..20_000).collect::<Vec<_>>());
        assert!(
            (25_000..50_000).contains(&burst.capacity()),
            "{}",
            burst.capacity()
        );
        // Then a frame of the same size allocates nothing.
        let capacity = burst.capacity();
        clear_with_room_for(&mut burst, 0);
        burst.extend(0..20_000);
        assert_eq!(burst.capacity(), capacity);
        // Small buffers, and room within twice the contents', stay as they are.
        let mut small: Vec<u32> = Vec::with_capacity(8000);
        fit(&mut small);
        assert_eq!(small.capacity(), 8000);
        // Scratch: emptied and given back.
        let mut scratch: Vec<u32> = (0..50_000).collect();
        fit_empty(&mut scratch);
        assert!(scratch.is_empty() && scratch.capacity() <= 2 * WHOLE_UP_TO);
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
