//! What a shader reads at an optional attribute's location where the mesh lacks it: the only
//! current (constant) attribute values the renderer sets, so the only ones it gives back.

/// (location, value): texture coordinates (0, 0) (a mesh without them; only an untextured
/// variant draws it), white vertex colour, +X tangent, second texture coordinates (0, 0) (no
/// variant reads them from a mesh without them; on ES 2.0 without vertex array objects
/// their array is switched off all the same, so none is left pointing at another mesh).
pub(crate) const ABSENT: [(u32, [f32; 4]); 4] = [
    (2, [0.0, 0.0, 0.0, 1.0]),
    (3, [1.0; 4]),
    (4, [1.0, 0.0, 0.0, 1.0]),
    (5, [0.0, 0.0, 0.0, 1.0]),
];

/// Every attribute of [`ABSENT`], as bits (bit `i`: `ABSENT[i]`).
pub(crate) const ABSENT_BITS: u8 = (1 << ABSENT.len()) - 1;
