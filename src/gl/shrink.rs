//! When a store a burst of lights grew goes back to what its contents need: after
//! [`SHRINK_AFTER`] frames in a row that fill a quarter of it at most, uploaded or drawn again.

/// Frames in a row whose contents fill at most a quarter of a store (a data texture's rows, an
/// instance buffer) after which it is allocated again at their size: a burst of lights (an
/// explosion's sparks for a few frames) does not hold its memory for good, and a count that
/// hovers does not reallocate often.
pub const SHRINK_AFTER: u32 = 60;

/// Frames in a row whose contents filled a quarter of a store at most.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SmallFrames(u32);

impl SmallFrames {
    /// Counts a frame whose contents need `needed` of the `held` its store has: whether it is
    /// time to allocate the store at `needed`.
    pub fn note(&mut self, needed: usize, held: usize) -> bool {
        self.0 = match needed.saturating_mul(4) <= held {
            true => self.0.saturating_add(1),
            false => 0,
        };
        self.0 >= SHRINK_AFTER
    }

    /// Starts again: the store was allocated at its contents' size.
    pub fn reset(&mut self) {
        self.0 = 0;
    }
}
