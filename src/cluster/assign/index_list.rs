//! The assignment's index list ([`IndexList`]): every cell's lights, as positions in the
//! visible lights, 16-bit while they fit.
//!
//! Why two widths: the list is the assignment's largest buffer (a fine grid lists some
//! 600 000 entries a frame), a renderer writes it cache-cold, and the index texture stores
//! 16-bit indices anyway; 32-bit entries are only needed past 65 536 visible lights, which a
//! renderer refuses but the CPU-only uses (`bench-assign` at a million lights) reach. Both
//! buffers are kept, so a list that changes width allocates nothing once both have grown.

use crate::cluster::headroom::try_room_for;

/// Every cell's lights, cell after cell: positions in
/// [`Assignment::visible`](crate::cluster::assign::Assignment::visible), 16-bit when there are at most 65 536 visible
/// lights ([`IndexList::as_u16`]), else 32-bit ([`IndexList::as_u32`]).
#[derive(Clone, Debug, Default)]
pub struct IndexList {
    narrow: Vec<u16>,
    wide: Vec<u32>,
    is_wide: bool,
}

/// Most visible lights a 16-bit list numbers.
pub const NARROW_LIGHTS: usize = 1 << 16;

impl IndexList {
    /// Gives back what a burst of lights grew the list to, keeping its entries (`keep`) or
    /// not ([`fit_keeping`](crate::cluster::headroom::fit_keeping)).
    pub(crate) fn fit_keeping(&mut self, keep: bool) {
        crate::cluster::headroom::fit_keeping(&mut self.narrow, keep);
        crate::cluster::headroom::fit_keeping(&mut self.wide, keep);
    }

    /// Entries in the list.
    pub fn len(&self) -> usize {
        if self.is_wide {
            self.wide.len()
        } else {
            self.narrow.len()
        }
    }

    /// True when no cell lists a light.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Entry `i` (panics past the end, as indexing a slice does).
    pub fn get(&self, i: usize) -> u32 {
        if self.is_wide {
            self.wide[i]
        } else {
            self.narrow[i] as u32
        }
    }

    /// Entries `range` (a cell's list is `offset..offset + count`), widened to `u32`.
    pub fn range(&self, range: std::ops::Range<usize>) -> Vec<u32> {
        if self.is_wide {
            self.wide[range].to_vec()
        } else {
            self.narrow[range].iter().map(|&i| i as u32).collect()
        }
    }

    /// Every entry, widened to `u32`.
    pub fn to_vec(&self) -> Vec<u32> {
        self.range(0..self.len())
    }

    /// The entries, when the list is 16-bit.
    pub fn as_u16(&self) -> Option<&[u16]> {
        (!self.is_wide).then_some(&self.narrow[..])
    }

    /// The entries, when the list is 32-bit.
    pub fn as_u32(&self) -> Option<&[u32]> {
        self.is_wide.then_some(&self.wide[..])
    }

    /// Empties the list (keeping its buffers).
    pub(super) fn clear(&mut self) {
        self.narrow.clear();
        self.wide.clear();
    }

    /// Makes the list `len` entries long, 16-bit if `visible` lights fit, and returns it to be
    /// written: every entry must then be written (growth is zero-filled, the rest keeps an
    /// earlier frame's entries).
    /// The bytes the allocator refused, if it did (the list is then to be emptied).
    pub(super) fn prepare(&mut self, len: usize, visible: usize) -> Result<EntriesMut<'_>, u64> {
        self.prepare_with_room(len, 0, visible)
    }

    /// [`prepare`](Self::prepare), keeping room for at least `room` entries: for a part of a
    /// list whose share of the whole moves (a chunk's), so that it stops growing at the whole's
    /// peak rather than at each peak of its own.
    pub(super) fn prepare_with_room(
        &mut self,
        len: usize,
        room: usize,
        visible: usize,
    ) -> Result<EntriesMut<'_>, u64> {
        self.is_wide = visible > NARROW_LIGHTS;
        // The room kept where the allocator gives it, else `len` alone.
        fn sized<T: Copy + Default>(v: &mut Vec<T>, len: usize, room: usize) -> Result<(), u64> {
            try_room_for(v, len.max(room)).or_else(|_| try_room_for(v, len))?;
            v.resize(len, T::default());
            Ok(())
        }
        if self.is_wide {
            self.narrow.clear();
            sized(&mut self.wide, len, room)?;
            Ok(EntriesMut::Wide(&mut self.wide))
        } else {
            self.wide.clear();
            sized(&mut self.narrow, len, room)?;
            Ok(EntriesMut::Narrow(&mut self.narrow))
        }
    }

    /// The entries to rewrite in place (their count stays).
    pub(super) fn entries_mut(&mut self) -> EntriesMut<'_> {
        if self.is_wide {
            EntriesMut::Wide(&mut self.wide)
        } else {
            EntriesMut::Narrow(&mut self.narrow)
        }
    }
}

