//! A material's depth bias (`Material::depth_bias`): a polygon offset toward the camera, set
//! only where a frame draws a biased surface, so a scene without one makes no call for it.
//! The offset's values are the application's state too: read the first time a call changes
//! them, and given back as the call ends (with `GlStateHandling::Reset`, not read, and left at
//! GL's initial 0), with `GL_POLYGON_OFFSET_FILL` off again (the state save then switches the
//! game's back on where it was).
#![allow(unsafe_code)]

use std::cell::Cell;

use glow::HasContext;

/// The depth bias of the call under way.
#[derive(Default)]
pub(crate) struct DepthBias {
    /// The bias set last: 0 (the offset off, as every call starts: `host_state::OFF_INSIDE`).
    current: Cell<f32>,
    /// This call changed the offset, and the application's factor and units where they were
    /// read to be given back.
    changed: Cell<Option<Option<[f32; 2]>>>,
}

impl DepthBias {
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
        unsafe {
            if bias == 0.0 {
                gl.disable(glow::POLYGON_OFFSET_FILL);
            } else {
                gl.enable(glow::POLYGON_OFFSET_FILL);
                gl.polygon_offset(-bias, -bias);
            }
        }
        self.current.set(bias);
    }

    /// The call ends: the offset off, and its values the application's again (or GL's
    /// initial ones, where they were not read).
    pub(super) fn leave(&self, gl: &glow::Context) {
        if let Some(saved) = self.changed.take() {
            let [factor, units] = saved.unwrap_or([0.0, 0.0]);
            unsafe {
                gl.disable(glow::POLYGON_OFFSET_FILL);
                gl.polygon_offset(factor, units);
            }
        }
        self.current.set(0.0);
    }
}
