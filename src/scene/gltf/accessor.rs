//! Reading accessors: every byte range checked against its buffer view and buffer before
//! anything is read, counts checked against a budget before anything is allocated, sparse
//! substitutions applied. Components are decoded little-endian from unaligned bytes.

use gltf::accessor::{DataType, Dimensions};

use super::buffers::Buffers;

/// Components per element of the element types the loader reads.
pub(super) fn dims(d: Dimensions) -> Option<usize> {
    match d {
        Dimensions::Scalar => Some(1),
        Dimensions::Vec2 => Some(2),
        Dimensions::Vec3 => Some(3),
        Dimensions::Vec4 => Some(4),
        _ => None,
    }
}

fn size(t: DataType) -> usize {
    match t {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// `"VEC3 of FLOAT"`, for messages.
pub(super) fn describe(a: &gltf::Accessor) -> String {
    let d = match a.dimensions() {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    };
    let t = match a.data_type() {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    };
    let n = if a.normalized() { " (normalized)" } else { "" };
    format!("{d} of {t}{n}")
}

/// One component as `f32`: floats as they are, normalized integers mapped to [0, 1] (or
/// [−1, 1]) as glTF defines, other integers as their value.
fn component_f32(b: &[u8], t: DataType, normalized: bool) -> f32 {
    match (t, normalized) {
        (DataType::F32, _) => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        (DataType::U8, true) => f32::from(b[0]) / 255.0,
        (DataType::U16, true) => f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
        (DataType::I8, true) => (f32::from(b[0] as i8) / 127.0).max(-1.0),
        (DataType::I16, true) => (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0),
        _ => component_u32(b, t) as f32,
    }
}

fn component_u32(b: &[u8], t: DataType) -> u32 {
    match t {
        DataType::U8 => u32::from(b[0]),
        DataType::I8 => b[0] as i8 as u32,
        DataType::U16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
        DataType::I16 => i16::from_le_bytes([b[0], b[1]]) as u32,
        DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u32,
    }
}

/// The accessor's components as `f32`, `dims` per element. `max_count` is how many elements
/// the caller can still afford; more is an error before anything is allocated.
pub(super) fn read_f32(
    a: &gltf::Accessor,
    buffers: &mut Buffers,
    max_count: usize,
) -> Result<Vec<f32>, String> {
    let (t, normalized) = (a.data_type(), a.normalized());
    read(a, buffers, max_count, |b| component_f32(b, t, normalized))
}

/// The accessor's components as `u32` (for indices).
pub(super) fn read_u32(
    a: &gltf::Accessor,
    buffers: &mut Buffers,
    max_count: usize,
) -> Result<Vec<u32>, String> {
    let t = a.data_type();
    read(a, buffers, max_count, |b| component_u32(b, t))
}

/// Where `count` elements of `elem` bytes, `stride` apart, start `offset` bytes into a view of
/// `length` bytes: checked to fit, with overflow-free arithmetic.
fn check_span(
    count: usize,
    elem: usize,
    stride: usize,
    offset: usize,
    length: usize,
) -> Result<(), String> {
    if count == 0 {
        return Ok(());
    }
    let needed = (count as u128 - 1) * stride as u128 + elem as u128 + offset as u128;
    if needed > length as u128 {
        return Err(format!(
            "{count} elements of {elem} bytes (stride {stride}) from byte {offset} need {needed} \
             bytes, past the end of"
        ));
    }
    Ok(())
}

fn read<T: Copy + Default>(
    a: &gltf::Accessor,
    buffers: &mut Buffers,
    max_count: usize,
    component: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, String> {
    let field = format!("accessors[{}]", a.index());
    let d = dims(a.dimensions())
        .ok_or_else(|| format!("{field}: {} is not a vertex attribute type", describe(a)))?;
    let csize = size(a.data_type());
    let elem = csize * d;
    let count = a.count();
    if count > max_count {
        return Err(format!(
            "{field}: count {count} is more than the {max_count} elements left of the limit \
             ({} vertices and {} indices per file)",
            super::MAX_VERTICES,
            super::MAX_INDICES
        ));
    }
    let mut out = Vec::new();
    match a.view() {
        Some(view) => {
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!(
                    "{field}: bufferViews[{}] has byteStride {stride}, less than the {elem} \
                     bytes of one {} element",
                    view.index(),
                    describe(a)
                ));
            }
            let view_index = view.index();
            let bytes = buffers.view(&view)?;
            check_span(count, elem, stride, a.offset(), bytes.len()).map_err(|e| {
                format!(
                    "{field}: {e} bufferViews[{view_index}] ({} bytes)",
                    bytes.len()
                )
            })?;
            out.reserve_exact(count * d);
            for i in 0..count {
                let start = a.offset() + i * stride;
                for c in 0..d {
                    let at = start + c * csize;
                    out.push(component(&bytes[at..at + csize]));
                }
            }
        }
        // No view: every element is zero until sparse substitution.
        None => {
            buffers.take_unbacked(count, &field)?;
            out.resize(count * d, T::default())
        }
    }
    if let Some(sparse) = a.sparse() {
        let field = format!("{field}.sparse");
        let n = sparse.count();
        if n > count {
            return Err(format!(
                "{field}: count {n} is more than the accessor's {count} elements"
            ));
        }
        let indices = sparse.indices();
        let itype = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let isize = size(itype);
        let view = indices.view();
        let view_index = view.index();
        let whole = buffers.view(&view)?;
        check_span(n, isize, isize, indices.offset(), whole.len()).map_err(|e| {
            format!(
                "{field}.indices: {e} bufferViews[{view_index}] ({} bytes)",
                whole.len()
            )
        })?;
        // Only the indices' bytes, not their whole view (the values' view is borrowed next).
        // (In range once `check_span` passed; none at all for a sparse count of 0.)
        let ibytes = whole
            .get(indices.offset()..indices.offset() + n * isize)
            .unwrap_or_default()
            .to_vec();
        let values = sparse.values();
        let view = values.view();
        let view_index = view.index();
        let vbytes = buffers.view(&view)?;
        check_span(n, elem, elem, values.offset(), vbytes.len()).map_err(|e| {
            format!(
                "{field}.values: {e} bufferViews[{view_index}] ({} bytes)",
                vbytes.len()
            )
        })?;
        for k in 0..n {
            let at = k * isize;
            let target = component_u32(&ibytes[at..at + isize], itype) as usize;
            if target >= count {
                return Err(format!(
                    "{field}.indices: element {k} is out of range for {count} elements"
                ));
            }
            for c in 0..d {
                let at = values.offset() + k * elem + c * csize;
                out[target * d + c] = component(&vbytes[at..at + csize]);
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_are_checked_without_overflow() {
        assert!(check_span(3, 12, 12, 0, 36).is_ok());
        assert!(check_span(3, 12, 12, 4, 36).is_err());
        assert!(
            check_span(3, 12, 16, 0, 44).is_ok(),
            "the last element needs no stride"
        );
        assert!(check_span(usize::MAX, 16, usize::MAX, usize::MAX, 100).is_err());
        assert!(check_span(0, 12, 12, 1000, 0).is_ok());
    }

    #[test]
    fn components_decode_as_gltf_defines() {
        assert_eq!(component_f32(&[255], DataType::U8, true), 1.0);
        assert_eq!(component_f32(&[0x00, 0x80], DataType::I16, true), -1.0);
        assert_eq!(
            component_f32(&1.5f32.to_le_bytes(), DataType::F32, false),
            1.5
        );
        assert_eq!(component_u32(&[1, 2, 0, 0], DataType::U32), 0x0201);
        assert_eq!(component_u32(&[7], DataType::U8), 7);
    }
}
