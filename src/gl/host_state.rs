//! The application's GL state around the renderer's calls. A game draws with the same context:
//! each entry into the renderer saves the state the renderer changes or depends on, sets the
//! part it depends on to what it assumes, and gives everything back on the way out, so the
//! game's vertex array, buffers, program, textures, samplers, framebuffers, viewport, blend,
//! depth, culling and pixel-store settings are as it left them (the way Dear ImGui's GL
//! back-end embeds). The attributes' constant values the renderer sets (locations 3 to 5), and
//! on ES 2.0 (no vertex array objects) the arrays at its locations, are saved and given back
//! one by one (`host_attributes.rs`).
#![allow(unsafe_code)]

use glow::HasContext;

use super::caps::Caps;
use super::ext_fns::{AttribPointerFns, VertexAttribDivisor};
use super::host_attributes::HostAttributes;
use super::host_draw_buffers::HostDrawBuffers;
use super::vertex_arrays::VertexArrays;

/// Texture units the renderer binds: 0 to 7 (`methods::maps::UNIT_MAPS` + 3), within the
/// 8 fragment units every ES 2.0 context has.
pub(super) const UNITS: usize = 8;

/// Capabilities the renderer enables and disables as each pass needs (saved and given back).
pub(super) const TOGGLED: [u32; 3] = [glow::BLEND, glow::CULL_FACE, glow::DEPTH_TEST];

/// Capabilities that change what the renderer draws and that it never uses: off during its
/// calls (a game's scissor box or stencil test would cut its frame), given back after.
pub(super) const OFF_INSIDE: [u32; 5] = [
    glow::SCISSOR_TEST,
    glow::STENCIL_TEST,
    glow::POLYGON_OFFSET_FILL,
    glow::SAMPLE_ALPHA_TO_COVERAGE,
    glow::SAMPLE_COVERAGE,
];

/// Pixel-store settings that move where uploads start: 0 inside. ES 3.0 state, and ES 2.0's
/// with `GL_EXT_unpack_subimage`.
pub(super) const UNPACK_ROWS: [u32; 3] = [
    glow::UNPACK_ROW_LENGTH,
    glow::UNPACK_SKIP_ROWS,
    glow::UNPACK_SKIP_PIXELS,
];

/// The same for 3D and array uploads: ES 3.0 state. GL applies them to 3D uploads alone,
/// but SwiftShader moves a 2D upload's start by a game's `UNPACK_SKIP_IMAGES` too: it read
/// past the renderer's light data (a dark picture, light loops that never ended).
pub(super) const UNPACK_IMAGES: [u32; 2] = [glow::UNPACK_IMAGE_HEIGHT, glow::UNPACK_SKIP_IMAGES];

/// The same for read-backs: ES 3.0, and ES 2.0 with `GL_NV_pack_subimage`.
pub(super) const PACK_ROWS: [u32; 3] = [
    glow::PACK_ROW_LENGTH,
    glow::PACK_SKIP_ROWS,
    glow::PACK_SKIP_PIXELS,
];

/// What the context has of the state a call saves, found once a device.
#[derive(Clone, Copy)]
pub(crate) struct HostFeatures {
    /// ES 3.0 state (an ES 3.x or desktop context, whatever level the renderer plays).
    pub(super) es3: bool,
    pub(super) desktop: bool,
    /// [`UNPACK_ROWS`] and [`PACK_ROWS`] exist.
    pub(super) unpack_rows: bool,
    pub(super) pack_rows: bool,
    /// ES's `GL_EXT_sRGB_write_control`: whether writes to an sRGB attachment encode is state
    /// a game may switch off (the renderer's picture assumes they do).
    pub(super) srgb_write_control: bool,
    /// `GL_SAMPLE_MASK` exists (ES 3.1, desktop 3.2): a game's sample mask would drop samples
    /// of the renderer's MSAA target.
    pub(super) sample_mask: bool,
    /// `GL_SAMPLE_SHADING` exists (ES 3.2 or `GL_OES_sample_shading`, desktop 4.0): a game's
    /// would shade each sample of the renderer's MSAA target on its own, at up to its sample
    /// count times the cost, and at the samples' positions rather than the pixel's.
    pub(super) sample_shading: bool,
    /// `GL_PRIMITIVE_RESTART_FIXED_INDEX` exists (ES 3.0, desktop 4.3): the renderer's 16-bit
    /// index 65 535 is a vertex of any mesh chunk of 65 536 vertices.
    pub(super) fixed_index_restart: bool,
    /// Without a vertex array of the renderer's own: what saves the application's arrays,
    /// and an instanced-arrays extension's divisor setter (their divisors are theirs too).
    pub(super) attrib_fns: Option<AttribPointerFns>,
    pub(super) divisor: Option<VertexAttribDivisor>,
    /// Texture units saved and given back: the context's, at most [`UNITS`].
    pub(super) units: usize,
    /// `GL_MAX_DRAW_BUFFERS` (ES 3.0 state): a framebuffer object's draw buffers saved.
    pub(super) max_draw_buffers: usize,
}

