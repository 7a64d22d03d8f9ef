//! Render state as a value: every pass declares its full state and applies it in one place,
//! so no pass inherits a stray blend or depth setting from the one before.
#![allow(unsafe_code)]

use glow::HasContext;

use super::Device;

/// Blending.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Replace.
    Off,
    /// `dst + src` (light accumulation).
    Additive,
    /// `src·a + dst·(1−a)` (transparency).
    Alpha,
}

/// Depth test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthTest {
    /// No depth test.
    Off,
    /// `LESS`.
    Less,
    /// `LEQUAL` (passes after an equal-depth prepass).
    LessEqual,
    /// `GEQUAL` (a light volume's far side behind or on a surface).
    GreaterEqual,
    /// `ALWAYS`: every fragment passes and, with depth writes, sets the depth (GL writes depth
    /// only while the test is enabled).
    Always,
}

/// Face culling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cull {
    /// Draw both sides.
    None,
    /// Cull back faces.
    Back,
    /// Cull front faces (draw the far side of a transparent object first).
    Front,
}

/// The full fixed-function state of a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderState {
    /// Depth test function.
    pub depth_test: DepthTest,
    /// Depth writes.
    pub depth_write: bool,
    /// Blending.
    pub blend: Blend,
    /// Culling.
    pub cull: Cull,
    /// Colour writes (off for a depth prepass).
    pub color_write: bool,
}

impl RenderState {
    /// A full-screen pass (composite, copy): every pixel written, no depth, no blending.
    pub const FULL_SCREEN: RenderState = RenderState {
        depth_test: DepthTest::Off,
        depth_write: false,
        blend: Blend::Off,
        cull: Cull::None,
        color_write: true,
    };

    /// A full-screen pass that also sets each pixel's depth from its shader (`gl_FragDepth`).
    pub const FULL_SCREEN_WITH_DEPTH: RenderState = RenderState {
        depth_test: DepthTest::Always,
        depth_write: true,
        ..Self::FULL_SCREEN
    };

    /// Depth prepass: depth test and write, no colour.
    pub const DEPTH_PREPASS: RenderState = RenderState {
        depth_test: DepthTest::Less,
        depth_write: true,
        blend: Blend::Off,
        cull: Cull::None,
        color_write: false,
    };

    /// Opaque shading after a depth prepass: only the visible surface passes `LEQUAL`, so each
    /// pixel is shaded once however deep the overdraw.
    pub const OPAQUE_AFTER_PREPASS: RenderState = RenderState {
        depth_test: DepthTest::LessEqual,
        depth_write: false,
        blend: Blend::Off,
        cull: Cull::None,
        color_write: true,
    };

    /// Opaque surfaces cut out by a texture's alpha, after the others: tested and written
    /// against their depth (the prepass left them out), the last drawn winning ties as after
    /// the prepass.
    pub const CUT_OUT: RenderState = RenderState {
        depth_write: true,
        ..Self::OPAQUE_AFTER_PREPASS
    };

    /// Transparent objects, first pass: their far side (GL's back faces; the front ones of a
    /// mirrored object, which takes the passes the other way round), blended over what is
    /// behind, tested against (but not writing) the opaque depth.
    pub const TRANSPARENT_BACK_FACES: RenderState = RenderState {
        depth_test: DepthTest::Less,
        depth_write: false,
        blend: Blend::Alpha,
        cull: Cull::Front,
        color_write: true,
    };

    /// Transparent objects, second pass: their near side.
    pub const TRANSPARENT_FRONT_FACES: RenderState = RenderState {
        cull: Cull::Back,
        ..Self::TRANSPARENT_BACK_FACES
    };

    /// Transparent objects whose triangles face one way: one pass shows whichever side the
    /// eye sees.
    pub const TRANSPARENT_BOTH_SIDES: RenderState = RenderState {
        cull: Cull::None,
        ..Self::TRANSPARENT_BACK_FACES
    };

    /// Applies every field.
    pub fn apply(&self, dev: &Device) {
        let gl = &dev.gl;
        unsafe {
            match self.depth_test {
                DepthTest::Off => gl.disable(glow::DEPTH_TEST),
                DepthTest::Less => {
                    gl.enable(glow::DEPTH_TEST);
                    gl.depth_func(glow::LESS);
                }
                DepthTest::LessEqual => {
                    gl.enable(glow::DEPTH_TEST);
                    gl.depth_func(glow::LEQUAL);
                }
                DepthTest::GreaterEqual => {
                    gl.enable(glow::DEPTH_TEST);
                    gl.depth_func(glow::GEQUAL);
                }
                DepthTest::Always => {
                    gl.enable(glow::DEPTH_TEST);
                    gl.depth_func(glow::ALWAYS);
                }
            }
            gl.depth_mask(self.depth_write);
            let c = self.color_write;
            gl.color_mask(c, c, c, c);
            match self.blend {
                Blend::Off => gl.disable(glow::BLEND),
                Blend::Additive => {
                    gl.enable(glow::BLEND);
                    gl.blend_func(glow::ONE, glow::ONE);
                }
                Blend::Alpha => {
                    gl.enable(glow::BLEND);
                    // Alpha composes as coverage, `a + a_dst·(1 − a)`: 1 over an opaque
                    // background, the surface's own opacity over a transparent one.
                    gl.blend_func_separate(
                        glow::SRC_ALPHA,
                        glow::ONE_MINUS_SRC_ALPHA,
                        glow::ONE,
                        glow::ONE_MINUS_SRC_ALPHA,
                    );
                }
            }
        }
        self.cull.apply(dev);
    }
}

impl Cull {
    /// What a surface drawn from `double_sided` (else its front only) takes, placed by a
    /// transform that is `mirrored` or not: the glTF front is counter-clockwise on screen,
    /// clockwise under a mirroring transform (GL's back face, so its front is culled then).
    pub fn for_surface(double_sided: bool, mirrored: bool) -> Cull {
        match (double_sided, mirrored) {
            (true, _) => Cull::None,
            (false, false) => Cull::Back,
            (false, true) => Cull::Front,
        }
    }

    /// Sets culling alone (a pass's objects differ only in it).
    pub fn apply(self, dev: &Device) {
        let gl = &dev.gl;
        unsafe {
            match self {
                Cull::None => gl.disable(glow::CULL_FACE),
                Cull::Back => {
                    gl.enable(glow::CULL_FACE);
                    gl.cull_face(glow::BACK);
                }
                Cull::Front => {
                    gl.enable(glow::CULL_FACE);
                    gl.cull_face(glow::FRONT);
                }
            }
        }
    }
}