/// The list's entries (or a part of them), to be written, at their width.
pub(super) enum EntriesMut<'a> {
    Narrow(&'a mut [u16]),
    Wide(&'a mut [u32]),
}

impl<'a> EntriesMut<'a> {
    /// The first `len` entries, and the rest.
    pub(super) fn split_at(self, len: usize) -> (EntriesMut<'a>, EntriesMut<'a>) {
        match self {
            EntriesMut::Narrow(list) => {
                let (a, b) = list.split_at_mut(len);
                (EntriesMut::Narrow(a), EntriesMut::Narrow(b))
            }
            EntriesMut::Wide(list) => {
                let (a, b) = list.split_at_mut(len);
                (EntriesMut::Wide(a), EntriesMut::Wide(b))
            }
        }
    }
}

/// An entry type of the index list: what the scatter, merge and trim code is generic over.
pub(super) trait LightIndex: Copy + Default + Send + Sync + 'static {
    /// `value` as an entry (the caller has checked it fits: [`IndexList::prepare`]).
    fn from_u32(value: u32) -> Self;
    /// The entry as a position in the visible lights.
    fn to_usize(self) -> usize;
    /// `list`'s entries at this width (empty when the list is at the other width).
    fn entries(list: &IndexList) -> &[Self];
}

impl LightIndex for u16 {
    #[inline(always)]
    fn from_u32(value: u32) -> Self {
        value as u16
    }

    #[inline(always)]
    fn to_usize(self) -> usize {
        self as usize
    }

    #[inline(always)]
    fn entries(list: &IndexList) -> &[Self] {
        &list.narrow
    }
}

impl LightIndex for u32 {
    #[inline(always)]
    fn from_u32(value: u32) -> Self {
        value
    }

    #[inline(always)]
    fn to_usize(self) -> usize {
        self as usize
    }

    #[inline(always)]
    fn entries(list: &IndexList) -> &[Self] {
        &list.wide
    }
}

impl PartialEq for IndexList {
    /// Equal entries, whatever the widths.
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && (0..self.len()).all(|i| self.get(i) == other.get(i))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 65 536 visible lights still fit 16 bits (positions 0..=65 535); one more does not;
    /// the widths read back the same values and compare equal.
    #[test]
    fn width_follows_the_visible_lights() {
        let mut list = IndexList::default();
        match list.prepare(3, NARROW_LIGHTS).unwrap() {
            EntriesMut::Narrow(v) => v.copy_from_slice(&[0, 7, 65_535]),
            EntriesMut::Wide(_) => panic!("65 536 visible lights fit 16 bits"),
        }
        assert_eq!(list.as_u16(), Some(&[0u16, 7, 65_535][..]));
        assert_eq!(list.to_vec(), vec![0, 7, 65_535]);
        let mut wide = IndexList::default();
        match wide.prepare(3, NARROW_LIGHTS + 1).unwrap() {
            EntriesMut::Wide(v) => v.copy_from_slice(&[0, 7, 65_535]),
            EntriesMut::Narrow(_) => panic!("65 537 visible lights need 32 bits"),
        }
        assert!(wide.as_u16().is_none());
        assert_eq!(wide.get(2), 65_535);
        assert_eq!(list, wide);
        assert_eq!(list.range(1..3), vec![7, 65_535]);
    }
}