impl HostFeatures {
    /// From the context's capabilities; `own_vertex_array` when the renderer binds its own
    /// vertex array object (which keeps its arrays and divisors apart from the game's);
    /// `units`: its `GL_MAX_COMBINED_TEXTURE_IMAGE_UNITS`. Asks `gl` for its constants.
    pub(crate) fn of(
        gl: &glow::Context,
        caps: &Caps,
        own_vertex_array: bool,
        units: i32,
    ) -> HostFeatures {
        let es3 = caps.context_has_es3_state();
        let has = |name: &str| caps.has_extension(name);
        let desktop = caps.desktop;
        let version = (gl.version().major, gl.version().minor);
        HostFeatures {
            es3,
            desktop,
            unpack_rows: es3 || has("GL_EXT_unpack_subimage"),
            pack_rows: es3 || has("GL_NV_pack_subimage"),
            srgb_write_control: !desktop && has("GL_EXT_sRGB_write_control"),
            sample_mask: version >= if desktop { (3, 2) } else { (3, 1) },
            sample_shading: version >= if desktop { (4, 0) } else { (3, 2) }
                || has("GL_OES_sample_shading")
                || has("GL_ARB_sample_shading"),
            fixed_index_restart: es3 && (!desktop || version >= (4, 3)),
            attrib_fns: (!own_vertex_array)
                .then(super::ext_fns::attrib_pointer_fns)
                .flatten(),
            divisor: (!own_vertex_array)
                .then(|| super::ext_fns::vertex_attrib_divisor_ext(has))
                .flatten(),
            units: (units.max(0) as usize).min(UNITS),
            max_draw_buffers: match es3 {
                true => unsafe { gl.get_parameter_i32(glow::MAX_DRAW_BUFFERS) }.max(1) as usize,
                false => 0,
            },
        }
    }

    /// The pixel-store row lengths and skips the context has ([`UNPACK_ROWS`],
    /// [`UNPACK_IMAGES`], [`PACK_ROWS`]).
    pub(super) fn rows(&self) -> impl Iterator<Item = u32> {
        let unpack = self
            .unpack_rows
            .then_some(UNPACK_ROWS)
            .into_iter()
            .flatten();
        let images = self.es3.then_some(UNPACK_IMAGES).into_iter().flatten();
        let pack = self.pack_rows.then_some(PACK_ROWS).into_iter().flatten();
        unpack.chain(images).chain(pack)
    }
}

