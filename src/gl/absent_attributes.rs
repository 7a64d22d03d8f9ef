//! What a shader reads at an optional attribute's location where the mesh lacks it: the only
//! current (constant) attribute values the renderer sets, so the only ones it gives back.

/// (location, value): white vertex colour, +X tangent.
pub(crate) const ABSENT: [(u32, [f32; 4]); 2] = [(3, [1.0; 4]), (4, [1.0, 0.0, 0.0, 1.0])];
