//! A material's depth bias (`Material::depth_bias`): a polygon offset toward the camera, set
//! only where a frame draws a biased surface, so a scene without one makes no call for it.
//! The offset's values are the application's state too: read the first time a call changes
//! them, and given back as the call ends (with `GlStateHandling::Reset`, not read, and left at
//! GL's initial 0), with `GL_POLYGON_OFFSET_FILL` off again (the state save then switches the
//! game's back on where it was). Where `GL_EXT_polygon_offset_clamp` is listed, its clamp is
//! the application's state too, and 0 (no clamp) during the call: a game's negative clamp
//! would cut the bias toward the camera to nothing.
#![allow(unsafe_code)]

use std::cell::Cell;

use glow::HasContext;

use super::ext_fns::PolygonOffsetClamp;

/// The depth bias of the call under way.
pub(crate) struct DepthBias {
    /// The bias set last: 0 (the offset off, as every call starts: `host_state::OFF_INSIDE`).
    current: Cell<f32>,
    /// This call changed the offset, and the application's factor, units and clamp where they
    /// were read to be given back.
    changed: Cell<Option<Option<[f32; 3]>>>,
    /// `glPolygonOffsetClampEXT`, where the context has it.
    clamp: Option<PolygonOffsetClamp>,
}

impl DepthBias {
    pub(crate) fn new(clamp: Option<PolygonOffsetClamp>) -> DepthBias {
        DepthBias {
            current: Cell::new(0.0),
            changed: Cell::new(None),
            clamp,
        }
    }

    /// Sets the offset's values: its clamp too, where the context has one.
    fn offset(&self, gl: &glow::Context, [factor, units, clamp]: [f32; 3]) {
        match self.clamp {
            // SAFETY: the extension's entry point, loaded for this context's implementation.
            Some(set) => unsafe { set(factor, units, clamp) },
            None => unsafe { gl.polygon_offset(factor, units) },
        }
    }

    /// A frame that draws a biased surface is about to start: the application's values are
    /// read now (`save`), before its draws are queued; a read after them would wait for a
    /// threaded driver to run them.
    pub(super) fn prepare(&self, gl: &glow::Context, save: bool) {
        if self.changed.get().is_none() {
            let read = |p| unsafe { gl.get_parameter_f32(p) };
            let saved = save.then(|| {
                [
                    read(glow::POLYGON_OFFSET_FACTOR),
                    read(glow::POLYGON_OFFSET_UNITS),
                    match self.clamp {
                        Some(_) => read(glow::POLYGON_OFFSET_CLAMP),
                        None => 0.0,
                    },
                ]
            });
            self.changed.set(Some(saved));
        }
    }

    /// Draws from now on `bias` depth steps, plus `bias` times the surface's depth slope
    /// across a pixel, toward the camera: the slope term covers the rasterizer's snapping of
    /// the two surfaces' different vertices, which moves a surface seen at a grazing angle by
    /// many steps. `save`: read the application's values first, to give them back.
    pub(super) fn set(&self, gl: &glow::Context, bias: f32, save: bool) {
        if bias == self.current.get() {
            return;
        }
        self.prepare(gl, save);
        if bias == 0.0 {
            unsafe { gl.disable(glow::POLYGON_OFFSET_FILL) };
        } else {
            unsafe { gl.enable(glow::POLYGON_OFFSET_FILL) };
            self.offset(gl, [-bias, -bias, 0.0]);
        }
        self.current.set(bias);
    }

    /// The call ends: the offset off, and its values the application's again (or GL's
    /// initial ones, where they were not read).
    pub(super) fn leave(&self, gl: &glow::Context) {
        if let Some(saved) = self.changed.take() {
            unsafe { gl.disable(glow::POLYGON_OFFSET_FILL) };
            self.offset(gl, saved.unwrap_or([0.0; 3]));
        }
        self.current.set(0.0);
    }
}
