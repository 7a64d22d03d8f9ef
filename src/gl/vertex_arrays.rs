//! Vertex array objects: core ones (ES 3.x, desktop) through glow, ES 2.0's through
//! `GL_OES_vertex_array_object`, whose entry points glow calls only where the core names do
//! not load (an ES 2.0 context's implementation may load them and refuse the calls).
#![allow(unsafe_code)]

use glow::HasContext;

/// `glGenVertexArraysOES(n, arrays)`.
type GenOes = unsafe extern "system" fn(n: i32, arrays: *mut u32);
/// `glBindVertexArrayOES(array)`.
type BindOes = unsafe extern "system" fn(array: u32);
/// `glDeleteVertexArraysOES(n, arrays)`.
type DeleteOes = unsafe extern "system" fn(n: i32, arrays: *const u32);

/// How this context makes and binds vertex array objects.
#[derive(Clone, Copy)]
pub(crate) enum VertexArrays {
    Core,
    Oes {
        gen: GenOes,
        bind: BindOes,
        delete: DeleteOes,
    },
}

impl VertexArrays {
    /// ES 2.0's, where the context lists `GL_OES_vertex_array_object` and its entry points
    /// load.
    pub(crate) fn oes() -> Option<VertexArrays> {
        type Ptr = *const std::ffi::c_void;
        let load = |name| super::ext_fns::entry_point(name);
        let (gen, bind, delete) = (
            load("glGenVertexArraysOES")?,
            load("glBindVertexArrayOES")?,
            load("glDeleteVertexArraysOES")?,
        );
        // SAFETY: the extension specifies these signatures for its entry points of these
        // names, and the library stays loaded for the whole process.
        unsafe {
            Some(VertexArrays::Oes {
                gen: std::mem::transmute::<Ptr, GenOes>(gen),
                bind: std::mem::transmute::<Ptr, BindOes>(bind),
                delete: std::mem::transmute::<Ptr, DeleteOes>(delete),
            })
        }
    }

    pub(crate) fn create(self, gl: &glow::Context) -> Result<glow::VertexArray, String> {
        match self {
            VertexArrays::Core => unsafe { gl.create_vertex_array() },
            VertexArrays::Oes { gen, .. } => {
                let mut name = 0;
                unsafe { gen(1, &mut name) };
                std::num::NonZeroU32::new(name)
                    .map(glow::NativeVertexArray)
                    .ok_or_else(|| "glGenVertexArraysOES gave no name".to_string())
            }
        }
    }

    /// Binds `vao` (`None`: the default vertex array).
    pub(crate) fn bind(self, gl: &glow::Context, vao: Option<glow::VertexArray>) {
        match self {
            VertexArrays::Core => unsafe { gl.bind_vertex_array(vao) },
            VertexArrays::Oes { bind, .. } => unsafe { bind(vao.map_or(0, |v| v.0.get())) },
        }
    }

    pub(crate) fn delete(self, gl: &glow::Context, vao: glow::VertexArray) {
        match self {
            VertexArrays::Core => unsafe { gl.delete_vertex_array(vao) },
            VertexArrays::Oes { delete, .. } => unsafe { delete(1, &vao.0.get()) },
        }
    }
}
