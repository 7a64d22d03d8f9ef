//! A material's depth bias (`Material::depth_bias`): a polygon offset toward the camera, set
//! only where a frame draws a biased surface, so a scene without one makes no call for it.
//! The offset's values are the application's state too: read the first time a call changes
//! them, and given back as the call ends (with `GlStateHandling::Reset`, not read, and left at
//! GL's initial 0), with `GL_POLYGON_OFFSET_FILL` off again (the state save then switches the
//! game's back on where it was). Where `GL_EXT_polygon_offset_clamp` is listed, its clamp is
//! the application's state too: `glPolygonOffset` sets it to 0 (no clamp) for the call (a
//! game's negative clamp would cut the bias toward the camera to nothing), and
//! `glPolygonOffsetClampEXT` gives a non-zero one back. The offset itself is always set through
//! the core entry point: the extension's is loaded through EGL, which may not reach a context
//! made otherwise (OSMesa's).
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
    /// The context lists `GL_EXT_polygon_offset_clamp`: the clamp is read to be given back.
    clamp_listed: bool,
    /// `glPolygonOffsetClampEXT`, where it loaded.
    set_clamp: Option<PolygonOffsetClamp>,
}

impl DepthBias {
    pub(crate) fn new(clamp_listed: bool, set_clamp: Option<PolygonOffsetClamp>) -> DepthBias {
        DepthBias {
            current: Cell::new(0.0),
            changed: Cell::new(None),
            clamp_listed,
            set_clamp,
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
                    if self.clamp_listed {
                        read(glow::POLYGON_OFFSET_CLAMP)
                    } else {
                        0.0
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
            unsafe {
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
            let [factor, units, clamp] = saved.unwrap_or([0.0; 3]);
            unsafe {
                gl.disable(glow::POLYGON_OFFSET_FILL);
                gl.polygon_offset(factor, units);
            }
            if let (Some(set_clamp), true) = (self.set_clamp, clamp != 0.0) {
                // SAFETY: the extension's entry point, loaded for this context's implementation.
                unsafe { set_clamp(factor, units, clamp) };
            }
        }
        self.current.set(0.0);
    }
}
