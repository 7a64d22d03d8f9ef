//! Capability probe: versions, renderer, extensions, limits and fragment precision, read once
//! when the [`super::Device`] is created.
#![allow(unsafe_code)]

use std::collections::BTreeSet;

use glow::HasContext;
use serde::Serialize;

use super::{EsVersion, GlError};

/// A shader precision as `glGetShaderPrecisionFormat` reports it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Precision {
    /// The range reaches down to −2^`range_min` (log2 of the most negative value's magnitude).
    pub range_min: i32,
    /// The range reaches up to 2^`range_max`.
    pub range_max: i32,
    /// Bits of precision (0 = not supported).
    pub precision: i32,
}

/// What the context can do, restricted to the requested ES level.
#[derive(Clone, Debug, Serialize)]
pub struct Caps {
    /// Feature level in use (may be lower than what the driver returned).
    pub es: EsVersion,
    /// `major.minor` of the context the driver returned.
    pub context_version: String,
    /// Desktop OpenGL (OSMesa) rather than OpenGL ES: shaders are assembled as GLSL 3.30 core
    /// and the ES 3.0 feature level is used.
    pub desktop: bool,
    /// `GL_VERSION`.
    pub gl_version: String,
    /// `GL_SHADING_LANGUAGE_VERSION`.
    pub glsl_version: String,
    /// `GL_RENDERER`.
    pub renderer: String,
    /// `GL_VENDOR`.
    pub vendor: String,
    /// `GL_MAX_TEXTURE_SIZE`.
    pub max_texture_size: i32,
    /// `GL_MAX_RENDERBUFFER_SIZE`.
    pub max_renderbuffer_size: i32,
    /// `GL_MAX_VIEWPORT_DIMS`: the widest and tallest frame into a framebuffer a game binds.
    pub max_viewport_dims: [i32; 2],
    /// `GL_MAX_FRAGMENT_UNIFORM_VECTORS`.
    pub max_fragment_uniform_vectors: i32,
    /// `GL_MAX_TEXTURE_IMAGE_UNITS`.
    pub max_texture_image_units: i32,
    /// `GL_MAX_DRAW_BUFFERS` (1 on ES 2.0 without `GL_EXT_draw_buffers`).
    pub max_draw_buffers: i32,
    /// `GL_MAX_COLOR_ATTACHMENTS` (1 on ES 2.0 without `GL_EXT_draw_buffers`).
    pub max_color_attachments: i32,
    /// Most samples of the offscreen MSAA target: `GL_MAX_SAMPLES` at the ES 3.0 level, and at
    /// ES 2.0 `GL_MAX_SAMPLES_EXT` where `GL_EXT_multisampled_render_to_texture` is present
    /// (0 without it).
    pub max_samples: i32,
    /// ES 2.0 with `GL_EXT_multisampled_render_to_texture`: MSAA renders into a texture whose
    /// samples the driver averages on flush (tile-based GPUs keep them on chip), instead of
    /// ES 3.0's multisampled renderbuffers and blit.
    pub msaa_render_to_texture: bool,
    /// Fragment `highp float`; precision 0 means the fragment stage has no highp.
    pub fragment_highp: Precision,
    /// Fragment `mediump float` (fp16 on most phones, and on llvmpipe).
    pub fragment_mediump: Precision,
    /// RGBA32F data textures can be sampled (ES 3.0, or `GL_OES_texture_float`).
    pub float_textures: bool,
    /// Textures of any size with mipmaps and `REPEAT` (an ES 3.0 context, or
    /// `GL_OES_texture_npot`): without it, ES 2.0 images are scaled to a power of two.
    pub npot_textures: bool,
    /// Render-target textures (clamped, unmipmapped) of any size: ES 2.0 allows them without
    /// `GL_OES_texture_npot`, Mesa without it refuses them (probed). Without them the
    /// renderer's own targets are allocated at powers of two, the frame in their corner.
    pub npot_targets: bool,
    /// 24-bit depth renderbuffers (ES 3.0, or `GL_OES_depth24`).
    pub depth24: bool,
    /// Packed depth and stencil renderbuffers, 24 bits of depth (ES 3.0, or
    /// `GL_OES_packed_depth_stencil`): the renderer's own targets' depth where `depth24` is
    /// missing.
    pub packed_depth_stencil: bool,
    /// `GL_EXT_disjoint_timer_query`.
    pub timer_query: bool,
    /// `GL_SUBPIXEL_BITS`: the rasterizer snaps vertices to 1/2^bits of a pixel (at least 4 by
    /// the specification: SwiftShader 4, llvmpipe 8), which bounds how far the point a fragment
    /// is shaded at may lie from its pixel centre's ray.
    pub subpixel_bits: i32,
    /// The extension set, sorted.
    pub extensions: BTreeSet<String>,
    /// Most iterations a fragment shader's loops may run together before the driver ends
    /// them early and silently (`None`: no such limit is known). llvmpipe stops every loop of
    /// a shader once they have run 65 535 iterations between them.
    pub max_loop_iterations: Option<u32>,
}