/// The application's state on entry; [`HostState::leave`] sets it back.
pub(crate) struct HostState {
    es3: bool,
    vertex_array: Option<glow::VertexArray>,
    array_buffer: Option<glow::Buffer>,
    element_buffer: Option<glow::Buffer>,
    pixel_buffers: [Option<glow::Buffer>; 2],
    program: Option<glow::Program>,
    /// The game deleted `program` while it was current: it lives only while it stays so.
    program_deleted: bool,
    active_texture: i32,
    textures: [Option<glow::Texture>; UNITS],
    samplers: [Option<glow::Sampler>; UNITS],
    units: usize,
    framebuffers: [Option<glow::Framebuffer>; 2],
    renderbuffer: Option<glow::Renderbuffer>,
    /// The bound draw framebuffer's draw buffers, where the call points them at attachment 0.
    draw_buffers: Option<HostDrawBuffers>,
    viewport: [i32; 4],
    /// The scissor box (the renderer's scissored clear sets it).
    scissor: [i32; 4],
    toggled: [bool; TOGGLED.len()],
    off_inside: [bool; OFF_INSIDE.len()],
    rasterizer_discard: bool,
    /// `SAMPLE_MASK` (ES 3.1, desktop 3.2): a game's sample mask would drop samples of the
    /// renderer's MSAA target. `None` where the context has no such capability.
    sample_mask: Option<bool>,
    /// `SAMPLE_SHADING` (`HostFeatures::sample_shading`), where the context has it.
    sample_shading: Option<bool>,
    /// `PRIMITIVE_RESTART_FIXED_INDEX` (ES 3.0, desktop 4.3): the renderer's 16-bit index
    /// 65 535 is a vertex of any mesh chunk of 65 536 vertices. `None` where the context has
    /// no such capability.
    fixed_index_restart: Option<bool>,
    blend_func: [i32; 4],
    blend_equation: [i32; 2],
    depth_func: i32,
    depth_mask: bool,
    depth_range: [f32; 2],
    color_mask: [bool; 4],
    cull_face: i32,
    front_face: i32,
    clear_color: [f32; 4],
    clear_depth: f32,
    alignment: [i32; 2],
    /// [`UNPACK_ROWS`], [`UNPACK_IMAGES`] and [`PACK_ROWS`], where the context has them.
    unpack_rows: Option<[i32; 3]>,
    unpack_images: Option<[i32; 2]>,
    pack_rows: Option<[i32; 3]>,
    /// `GL_FRAMEBUFFER_SRGB_EXT` on ES with `GL_EXT_sRGB_write_control`.
    srgb_write: Option<bool>,
    /// The attributes' constant values, and on ES 2.0 their arrays and divisors (no vertex
    /// array object keeps them apart).
    attributes: HostAttributes,
    /// Desktop GL's own state that changes the picture: its polygon mode (a wireframe debug
    /// view) and whether sRGB framebuffers encode (the shaders encode already).
    desktop: Option<DesktopState>,
}

/// See [`HostState::desktop`].
struct DesktopState {
    polygon_mode: i32,
    framebuffer_srgb: bool,
    /// `PRIMITIVE_RESTART` (desktop 3.1), restarting at the game's own index.
    primitive_restart: bool,
}

impl HostState {
    /// Makes the game's program current again. One it deleted while current cannot be: once
    /// the call made another current, GL ended it (binding its name again would fail and leave
    /// the renderer's program for the game to write), so none is left current; a call that
    /// bound none keeps it, still alive. A program of the renderer's given the ended one's
    /// name is told apart by its delete status.
    unsafe fn give_program_back(&self, gl: &glow::Context) {
        match (self.program, self.program_deleted) {
            (Some(program), true) => {
                let current = gl.get_parameter_program(glow::CURRENT_PROGRAM);
                let alive = current == Some(program)
                    && gl.get_program_parameter_i32(program, glow::DELETE_STATUS) != 0;
                if !alive {
                    gl.use_program(None);
                }
            }
            (program, _) => gl.use_program(program),
        }
    }

