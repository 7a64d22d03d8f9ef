//! How a renderer call treats the application's GL state: saved and given back
//! (`host_state.rs`), or set without being read and left at GL's initial values
//! (`host_reset.rs`), as the application chose.

use super::host_reset::ResetEntry;
use super::host_state::{HostFeatures, HostState};
use super::vertex_arrays::VertexArrays;

/// What each renderer call does with the application's GL state
/// ([`Renderer::set_gl_state_handling`](crate::Renderer::set_gl_state_handling); README,
/// "Sharing the context with a game").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GlStateHandling {
    /// Save the state the renderer changes or depends on as a call starts, and give it back
    /// as the call returns (the default): about 70 queries a call on ES 3.0.
    #[default]
    SaveAndRestore,
    /// Read nothing of it but what a frame must know of the bound framebuffer: a call sets
    /// what the renderer depends on, and returns with what it changed at GL's initial values
    /// (no program, vertex array 0 bound, no 2D textures on units 0–7, unit 0 active,
    /// blending, depth test and culling off…), the framebuffer the application bound still
    /// bound, and the viewport and scissor box not set back. For an engine that sets its own
    /// state before it draws.
    Reset,
}

/// The outermost renderer call under way, entered as its [`GlStateHandling`] says. Not
/// boxed: the saved state lives on the stack, since a steady frame allocates nothing.
#[allow(clippy::large_enum_variant)]
pub(crate) enum HostEntry {
    Saved(HostState),
    Reset(ResetEntry),
}

impl HostEntry {
    /// Enters a call: saves the application's state, or only reads its framebuffer; either
    /// way, sets what the renderer depends on.
    pub(crate) fn enter(
        gl: &glow::Context,
        features: &HostFeatures,
        vao: Option<(glow::VertexArray, VertexArrays)>,
        handling: GlStateHandling,
    ) -> Self {
        match handling {
            GlStateHandling::SaveAndRestore => {
                HostEntry::Saved(HostState::enter(gl, features, vao))
            }
            GlStateHandling::Reset => HostEntry::Reset(ResetEntry::enter(gl, features, vao)),
        }
    }

    /// The framebuffer the application had bound for drawing (`None`: the default one): the
    /// frame's target, read once a call.
    pub(crate) fn draw_framebuffer(&self) -> Option<glow::Framebuffer> {
        match self {
            HostEntry::Saved(saved) => saved.draw_framebuffer(),
            HostEntry::Reset(entry) => entry.draw_framebuffer(),
        }
    }

    /// Ends the call: gives the application its state back, or leaves GL's initial values.
    pub(crate) fn leave(
        self,
        gl: &glow::Context,
        features: &HostFeatures,
        vao: Option<(glow::VertexArray, VertexArrays)>,
    ) {
        match self {
            HostEntry::Saved(saved) => saved.leave(gl, vao),
            HostEntry::Reset(entry) => entry.leave(gl, features, vao.map(|(_, arrays)| arrays)),
        }
    }
}
