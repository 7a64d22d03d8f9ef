//! What a renderer call has made current (its program, its vertex array, the constant values of
//! the attributes a mesh may lack), so that a frame binding one program and one vertex array
//! for many objects makes each GL call once; and the counts of the calls it did make.
#![allow(unsafe_code)]

use std::cell::Cell;

use glow::HasContext;

use super::absent_attributes::ABSENT;
use super::vertex_arrays::VertexArrays;

/// State calls the renderer's caches made, counted since the device was created: what tests
/// use to check that a frame sets what its objects share once, not once an object.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StateCalls {
    /// `glUseProgram` calls.
    pub programs_bound: u64,
    /// `glUniform*` calls.
    pub uniforms_set: u64,
    /// Calls that bind a mesh's vertex arrays: its vertex array object, or (without one) its
    /// buffers and attribute arrays.
    pub vertex_array_calls: u64,
    /// Binds of the methods' data textures (lights, grids, lists), each choosing its unit.
    pub data_textures_bound: u64,
    /// Constant values of the attributes a mesh may lack that were set (one
    /// `glVertexAttrib4f` each).
    pub absent_values_set: u64,
}

/// What the call under way has bound. The application may bind anything between calls, so it
/// is known only during one (`in_call`): forgotten when a call starts and when it ends.
#[derive(Default)]
pub(crate) struct CallState {
    program: Cell<Option<glow::Program>>,
    vertex_array: Cell<Option<glow::VertexArray>>,
    /// Which [`ABSENT`] attributes' constant values this call has set (bit `i`: `ABSENT[i]`)
    /// and no draw has made undefined since.
    absent_values_set: Cell<u8>,
    calls: Cell<StateCalls>,
}

impl CallState {
    /// A call starts with `vertex_array` (the renderer's own, if any) bound, or ends (`None`).
    pub(super) fn forget(&self, vertex_array: Option<glow::VertexArray>) {
        self.program.set(None);
        self.vertex_array.set(vertex_array);
        self.absent_values_set.set(0);
    }

    /// `program` is deleted: a program made later may take its name, and must be bound.
    pub(super) fn forget_program(&self, program: glow::Program) {
        if self.program.get() == Some(program) {
            self.program.set(None);
        }
    }

    /// Makes `program` current, unless this call already did.
    pub(super) fn use_program(&self, gl: &glow::Context, program: glow::Program, in_call: bool) {
        if self.program.get() == Some(program) {
            return;
        }
        unsafe { gl.use_program(Some(program)) };
        self.count(|c| c.programs_bound += 1);
        if in_call {
            self.program.set(Some(program));
        }
    }

    /// A vertex array deleted while bound: GL binds none in its place.
    pub(super) fn forget_vertex_array(&self) {
        self.vertex_array.set(None);
    }

    /// The vertex array this call bound last.
    pub(super) fn vertex_array(&self) -> Option<glow::VertexArray> {
        self.vertex_array.get()
    }

    /// Binds `vao` through `arrays`, unless this call already did.
    pub(super) fn bind_vertex_array(
        &self,
        gl: &glow::Context,
        arrays: VertexArrays,
        vao: glow::VertexArray,
        in_call: bool,
    ) {
        if self.vertex_array.get() == Some(vao) {
            return;
        }
        arrays.bind(gl, Some(vao));
        self.count(|c| c.vertex_array_calls += 1);
        if in_call {
            self.vertex_array.set(Some(vao));
        }
    }

    /// Sets the constant values of the [`ABSENT`] attributes in `needed` (bit `i`: `ABSENT[i]`)
    /// that this call has not set since (a value is the context's, not a vertex array's).
    pub(super) fn set_absent_values(&self, gl: &glow::Context, needed: u8, in_call: bool) {
        let set = self.absent_values_set.get();
        let missing = needed & !set;
        if missing == 0 {
            return;
        }
        for (i, (loc, v)) in ABSENT.into_iter().enumerate() {
            if missing & (1 << i) != 0 {
                unsafe { gl.vertex_attrib_4_f32(loc, v[0], v[1], v[2], v[3]) };
            }
        }
        self.count(|c| c.absent_values_set += u64::from(missing.count_ones()));
        if in_call {
            self.absent_values_set.set(set | missing);
        }
    }

    /// A draw is to read arrays at the [`ABSENT`] locations in `arrays`. GL before 4.2 (and
    /// older drivers after it) leaves the constant values there undefined after such a draw,
    /// so they are set again before a mesh lacking those arrays draws.
    pub(super) fn forget_absent_values(&self, arrays: u8) {
        let set = self.absent_values_set.get();
        self.absent_values_set.set(set & !arrays);
    }

    /// Counts a state call.
    pub(super) fn count(&self, f: impl FnOnce(&mut StateCalls)) {
        let mut c = self.calls.get();
        f(&mut c);
        self.calls.set(c);
    }

    /// State calls made so far.
    pub(super) fn calls(&self) -> StateCalls {
        self.calls.get()
    }
}