    /// Saves the application's state and sets what the renderer assumes: its own vertex
    /// array (`vao` with how to bind it: an ES 3.x or desktop context, ES 2.0 with
    /// `GL_OES_vertex_array_object`), the bound framebuffer drawing into its
    /// attachment 0 alone (`host_draw_buffers.rs`), no pixel buffer, no sampler objects on
    /// its units, the capabilities of `OFF_INSIDE` off, additive blend equations, no sample
    /// mask nor sample shading, counter-clockwise front faces, the full depth range, a clear
    /// depth of 1, pixel rows that start where the data does and texture unit 0 active (a
    /// game's active unit past the saved ones keeps its texture), no primitive restart, no attribute divisors; on ES
    /// with `GL_EXT_sRGB_write_control` sRGB encoding on; on desktop GL, filled polygons and
    /// no sRGB encoding.
    pub(crate) fn enter(
        gl: &glow::Context,
        features: &HostFeatures,
        vao: Option<(glow::VertexArray, VertexArrays)>,
    ) -> Self {
        let HostFeatures {
            es3,
            desktop,
            unpack_rows,
            pack_rows,
            srgb_write_control,
            sample_mask,
            sample_shading,
            fixed_index_restart,
            attrib_fns,
            divisor,
            units,
            max_draw_buffers,
        } = *features;
        unsafe {
            let int = |p| gl.get_parameter_i32(p);
            let active_texture = int(glow::ACTIVE_TEXTURE);
            let mut textures = [None; UNITS];
            let mut samplers = [None; UNITS];
            for unit in 0..units {
                gl.active_texture(glow::TEXTURE0 + unit as u32);
                textures[unit] = gl.get_parameter_texture(glow::TEXTURE_BINDING_2D);
                if es3 {
                    samplers[unit] = gl.get_parameter_sampler(glow::SAMPLER_BINDING);
                    gl.bind_sampler(unit as u32, None);
                }
            }
            gl.active_texture(glow::TEXTURE0);
            let mut viewport = [0i32; 4];
            gl.get_parameter_i32_slice(glow::VIEWPORT, &mut viewport);
            let mut scissor = [0i32; 4];
            gl.get_parameter_i32_slice(glow::SCISSOR_BOX, &mut scissor);
            let mut clear_color = [0f32; 4];
            gl.get_parameter_f32_slice(glow::COLOR_CLEAR_VALUE, &mut clear_color);
            let mut depth_range = [0f32; 2];
            gl.get_parameter_f32_slice(glow::DEPTH_RANGE, &mut depth_range);
            let blend_func = [
                int(glow::BLEND_SRC_RGB),
                int(glow::BLEND_DST_RGB),
                int(glow::BLEND_SRC_ALPHA),
                int(glow::BLEND_DST_ALPHA),
            ];
            let program = gl.get_parameter_program(glow::CURRENT_PROGRAM);
            let framebuffers = if es3 {
                [
                    gl.get_parameter_framebuffer(glow::DRAW_FRAMEBUFFER_BINDING),
                    gl.get_parameter_framebuffer(glow::READ_FRAMEBUFFER_BINDING),
                ]
            } else {
                [
                    gl.get_parameter_framebuffer(glow::FRAMEBUFFER_BINDING),
                    None,
                ]
            };
            let draw_framebuffer = framebuffers[0];
            let saved = HostState {
                es3,
                vertex_array: vao
                    .and_then(|_| gl.get_parameter_vertex_array(glow::VERTEX_ARRAY_BINDING)),
                array_buffer: gl.get_parameter_buffer(glow::ARRAY_BUFFER_BINDING),
                element_buffer: gl.get_parameter_buffer(glow::ELEMENT_ARRAY_BUFFER_BINDING),
                pixel_buffers: if es3 {
                    [
                        gl.get_parameter_buffer(glow::PIXEL_PACK_BUFFER_BINDING),
                        gl.get_parameter_buffer(glow::PIXEL_UNPACK_BUFFER_BINDING),
                    ]
                } else {
                    [None; 2]
                },
                program,
                program_deleted: program
                    .is_some_and(|p| gl.get_program_parameter_i32(p, glow::DELETE_STATUS) != 0),
                active_texture,
                textures,
                samplers,
                units,
                framebuffers,
                renderbuffer: gl.get_parameter_renderbuffer(glow::RENDERBUFFER_BINDING),
                draw_buffers: es3
                    .then(|| {
                        HostDrawBuffers::enter(gl, desktop, draw_framebuffer, max_draw_buffers)
                    })
                    .flatten(),
                viewport,
                scissor,
                toggled: TOGGLED.map(|c| gl.is_enabled(c)),
                off_inside: OFF_INSIDE.map(|c| gl.is_enabled(c)),
                rasterizer_discard: es3 && gl.is_enabled(glow::RASTERIZER_DISCARD),
                sample_mask: sample_mask.then(|| gl.is_enabled(glow::SAMPLE_MASK)),
                sample_shading: sample_shading.then(|| gl.is_enabled(glow::SAMPLE_SHADING)),
                fixed_index_restart: fixed_index_restart
                    .then(|| gl.is_enabled(glow::PRIMITIVE_RESTART_FIXED_INDEX)),
                blend_func,
                blend_equation: [
                    int(glow::BLEND_EQUATION_RGB),
                    int(glow::BLEND_EQUATION_ALPHA),
                ],
                depth_func: int(glow::DEPTH_FUNC),
                depth_mask: gl.get_parameter_bool(glow::DEPTH_WRITEMASK),
                depth_range,
                color_mask: gl.get_parameter_bool_array::<4>(glow::COLOR_WRITEMASK),
                cull_face: int(glow::CULL_FACE_MODE),
                front_face: int(glow::FRONT_FACE),
                clear_color,
                clear_depth: gl.get_parameter_f32(glow::DEPTH_CLEAR_VALUE),
                alignment: [int(glow::PACK_ALIGNMENT), int(glow::UNPACK_ALIGNMENT)],
                unpack_rows: unpack_rows.then(|| UNPACK_ROWS.map(int)),
                unpack_images: es3.then(|| UNPACK_IMAGES.map(int)),
                pack_rows: pack_rows.then(|| PACK_ROWS.map(int)),
                srgb_write: srgb_write_control.then(|| gl.is_enabled(glow::FRAMEBUFFER_SRGB)),
                attributes: HostAttributes::save(
                    gl,
                    vao.is_none().then_some(attrib_fns).flatten(),
                    vao.is_none().then_some(divisor).flatten(),
                ),
                desktop: desktop.then(|| {
                    let mut polygon_mode = [glow::FILL as i32; 2];
                    gl.get_parameter_i32_slice(glow::POLYGON_MODE, &mut polygon_mode);
                    DesktopState {
                        polygon_mode: polygon_mode[0],
                        framebuffer_srgb: gl.is_enabled(glow::FRAMEBUFFER_SRGB),
                        primitive_restart: gl.is_enabled(glow::PRIMITIVE_RESTART),
                    }
                }),
            };
            // What the renderer never switches on is switched off only where it is on, and
            // (in `leave`) on again only where it was.
            let off = |c, on: bool| {
                if on {
                    gl.disable(c)
                }
            };
            if let Some(d) = &saved.desktop {
                gl.polygon_mode(glow::FRONT_AND_BACK, glow::FILL);
                gl.disable(glow::FRAMEBUFFER_SRGB);
                off(glow::PRIMITIVE_RESTART, d.primitive_restart);
            }
            off(
                glow::PRIMITIVE_RESTART_FIXED_INDEX,
                saved.fixed_index_restart == Some(true),
            );
            off(glow::SAMPLE_MASK, saved.sample_mask == Some(true));
            off(glow::SAMPLE_SHADING, saved.sample_shading == Some(true));
            if let Some((vao, arrays)) = vao {
                arrays.bind(gl, Some(vao));
            }
            if es3 {
                gl.bind_buffer(glow::PIXEL_PACK_BUFFER, None);
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, None);
                off(glow::RASTERIZER_DISCARD, saved.rasterizer_discard);
            }
            for (p, v) in saved.rows() {
                if v != 0 {
                    gl.pixel_store_i32(p, 0);
                }
            }
            if saved.srgb_write.is_some() {
                gl.enable(glow::FRAMEBUFFER_SRGB);
            }
            for (c, on) in OFF_INSIDE.into_iter().zip(saved.off_inside) {
                off(c, on);
            }
            gl.blend_equation(glow::FUNC_ADD);
            gl.front_face(glow::CCW);
            gl.depth_range(0.0, 1.0);
            gl.clear_depth(1.0);
            gl.color_mask(true, true, true, true);
            saved
        }
    }

    /// The saved row lengths and skips (where the context has them), with their names.
    fn rows(&self) -> impl Iterator<Item = (u32, i32)> {
        let unpack = (self.unpack_rows.into_iter()).flat_map(|v| UNPACK_ROWS.into_iter().zip(v));
        let images =
            (self.unpack_images.into_iter()).flat_map(|v| UNPACK_IMAGES.into_iter().zip(v));
        let pack = (self.pack_rows.into_iter()).flat_map(|v| PACK_ROWS.into_iter().zip(v));
        unpack.chain(images).chain(pack)
    }

    /// The framebuffer the application had bound for drawing (`None`: the default one): the
    /// frame's target, read once a call.
    pub(crate) fn draw_framebuffer(&self) -> Option<glow::Framebuffer> {
        self.framebuffers[0]
    }

    /// Gives the application its state back.
    pub(crate) fn leave(self, gl: &glow::Context, vao: Option<(glow::VertexArray, VertexArrays)>) {
        let enable = |c, on| unsafe {
            if on {
                gl.enable(c)
            } else {
                gl.disable(c)
            }
        };
        unsafe {
            // The vertex array first: on ES 3.0 the element buffer is its state.
            if let Some((_, arrays)) = vao {
                arrays.bind(gl, self.vertex_array);
            } else {
                gl.bind_buffer(glow::ELEMENT_ARRAY_BUFFER, self.element_buffer);
            }
            self.attributes.restore(gl);
            gl.bind_buffer(glow::ARRAY_BUFFER, self.array_buffer);
            self.give_program_back(gl);
            for unit in 0..self.units {
                gl.active_texture(glow::TEXTURE0 + unit as u32);
                gl.bind_texture(glow::TEXTURE_2D, self.textures[unit]);
                if self.es3 {
                    gl.bind_sampler(unit as u32, self.samplers[unit]);
                }
            }
            gl.active_texture(self.active_texture as u32);
            if self.es3 {
                gl.bind_framebuffer(glow::DRAW_FRAMEBUFFER, self.framebuffers[0]);
                if let Some(draw_buffers) = &self.draw_buffers {
                    draw_buffers.leave(gl);
                }
                gl.bind_framebuffer(glow::READ_FRAMEBUFFER, self.framebuffers[1]);
                gl.bind_buffer(glow::PIXEL_PACK_BUFFER, self.pixel_buffers[0]);
                gl.bind_buffer(glow::PIXEL_UNPACK_BUFFER, self.pixel_buffers[1]);
            } else {
                gl.bind_framebuffer(glow::FRAMEBUFFER, self.framebuffers[0]);
            }
            gl.bind_renderbuffer(glow::RENDERBUFFER, self.renderbuffer);
            let [x, y, w, h] = self.viewport;
            gl.viewport(x, y, w, h);
            let [x, y, w, h] = self.scissor;
            gl.scissor(x, y, w, h);
            for (c, on) in TOGGLED.into_iter().zip(self.toggled) {
                enable(c, on);
            }
            let on_again = |c, on: bool| {
                if on {
                    gl.enable(c)
                }
            };
            for (c, on) in OFF_INSIDE.into_iter().zip(self.off_inside) {
                on_again(c, on);
            }
            on_again(glow::RASTERIZER_DISCARD, self.rasterizer_discard);
            on_again(
                glow::PRIMITIVE_RESTART_FIXED_INDEX,
                self.fixed_index_restart == Some(true),
            );
            on_again(glow::SAMPLE_MASK, self.sample_mask == Some(true));
            on_again(glow::SAMPLE_SHADING, self.sample_shading == Some(true));
            let [sr, dr, sa, da] = self.blend_func.map(|v| v as u32);
            gl.blend_func_separate(sr, dr, sa, da);
            let [er, ea] = self.blend_equation.map(|v| v as u32);
            gl.blend_equation_separate(er, ea);
            gl.depth_func(self.depth_func as u32);
            gl.depth_mask(self.depth_mask);
            gl.depth_range(self.depth_range[0].into(), self.depth_range[1].into());
            let [r, g, b, a] = self.color_mask;
            gl.color_mask(r, g, b, a);
            gl.cull_face(self.cull_face as u32);
            gl.front_face(self.front_face as u32);
            let [r, g, b, a] = self.clear_color;
            gl.clear_color(r, g, b, a);
            gl.clear_depth(self.clear_depth.into());
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, self.alignment[0]);
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, self.alignment[1]);
            for (p, v) in self.rows() {
                if v != 0 {
                    gl.pixel_store_i32(p, v);
                }
            }
            if let Some(on) = self.srgb_write {
                enable(glow::FRAMEBUFFER_SRGB, on);
            }
            if let Some(desktop) = &self.desktop {
                gl.polygon_mode(glow::FRONT_AND_BACK, desktop.polygon_mode as u32);
                enable(glow::FRAMEBUFFER_SRGB, desktop.framebuffer_srgb);
                on_again(glow::PRIMITIVE_RESTART, desktop.primitive_restart);
            }
        }
    }
}