/// llvmpipe's loop limiter (`LP_MAX_TGSI_LOOP_ITERATIONS` in Mesa's gallivm): one count for
/// all the loops of a shader invocation.
const LLVMPIPE_LOOP_ITERATIONS: u32 = 65_535;

/// Iterations kept back from [`Caps::max_loop_iterations`] for a shader's other loops (the
/// directional lights', at most four) when a light loop is bounded by it.
const LOOP_RESERVE: u32 = 64;

/// The ES 2.0 extensions of float textures, which a device without them lacks.
const FLOAT_TEXTURE_EXTENSIONS: [&str; 4] = [
    "GL_OES_texture_float",
    "GL_OES_texture_half_float",
    "GL_OES_texture_float_linear",
    "GL_OES_texture_half_float_linear",
];

/// The ES 2.0 extension MSAA renders through.
pub const MSAA_RENDER_TO_TEXTURE: &str = "GL_EXT_multisampled_render_to_texture";

impl Caps {
    /// Probes the current context for feature level `es`. Errors when `es` is ES 3.0 and the
    /// driver returned less.
    pub fn probe(gl: &glow::Context, es: EsVersion) -> Result<Caps, GlError> {
        let v = gl.version();
        let context_version = format!("{}.{}", v.major, v.minor);
        let desktop = !v.is_embedded;
        if desktop && (es != EsVersion::Es3 || (v.major, v.minor) < (3, 3)) {
            return Err(GlError::VersionUnavailable {
                requested: es,
                reason: format!("desktop OpenGL {context_version} runs only the ES 3.0 feature level, and needs 3.3"),
            });
        }
        if !desktop && v.major < es.major() {
            return Err(GlError::VersionUnavailable {
                requested: es,
                reason: format!(
                    "the current context is OpenGL ES {context_version}{}",
                    mesa_switches_note()
                ),
            });
        }
        let mut extensions: BTreeSet<String> = gl
            .supported_extensions()
            .iter()
            .filter(|e| !e.is_empty())
            .cloned()
            .collect();
        if desktop {
            // Float colour buffers and float blending are core in desktop GL 3.0, so drivers do
            // not list the ES extensions; record them so one check serves both.
            extensions.insert("GL_EXT_color_buffer_float".into());
            extensions.insert("GL_EXT_float_blend".into());
        }
        let has = |e: &str| extensions.contains(e);
        let es3 = es == EsVersion::Es3;
        let (gl_version, glsl_version, renderer, vendor);
        let (max_texture_size, max_renderbuffer_size);
        let (max_fragment_uniform_vectors, max_texture_image_units);
        let (mut max_draw_buffers, mut max_color_attachments) = (1, 1);
        let mut max_samples = 0;
        let (fragment_highp, fragment_mediump);
        let subpixel_bits;
        let mut max_viewport_dims = [0; 2];
        unsafe {
            gl_version = gl.get_parameter_string(glow::VERSION);
            glsl_version = gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION);
            renderer = gl.get_parameter_string(glow::RENDERER);
            vendor = gl.get_parameter_string(glow::VENDOR);
            max_texture_size = gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE);
            max_renderbuffer_size = gl.get_parameter_i32(glow::MAX_RENDERBUFFER_SIZE);
            max_fragment_uniform_vectors = gl.get_parameter_i32(glow::MAX_FRAGMENT_UNIFORM_VECTORS);
            max_texture_image_units = gl.get_parameter_i32(glow::MAX_TEXTURE_IMAGE_UNITS);
            subpixel_bits = gl.get_parameter_i32(glow::SUBPIXEL_BITS);
            gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut max_viewport_dims);
            if es3 || (!desktop && has(MSAA_RENDER_TO_TEXTURE)) {
                // GL_MAX_SAMPLES_EXT has the value of GL_MAX_SAMPLES.
                max_samples = gl.get_parameter_i32(glow::MAX_SAMPLES);
            }
            if es3 || has("GL_EXT_draw_buffers") {
                max_draw_buffers = gl.get_parameter_i32(glow::MAX_DRAW_BUFFERS);
                max_color_attachments = gl.get_parameter_i32(glow::MAX_COLOR_ATTACHMENTS);
            }
            let precision = |p| {
                gl.get_shader_precision_format(glow::FRAGMENT_SHADER, p)
                    .map(|f| Precision {
                        range_min: f.range_min,
                        range_max: f.range_max,
                        precision: f.precision,
                    })
                    .unwrap_or_default()
            };
            fragment_highp = precision(glow::HIGH_FLOAT);
            fragment_mediump = precision(glow::MEDIUM_FLOAT);
            // Querying an unsupported enum must not leave an error behind for later checks.
            // Bounded, as `Device::drain_errors`: a lost context may report errors forever.
            for _ in 0..16 {
                if gl.get_error() == glow::NO_ERROR {
                    break;
                }
            }
        }
        let npot_textures = es3 || desktop || v.major >= 3 || has("GL_OES_texture_npot");
        Ok(Caps {
            es,
            context_version,
            desktop,
            gl_version,
            glsl_version,
            vendor,
            max_texture_size,
            max_renderbuffer_size,
            max_viewport_dims,
            max_fragment_uniform_vectors,
            max_texture_image_units,
            max_draw_buffers,
            max_color_attachments,
            max_samples,
            msaa_render_to_texture: !es3 && !desktop && has(MSAA_RENDER_TO_TEXTURE),
            fragment_highp,
            fragment_mediump,
            float_textures: es3 || has("GL_OES_texture_float"),
            // A context of ES 3.0 or later has them whatever level the renderer keeps to.
            npot_textures,
            npot_targets: npot_textures || unsafe { takes_npot_targets(gl) },
            depth24: es3 || has("GL_OES_depth24"),
            packed_depth_stencil: es3 || has("GL_OES_packed_depth_stencil"),
            timer_query: has("GL_EXT_disjoint_timer_query"),
            subpixel_bits,
            max_loop_iterations: renderer
                .contains("llvmpipe")
                .then_some(LLVMPIPE_LOOP_ITERATIONS),
            renderer,
            extensions,
        })
    }

    /// Whether the context itself is ES 3.0 or later (or desktop core), whatever feature level
    /// the renderer restricts itself to: its state (samplers, pixel buffers, separate read and
    /// draw framebuffers, ES 3.0 pixel-store settings) exists, a game may have set it, and an
    /// ES 2.0-level renderer's calls must neither depend on it nor change it.
    pub fn context_has_es3_state(&self) -> bool {
        let major = self.context_version.split('.').next();
        self.desktop
            || major
                .and_then(|m| m.parse::<u32>().ok())
                .is_some_and(|m| m >= 3)
    }

    /// Most lights one fragment's light loop may visit here: no limit but where the driver
    /// ends long loops early ([`Caps::max_loop_iterations`], less the other loops' share).
    pub fn light_loop_budget(&self) -> u32 {
        self.max_loop_iterations
            .map_or(u32::MAX, |n| n.saturating_sub(LOOP_RESERVE))
    }

    /// True when the extension is present.
    pub fn has_extension(&self, name: &str) -> bool {
        self.extensions.contains(name)
    }

    /// The implementation's family, from `GL_RENDERER` and `GL_VERSION`: "SwiftShader",
    /// "ANGLE", "Mesa llvmpipe", "Mesa softpipe", "Mesa", "NVIDIA", or else `GL_VENDOR`.
    pub fn implementation(&self) -> String {
        let (r, v) = (&self.renderer, &self.gl_version);
        let name = if r.contains("SwiftShader") {
            "SwiftShader"
        } else if r.starts_with("ANGLE") || v.contains("ANGLE") {
            "ANGLE"
        } else if r.contains("llvmpipe") {
            "Mesa llvmpipe"
        } else if r.contains("softpipe") {
            "Mesa softpipe"
        } else if v.contains("Mesa") {
            "Mesa"
        } else if self.vendor.contains("NVIDIA") {
            "NVIDIA"
        } else {
            return self.vendor.clone();
        };
        name.to_string()
    }

    /// A driver workaround: SwiftShader 4's GLSL ES 1.00 path loses an active fragment's light
    /// contributions when another fragment of its 2×2 quad has left the light loop (or skips
    /// its body), which happens wherever a quad straddles a cell boundary: lights vanish in
    /// one-pixel strokes along the grid. With every fragment of the draw running the same
    /// iterations the images equal forward's (docs/drivers.md). Its ES 3.0 path is unaffected.
    pub fn needs_uniform_light_loop(&self) -> bool {
        self.es == EsVersion::Es2 && !self.desktop && self.renderer.contains("SwiftShader")
    }

    /// A driver workaround: SwiftShader 4 loses parts of triangles that cross the eye's plane
    /// (clip w = 0), which its clipper should cut at the near plane, and Mesa's softpipe loses
    /// or doubles pixels of them; deferred's proxy spheres reaching behind the eye lost wedges
    /// of their light (docs/drivers.md), so there it bounds such a light by a full-screen
    /// triangle at its far end instead.
    pub fn loses_triangles_crossing_the_eye_plane(&self) -> bool {
        !self.desktop
            && (self.renderer.contains("SwiftShader") || self.renderer.contains("softpipe"))
    }

    /// A driver workaround: Mesa's softpipe clips two triangles sharing an edge that crosses a
    /// side of the view into pieces that do not meet, so a pixel on that edge is drawn by
    /// neither or both: deferred's proxy spheres crossing the frame's border lost or doubled
    /// their light there (docs/drivers.md), so there it bounds such a light by a full-screen
    /// triangle at its far end instead.
    pub fn clips_shared_edges_apart(&self) -> bool {
        !self.desktop && self.renderer.contains("softpipe")
    }

    /// A driver workaround: SwiftShader 4's `glClear` of a multisampled sRGB renderbuffer fills
    /// one sample (docs/drivers.md), so the renderer's MSAA target is filled by a draw first.
    /// Elsewhere that draw would be a full-screen pass every frame for nothing.
    pub fn clears_one_sample_of_srgb_msaa(&self) -> bool {
        !self.desktop && self.renderer.contains("SwiftShader")
    }

    /// Whether the context renders to half-float (RGBA16F) targets: what
    /// [`Renderer::render_offscreen_hdr`](crate::Renderer::render_offscreen_hdr) and HDR output
    /// need (ES 3.0: `GL_EXT_color_buffer_float` or `_half_float`; ES 2.0: `OES_texture_half_float`
    /// and `GL_EXT_color_buffer_half_float`).
    pub fn hdr_output(&self) -> bool {
        match self.es {
            EsVersion::Es3 => {
                self.has_extension("GL_EXT_color_buffer_float")
                    || self.has_extension("GL_EXT_color_buffer_half_float")
            }
            EsVersion::Es2 => {
                self.has_extension("GL_OES_texture_half_float")
                    && self.has_extension("GL_EXT_color_buffer_half_float")
            }
        }
    }

    /// The depth format of the renderer's own targets and its bits: 24-bit depth, else the
    /// 24 bits of a packed depth and stencil format, else ES 2.0's one required format, 16-bit.
    pub fn own_depth_format(&self) -> (u32, u32) {
        if self.depth24 {
            (glow::DEPTH_COMPONENT24, 24)
        } else if self.packed_depth_stencil {
            (glow::DEPTH24_STENCIL8, 24)
        } else {
            (glow::DEPTH_COMPONENT16, 16)
        }
    }

    /// True when fragment shaders have highp floats.
    pub fn fragment_has_highp(&self) -> bool {
        self.fragment_highp.precision > 0
    }

    /// Applies `restrictions` (see [`super::Restrictions`]). ES 3.0 requires fragment highp
    /// and float textures, so taking either away is only possible at the ES 2.0 level.
    pub fn restrict(&mut self, restrictions: &super::Restrictions) -> Result<(), GlError> {
        let taken = [
            (
                restrictions.no_fragment_highp,
                "no_fragment_highp",
                "a fragment stage without highp",
            ),
            (
                restrictions.no_float_textures,
                "no_float_textures",
                "a device without float textures",
            ),
        ];
        for (_, name, what) in taken.iter().filter(|(on, _, _)| *on) {
            if self.es != EsVersion::Es2 || self.desktop {
                // The restriction is the caller's contradiction, not the driver's limit.
                let context = if self.desktop {
                    "desktop OpenGL".to_string()
                } else {
                    format!("OpenGL {}", self.es)
                };
                return Err(GlError::Unsupported(format!(
                    "{name} needs an OpenGL ES 2.0 context ({what} exists only there: ES 3.0 \
                     requires it); this is {context}"
                )));
            }
        }
        if restrictions.no_fragment_highp {
            self.fragment_highp = Precision::default();
        }
        if restrictions.no_float_textures {
            self.float_textures = false;
            for float in FLOAT_TEXTURE_EXTENSIONS {
                self.extensions.remove(float);
            }
        }
        Ok(())
    }
}

