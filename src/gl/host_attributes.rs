//! The application's vertex attributes at the renderer's locations. Their current (constant)
//! values are context state on every version, and the renderer sets them where a mesh lacks an
//! attribute (only there: a compatibility profile refuses to read location 0's, which is
//! `glVertex`'s). ES 2.0 has no vertex array objects, so there the arrays themselves are the
//! application's too, with their divisors where an instanced-arrays extension gives them (a
//! game's per-instance array would collapse the renderer's meshes to their first vertex).
//! Each call saves them and gives them back: an engine that caches which arrays it enabled,
//! or a constant colour it set, draws wrong when they change behind it.
#![allow(unsafe_code)]

use glow::HasContext;

use super::absent_attributes::ABSENT;
use super::ext_fns::{AttribPointerFns, VertexAttribDivisor};

/// Locations 0 to 5: where `program::ATTRIBUTES` binds the renderer's attributes (its tests
/// check that they all fall below this), the precision probe's 0 among them.
pub(crate) const LOCATIONS: usize = 6;

/// One location's array (ES 2.0).
#[derive(Clone, Copy)]
struct Array {
    enabled: bool,
    size: i32,
    data_type: u32,
    normalized: bool,
    stride: i32,
    buffer: Option<glow::Buffer>,
    pointer: *mut std::ffi::c_void,
}

/// The application's attributes at the renderer's locations.
pub(crate) struct HostAttributes {
    /// The current values at the locations [`ABSENT`] sets.
    current: [(u32, [f32; 4]); ABSENT.len()],
    /// Without a vertex array object of the renderer's own: the arrays, and what sets their
    /// pointers back (`None` where those entry points could not be loaded).
    arrays: Option<([Array; LOCATIONS], AttribPointerFns)>,
    /// Their divisors and what sets them, where the context has instanced arrays.
    divisors: Option<([u32; LOCATIONS], VertexAttribDivisor)>,
}

/// One attribute parameter of location `index` (up to four values).
fn read(gl: &glow::Context, index: u32, pname: u32) -> [f32; 4] {
    let mut v = [0f32; 4];
    unsafe { gl.get_vertex_attrib_parameter_f32_slice(index, pname, &mut v) };
    v
}

impl HostAttributes {
    /// Reads them: the arrays too where `fns` is given (the renderer has no vertex array),
    /// and their divisors where `divisor` is, which it then sets to 0 for the renderer's draws.
    pub(crate) fn save(
        gl: &glow::Context,
        fns: Option<AttribPointerFns>,
        divisor: Option<VertexAttribDivisor>,
    ) -> Self {
        let current =
            ABSENT.map(|(index, _)| (index, read(gl, index, glow::CURRENT_VERTEX_ATTRIB)));
        let arrays = fns.map(|fns| (std::array::from_fn(|i| save_array(gl, fns, i as u32)), fns));
        let divisors = divisor.map(|set| {
            let saved = std::array::from_fn(|i| {
                read(gl, i as u32, glow::VERTEX_ATTRIB_ARRAY_DIVISOR)[0] as u32
            });
            for index in 0..LOCATIONS as u32 {
                // SAFETY: the extension's entry point, for a location below the context's 8.
                unsafe { set(index, 0) };
            }
            (saved, set)
        });
        HostAttributes {
            current,
            arrays,
            divisors,
        }
    }

    /// Gives them back; leaves `GL_ARRAY_BUFFER` bound to whatever an array needed last (the
    /// caller restores it next).
    pub(crate) fn restore(&self, gl: &glow::Context) {
        if let Some((arrays, fns)) = &self.arrays {
            for (index, a) in arrays.iter().enumerate() {
                let index = index as u32;
                unsafe {
                    gl.bind_buffer(glow::ARRAY_BUFFER, a.buffer);
                    let normalized = u8::from(a.normalized);
                    (fns.set)(index, a.size, a.data_type, normalized, a.stride, a.pointer);
                    if a.enabled {
                        gl.enable_vertex_attrib_array(index);
                    } else {
                        gl.disable_vertex_attrib_array(index);
                    }
                }
            }
        }
        if let Some((divisors, set)) = self.divisors {
            for (index, divisor) in divisors.into_iter().enumerate() {
                // SAFETY: as in `save`.
                unsafe { set(index as u32, divisor) };
            }
        }
        for (index, [x, y, z, w]) in self.current {
            unsafe { gl.vertex_attrib_4_f32(index, x, y, z, w) };
        }
    }
}

fn save_array(gl: &glow::Context, fns: AttribPointerFns, index: u32) -> Array {
    let number = |pname| read(gl, index, pname)[0] as i64;
    let mut pointer = std::ptr::null_mut();
    unsafe { (fns.get)(index, glow::VERTEX_ATTRIB_ARRAY_POINTER, &mut pointer) };
    Array {
        enabled: number(glow::VERTEX_ATTRIB_ARRAY_ENABLED) != 0,
        size: number(glow::VERTEX_ATTRIB_ARRAY_SIZE) as i32,
        data_type: number(glow::VERTEX_ATTRIB_ARRAY_TYPE) as u32,
        normalized: number(glow::VERTEX_ATTRIB_ARRAY_NORMALIZED) != 0,
        stride: number(glow::VERTEX_ATTRIB_ARRAY_STRIDE) as i32,
        buffer: u32::try_from(number(glow::VERTEX_ATTRIB_ARRAY_BUFFER_BINDING))
            .ok()
            .and_then(std::num::NonZeroU32::new)
            .map(glow::NativeBuffer),
        pointer,
    }
}
