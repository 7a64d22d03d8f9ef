//! Buffers sized by image dimensions (read-backs of render targets), allocated fallibly: a
//! size the machine cannot hold is an error naming it, never an abort.

use super::GlError;

/// `width × height × per_pixel` zeroed items of `T` for `what`, or
/// [`GlError::OutOfMemory`] naming the size when its byte count overflows `isize` or the
/// allocator refuses it.
pub fn zeroed<T: Copy + bytemuck::Zeroable>(
    width: u32,
    height: u32,
    per_pixel: usize,
    what: &str,
) -> Result<Vec<T>, GlError> {
    let bytes = u128::from(width)
        * u128::from(height)
        * per_pixel as u128
        * std::mem::size_of::<T>() as u128;
    let refuse = || {
        GlError::OutOfMemory(format!(
            "{what} of {width}×{height} pixels needs {bytes} bytes, which cannot be allocated"
        ))
    };
    if bytes > isize::MAX as u128 {
        return Err(refuse());
    }
    let count = width as usize * height as usize * per_pixel;
    let mut v = Vec::new();
    v.try_reserve_exact(count).map_err(|_| refuse())?;
    v.resize(count, T::zeroed());
    Ok(v)
}

/// Reverses the order of the rows of `row_len` items in place (GL's row 0 is the bottom one,
/// image files' the top one), so a read-back needs no second buffer.
pub fn flip_rows<T>(items: &mut [T], row_len: usize) {
    if row_len == 0 {
        return;
    }
    let rows = items.len() / row_len;
    for y in 0..rows / 2 {
        let (top, bottom) = items.split_at_mut((rows - 1 - y) * row_len);
        top[y * row_len..(y + 1) * row_len].swap_with_slice(&mut bottom[..row_len]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_the_machine_cannot_hold_are_errors_naming_the_size() {
        // The byte count overflows isize: refused before the allocator is asked.
        let err = zeroed::<[f32; 4]>(u32::MAX, u32::MAX, 1, "read-back").unwrap_err();
        assert!(matches!(err, GlError::OutOfMemory(_)), "{err}");
        let text = err.to_string();
        assert!(
            text.contains("read-back") && text.contains("4294967295×4294967295"),
            "{text}"
        );
        // 2⁵² bytes fit isize but no 64-bit address space (2⁴⁸): the allocator refuses.
        let err = zeroed::<[f32; 4]>(1 << 24, 1 << 24, 1, "HDR read-back").unwrap_err();
        assert!(err.to_string().contains("4503599627370496 bytes"), "{err}");
        let ok = zeroed::<u8>(3, 2, 4, "read-back").unwrap();
        assert_eq!(ok, vec![0; 24]);
    }

    #[test]
    fn rows_are_flipped_in_place() {
        let mut v: Vec<u32> = (0..12).collect();
        flip_rows(&mut v, 4);
        assert_eq!(v, [8, 9, 10, 11, 4, 5, 6, 7, 0, 1, 2, 3]);
        let mut v: Vec<u32> = (0..8).collect();
        flip_rows(&mut v, 2);
        assert_eq!(v, [6, 7, 4, 5, 2, 3, 0, 1]);
        flip_rows(&mut v, 0);
    }
}
