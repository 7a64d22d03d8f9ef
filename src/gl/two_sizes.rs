//! A frame-sized target (a multisampled target, deferred's G-buffer) kept for two sizes: a
//! renderer that draws two views a frame (a split screen, a picture in picture) switches
//! between two targets instead of making one anew on every call. The size not drawn is freed
//! after a few calls without it (a resize).

/// Calls after which the target of the size not drawn is freed.
pub(crate) const SPARE_KEPT_CALLS: u32 = 8;

/// The target in use and the one of the size drawn before it.
pub(crate) struct TwoSizes<T> {
    in_use: Option<T>,
    spare: Option<T>,
    /// Calls in a row that drew with the target in use.
    spare_idle: u32,
}

impl<T> Default for TwoSizes<T> {
    fn default() -> Self {
        TwoSizes {
            in_use: None,
            spare: None,
            spare_idle: 0,
        }
    }
}

impl<T> TwoSizes<T> {
    /// Makes the target in use one that `fits` accepts: the one in use, else the spare, else
    /// `make`'s (the one in use kept as the spare where `other_size` says it is of another
    /// size, else freed first; the spare before it given to `free`). Where `make` fails while
    /// a target is kept, that one is freed and `make` tried again.
    pub(crate) fn fit<E>(
        &mut self,
        fits: impl Fn(&T) -> bool,
        other_size: impl Fn(&T) -> bool,
        mut make: impl FnMut() -> Result<T, E>,
        mut free: impl FnMut(T),
    ) -> Result<(), E> {
        if self.in_use.as_ref().is_some_and(&fits) {
            self.spare_idle = self.spare_idle.saturating_add(1);
            if self.spare_idle >= SPARE_KEPT_CALLS {
                self.spare.take().map(&mut free);
            }
            return Ok(());
        }
        self.spare_idle = 0;
        if self.spare.as_ref().is_some_and(&fits) {
            std::mem::swap(&mut self.in_use, &mut self.spare);
            return Ok(());
        }
        self.spare.take().map(&mut free);
        if !self.in_use.as_ref().is_some_and(&other_size) {
            self.in_use.take().map(&mut free);
        }
        let made = match make() {
            Ok(made) => made,
            // Out of memory beside the other size's target, perhaps: without it.
            Err(_) if self.in_use.is_some() => {
                self.in_use.take().map(&mut free);
                make()?
            }
            Err(e) => return Err(e),
        };
        self.spare = self.in_use.replace(made);
        Ok(())
    }

    /// The target in use.
    pub(crate) fn get(&self) -> Option<&T> {
        self.in_use.as_ref()
    }

    /// The target in use.
    pub(crate) fn get_mut(&mut self) -> Option<&mut T> {
        self.in_use.as_mut()
    }

    /// Both targets, the one in use first.
    pub(crate) fn both(&self) -> impl Iterator<Item = &T> {
        self.in_use.iter().chain(&self.spare)
    }

    /// Takes both targets out (to free them).
    pub(crate) fn take_all(&mut self) -> impl Iterator<Item = T> {
        self.spare_idle = 0;
        [self.in_use.take(), self.spare.take()]
            .into_iter()
            .flatten()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fits a target of `size` (a target is its size), noting what is made and freed.
    fn fit(kept: &mut TwoSizes<u32>, size: u32, made: &mut Vec<u32>, freed: &mut Vec<u32>) {
        kept.fit(
            |&t| t == size,
            |&t| t != size,
            || {
                made.push(size);
                Ok::<_, ()>(size)
            },
            |t| freed.push(t),
        )
        .unwrap();
        assert_eq!(kept.get(), Some(&size));
    }

    #[test]
    fn two_sizes_in_turn_are_made_once_and_a_resize_frees_the_old_size() {
        let (mut kept, mut made, mut freed) = (TwoSizes::default(), vec![], vec![]);
        for _ in 0..20 {
            fit(&mut kept, 100, &mut made, &mut freed);
            fit(&mut kept, 25, &mut made, &mut freed);
        }
        assert_eq!(
            (made.as_slice(), freed.as_slice()),
            (&[100, 25][..], &[][..])
        );
        // A resize: the older spare goes at once, the size before it after SPARE_KEPT_CALLS
        // calls without it.
        fit(&mut kept, 50, &mut made, &mut freed);
        assert_eq!(freed, [100]);
        for _ in 1..SPARE_KEPT_CALLS {
            fit(&mut kept, 50, &mut made, &mut freed);
        }
        assert_eq!(kept.both().collect::<Vec<_>>(), [&50, &25]);
        fit(&mut kept, 50, &mut made, &mut freed);
        assert_eq!(freed, [100, 25]);
        assert_eq!(kept.both().collect::<Vec<_>>(), [&50]);
        assert_eq!(kept.take_all().collect::<Vec<_>>(), [50]);
    }

    #[test]
    fn a_refusal_beside_a_kept_target_frees_it_and_tries_again() {
        let mut kept = TwoSizes::default();
        let mut freed = vec![];
        kept.fit(
            |&t| t == 1,
            |_| true,
            || Ok::<u32, ()>(1),
            |t| freed.push(t),
        )
        .unwrap();
        let mut tries = 0;
        let made = kept.fit(
            |&t| t == 2,
            |_| true,
            || {
                tries += 1;
                if tries == 1 {
                    Err(())
                } else {
                    Ok(2)
                }
            },
            |t| freed.push(t),
        );
        assert_eq!((made, tries, freed.as_slice()), (Ok(()), 2, &[1][..]));
        assert_eq!(kept.both().collect::<Vec<_>>(), [&2]);
    }

    /// A target of the same size in another form (sRGB, a specular target) replaces the one
    /// in use, which is not kept.
    #[test]
    fn a_new_form_of_the_same_size_is_not_kept_beside_the_old() {
        let mut kept = TwoSizes::default();
        let mut freed = vec![];
        for form in [10, 11] {
            kept.fit(
                |&t| t == form,
                |_| false,
                || Ok::<u32, ()>(form),
                |t| freed.push(t),
            )
            .unwrap();
        }
        assert_eq!(freed, [10]);
        assert_eq!(kept.both().collect::<Vec<_>>(), [&11]);
    }
}