/// The Mesa switches set in this process that lower the ES version a context offers, as a
/// parenthesis for a version error ("" when none is).
pub(crate) fn mesa_switches_note() -> String {
    let notes: Vec<&str> = [
        (
            "MESA_GLES_VERSION_OVERRIDE",
            "MESA_GLES_VERSION_OVERRIDE is set and caps the version",
        ),
        (
            "MESA_EXTENSION_OVERRIDE",
            "MESA_EXTENSION_OVERRIDE is set: Mesa offers ES 3.0 only with the extensions it needs",
        ),
    ]
    .into_iter()
    .filter(|(var, _)| std::env::var_os(var).is_some())
    .map(|(_, note)| note)
    .collect();
    if notes.is_empty() {
        String::new()
    } else {
        format!(" ({})", notes.join("; "))
    }
}

/// Whether `gl` allocates a 3 × 3 RGBA texture, as ES 2.0 allows without
/// `GL_OES_texture_npot` (clamped and unmipmapped, as render targets are). The binding of
/// `TEXTURE_2D` is given back, and the texture deleted.
///
/// # Safety
/// `gl` is current, with no pixel-unpack buffer bound (an ES 2.0 context has none).
unsafe fn takes_npot_targets(gl: &glow::Context) -> bool {
    let Ok(texture) = gl.create_texture() else {
        return false;
    };
    let bound = gl.get_parameter_texture(glow::TEXTURE_BINDING_2D);
    gl.bind_texture(glow::TEXTURE_2D, Some(texture));
    gl.tex_image_2d(
        glow::TEXTURE_2D,
        0,
        glow::RGBA as i32,
        3,
        3,
        0,
        glow::RGBA,
        glow::UNSIGNED_BYTE,
        glow::PixelUnpackData::Slice(None),
    );
    let taken = gl.get_error() == glow::NO_ERROR;
    gl.bind_texture(glow::TEXTURE_2D, bound);
    gl.delete_texture(texture);
    taken
}
