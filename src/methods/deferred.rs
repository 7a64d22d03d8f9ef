//! Traditional deferred shading (ES 3.0 multiple render targets).
//!
//! 1. **Geometry pass** — opaque objects write albedo, normal + view depth and specular into
//!    the G-buffer (layout and memory per pixel: `gl::gbuffer`).
//! 2. **Light pass** — every light is drawn as a proxy sphere around it (instanced: a light is
//!    64 bytes of a batch, not a draw call of its own), its near side depth
//!    tested so surfaces in front of the sphere are skipped, or its far side (surfaces behind
//!    skipped) when the near side would be clipped by the near plane (a full-screen triangle
//!    only when the far side would be clipped too); each covered pixel reads the G-buffer once
//!    and adds the light's contribution to a float accumulation buffer. The light model is the
//!    same GLSL chunk as every other method's.
//! 3. **Composite** — ambient, occluded by the factor the geometry pass leaves in the
//!    accumulation's alpha, plus the accumulated light, encoded like the forward methods.
//! 4. **Transparent objects** — documented forward fallback: the composite wrote the G-buffer's
//!    depth into the target, the opaque objects' depth is laid over it again exactly, and
//!    transparent objects are drawn back to front with plain forward shading.
//!
//! The G-buffer keeps float normals, depth and 11-bit albedo/specular, so deferred matches plain
//! forward within 2/255 (tested); its cost is memory and bandwidth: 52 bytes per pixel, 44
//! without `GL_EXT_float_blend` (`gl::gbuffer`).

mod light_instances;
mod proxy;
mod proxy_sphere;

use glam::{Mat4, Vec3};

use super::directional::DirectionalUniforms;
use super::forward::Forward;
use super::geometry::{shade_object, sort_objects, GeometryProgram, UNIT_METHOD};
use super::uniforms::{self, Surface, Transforms};
use super::{FrameContext, MethodDesc, MethodStats, ShaderFeatures, ShadingMethod, Support};
use crate::cluster::grid::GridProjection;
use crate::gl::gbuffer::{self, GBuffer};
use crate::gl::mesh::GpuMesh;
use crate::gl::program::{ProgramKey, Resolver, Sampler, Uniform, UniformSet};
use crate::gl::state::{Blend, Cull, DepthTest, RenderState};
use crate::gl::{Caps, Device, EsVersion};
use crate::scene::{Material, Projection};
use crate::Error;
use light_instances::{light_instance, LightInstances};
use proxy::{Proxy, ProxyReach};

/// The table row.
pub const DESC: MethodDesc = MethodDesc {
    name: "deferred",
    summary: "traditional deferred: G-buffer (MRT), then one proxy volume per light",
    min_es: EsVersion::Es3,
    required_extensions: &["GL_EXT_color_buffer_float"],
    supported,
    // The G-buffer would need every attachment per sample.
    multisample: false,
    create: |_| Ok(Box::new(Deferred::default())),
};

fn supported(caps: &Caps) -> Support {
    // Its transparent objects are drawn forward, from the data textures.
    if let Some(why) = super::forward::data_textures_unfit(caps) {
        return Support::Unsupported(why);
    }
    match gbuffer::unsupported_reason(caps) {
        Some(reason) => Support::Unsupported(reason),
        None if gbuffer::half_float_accumulation(caps) => Support::Fallback(HALF_FLOAT_SUMS.into()),
        // Transparent objects take the documented forward fallback; opaque scenes are fully
        // deferred, so this is not reported as a degradation.
        None => Support::Supported,
    }
}

/// What a half-float accumulation costs: each light's proxy adds its radiance to the pixel's
/// sum by blending, rounded to fp16's 11 bits of the sum, so a light whose share falls below
/// half a step is lost and a pixel many lights reach darkens (docs/architecture.md, "Deferred").
pub const HALF_FLOAT_SUMS: &str = "lights summed in half floats (RGBA16F) because \
     GL_EXT_float_blend is missing: where hundreds of lights reach one pixel it darkens (255 \
     equal ones: up to 9/255 from forward, 1 000: 23/255); tiled and clustered sum in the shader";

/// What the light pass scales radiance by before the accumulation adds it (the composite
/// undoes it): the exposure rounded to a power of two, so the scaling is exact. The
/// accumulation is half-float without `GL_EXT_float_blend`, which holds about the displayed
/// range only pre-exposed: at a low exposure a bright frame summed past 65 504 to Inf (a 2·10⁵
/// light at −15 EV: white where forward's Reinhard gives 238/255), and at a high one faint
/// lights' shares rounded to zero (eight lights of 2·10⁻⁸ a pixel at +15 EV: black where
/// forward shows 17/255). A sum that passes 65 504 pre-exposed is white on screen anyway. HDR
/// output, which takes no exposure, keeps radiance as it is.
fn accumulation_scale(ctx: &FrameContext) -> f32 {
    if ctx.features.has(ShaderFeatures::OUTPUT_HDR) {
        return 1.0;
    }
    ctx.options.exposure_ev.round().exp2()
}

/// Channels a count frame spreads its proxies over, light after light, each adding 1 to one:
/// in half floats each channel counts exactly up to 2 048, the four together up to 8 192.
const COUNT_CHANNELS: usize = 4;

/// Texture units of the G-buffer's textures, in `GBuffer::bind_textures` order, and of its
/// depth.
const UNIT_G_ALBEDO: u32 = UNIT_METHOD;
const UNIT_G_NORMAL_DEPTH: u32 = UNIT_METHOD + 1;
const UNIT_G_SPECULAR: u32 = UNIT_METHOD + 2;
const UNIT_ACCUM: u32 = UNIT_METHOD + 3;
const UNIT_G_DEPTH: u32 = UNIT_METHOD + 4;

/// The geometry pass's program (`gbuffer`): the surface point is stored through the same
/// window mapping the light pass reads it back with.
pub struct GBufferProgram {
    transforms: Transforms,
    surface: Surface,
    viewport: Uniform<[f32; 2]>,
    half_extent: Uniform<[f32; 2]>,
    /// [`accumulation_scale`], for what the surface itself adds (emission).
    accum_scale: Uniform<f32>,
}

impl UniformSet for GBufferProgram {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        let f = uniforms::features(r);
        // Emission starts the accumulation (the count variants have none: they start at 0).
        let adds = f.has(ShaderFeatures::EMISSIVE);
        GBufferProgram {
            transforms: Transforms::resolve(r, true),
            surface: Surface::gbuffer(r),
            viewport: r.required("u_viewport"),
            half_extent: r.required("u_halfExtent"),
            accum_scale: r.required_when(adds, "u_accumScale"),
        }
    }
}

impl GeometryProgram for GBufferProgram {
    fn transforms(&self) -> &Transforms {
        &self.transforms
    }
    fn surface(&self) -> &Surface {
        &self.surface
    }
}

/// The light pass's program (`deferred_light`, `deferred_light_fullscreen`), whose lights are
/// its instances (`light_instances.rs`). A count variant reads only the G-buffer's coverage.
pub struct LightProgram {
    /// The projection (`deferred_light` only: the full-screen triangle has none).
    projection: Option<Uniform<Mat4>>,
    g_albedo: Uniform<Sampler>,
    g_normal_depth: Uniform<Sampler>,
    g_specular: Uniform<Sampler>,
    viewport: Uniform<[f32; 2]>,
    half_extent: Uniform<[f32; 2]>,
    orthographic: Uniform<f32>,
}

impl UniformSet for LightProgram {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        let f = uniforms::features(r);
        let colour = !f.counting();
        let proxy = r.shader() == "deferred_light";
        LightProgram {
            projection: proxy.then(|| r.required("u_projection")),
            g_albedo: r.required_when(colour, "u_gAlbedo"),
            g_normal_depth: r.required("u_gNormalDepth"),
            g_specular: r.required_when(colour && f.has(ShaderFeatures::SPECULAR), "u_gSpecular"),
            viewport: r.required_when(colour, "u_viewport"),
            half_extent: r.required_when(colour, "u_halfExtent"),
            orthographic: r.required_when(colour, "u_orthographic"),
        }
    }
}

/// The composite's program (`deferred_composite`).
pub struct CompositeProgram {
    g_albedo: Uniform<Sampler>,
    g_normal_depth: Uniform<Sampler>,
    accum: Uniform<Sampler>,
    g_depth: Uniform<Sampler>,
    frame_origin: Uniform<[f32; 2]>,
    ambient: Uniform<Vec3>,
    exposure: Uniform<f32>,
    /// Undoes [`accumulation_scale`].
    accum_to_radiance: Uniform<f32>,
    alpha: Uniform<f32>,
    heat_scale: Uniform<f32>,
    /// Directional lights: the G-buffer's specular and the surface point's reconstruction.
    g_specular: Uniform<Sampler>,
    viewport: Uniform<[f32; 2]>,
    half_extent: Uniform<[f32; 2]>,
    orthographic: Uniform<f32>,
    directional: DirectionalUniforms,
}

impl UniformSet for CompositeProgram {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        let f = uniforms::features(r);
        let colour = !f.counting();
        // The eye's direction (from the surface point) is read only by the specular term.
        let directional =
            colour && f.has(ShaderFeatures::DIRECTIONAL) && f.has(ShaderFeatures::SPECULAR);
        CompositeProgram {
            g_albedo: r.required_when(colour, "u_gAlbedo"),
            g_normal_depth: r.required("u_gNormalDepth"),
            accum: r.required("u_accum"),
            g_depth: r.required("u_gDepth"),
            frame_origin: r.required("u_frameOrigin"),
            ambient: r.required_when(colour, "u_ambient"),
            exposure: r.required_when(colour && !f.has(ShaderFeatures::OUTPUT_HDR), "u_exposure"),
            accum_to_radiance: r.required_when(colour, "u_accumToRadiance"),
            alpha: r.required_when(colour, "u_alpha"),
            heat_scale: r.required_when(
                f.has(ShaderFeatures::COUNT_EVALS) && f.has(ShaderFeatures::COUNT_HEATMAP),
                "u_heatScale",
            ),
            g_specular: r.required_when(directional, "u_gSpecular"),
            viewport: r.required_when(directional, "u_viewport"),
            half_extent: r.required_when(directional, "u_halfExtent"),
            orthographic: r.required_when(directional, "u_orthographic"),
            directional: DirectionalUniforms::resolve(r, colour),
        }
    }
}

/// Deferred's GPU state.
#[derive(Default)]
pub struct Deferred {
    /// The G-buffer, kept for two sizes (two views a frame).
    gbuffer: crate::gl::two_sizes::TwoSizes<GBuffer>,
    sphere: Option<GpuMesh>,
    fullscreen: Option<GpuMesh>,
    lights: LightInstances,
    /// What the light instances were last made from: a frame with the same draws them again.
    instances_key: Option<InstancesKey>,
    transparent: Forward,
    /// Frames in a row that needed no specular target (see [`SPECULAR_KEPT_FRAMES`]).
    frames_without_specular: u32,
    /// Frames in a row without lights or without opaque objects: frames that draw no
    /// G-buffer (see [`super::IDLE_FRAMES_KEPT`]).
    idle_frames: u32,
}

/// Frames the G-buffer keeps its specular target after the last that needed it: an object
/// that comes and goes (a pickup, a door, one the game culls) would otherwise remake the
/// whole G-buffer each time (about 100 MB at 1080p).
const SPECULAR_KEPT_FRAMES: u32 = 120;

/// Everything a frame's light instances are a function of: the lights (by generation), the
/// camera's kind, planes and lens and the frame's rows, which choose each light's proxy (a
/// lens or frame height alone turns a sphere too wide for rasterizers full screen), and the
/// accumulation's scale.
#[derive(Clone, Copy, Debug, PartialEq)]
struct InstancesKey {
    lights_generation: u64,
    /// The camera's projection: its kind, lens and planes.
    projection: Projection,
    near: u64,
    far: u64,
    rows: u32,
    scale: u32,
    /// The instances hold spot terms (the variant has spots).
    spots: bool,
    /// No light took its near side ([`ProxyReach::biased_toward`]).
    biased_toward: bool,
}

/// What a light pass did.
struct LightPass {
    /// Bytes of light instances uploaded.
    uploaded: usize,
    /// It drew the last frame's instances.
    reused: bool,
    /// What its instances were made from: kept once the frame's GL check passes.
    key: InstancesKey,
}

impl Deferred {
    /// Allocates what a frame of `ctx` needs (kept while its size and specular target stay),
    /// leaving the frame's framebuffer bound (making the G-buffer binds its own).
    pub(super) fn prepare(&mut self, ctx: &FrameContext) -> Result<(), Error> {
        if !draws_opaque(ctx) {
            return Ok(());
        }
        let dev = ctx.dev;
        let target = ctx.target;
        let has = self.gbuffer.get().is_some_and(GBuffer::has_specular);
        let prepared = self.ensure_resources(dev, ctx.viewport, has || needs_specular_target(ctx));
        dev.bind_framebuffer(target);
        prepared
    }

    /// Whether this frame's G-buffer has the specular target: where the frame needs it, and
    /// kept for [`SPECULAR_KEPT_FRAMES`] frames after the last that did.
    fn keeps_specular(&mut self, needed: bool) -> bool {
        self.frames_without_specular = match needed {
            true => 0,
            false => self.frames_without_specular.saturating_add(1),
        };
        let has = self.gbuffer.get().is_some_and(GBuffer::has_specular);
        needed || (has && self.frames_without_specular < SPECULAR_KEPT_FRAMES)
    }

    /// The G-buffer of `size`, with the specular target if `specular` (made anew when that
    /// changes), and the meshes.
    fn ensure_resources(
        &mut self,
        dev: &Device,
        size: (u32, u32),
        specular: bool,
    ) -> Result<(), Error> {
        self.gbuffer.fit(
            |g| g.size() == size && g.has_specular() == specular,
            |g| g.size() != size,
            || GBuffer::new(dev, size.0, size.1, specular),
            |mut g| g.destroy(dev),
        )?;
        if self.sphere.is_none() {
            self.sphere = Some(GpuMesh::new(dev, &proxy_sphere::unit_sphere())?);
            self.fullscreen = Some(GpuMesh::new(dev, &crate::gl::mesh::fullscreen_triangle())?);
        }
        Ok(())
    }

    /// Frees what the G-buffer passes hold: the G-buffer, the proxy meshes, the light
    /// instances (the transparent objects' forward pass keeps its own).
    fn free_gbuffer_passes(&mut self, dev: &Device) {
        for mut g in self.gbuffer.take_all() {
            g.destroy(dev);
        }
        for mut m in [self.sphere.take(), self.fullscreen.take()]
            .into_iter()
            .flatten()
        {
            m.destroy(dev);
        }
        self.lights.destroy(dev);
        self.instances_key = None;
    }

    /// Draws the opaque objects of `ctx.order` into the G-buffer.
    fn geometry_pass(&self, ctx: &mut FrameContext) -> Result<(), Error> {
        self.gbuffer
            .get()
            .expect("allocated")
            .begin_geometry(ctx.dev);
        // LEQUAL: where surfaces coincide, the last one drawn wins, exactly as in the forward
        // methods' shading pass after their depth prepass.
        RenderState {
            depth_test: DepthTest::LessEqual,
            depth_write: true,
            blend: Blend::Off,
            cull: Cull::None,
            color_write: true,
        }
        .apply(ctx.dev);
        let drawn = self.draw_gbuffer_objects(ctx, 0..ctx.order.opaque.len());
        // The light volumes are tested against the depth where it lies.
        ctx.dev.set_depth_bias(0.0);
        drawn
    }

    /// Draws the opaque objects `range` (of `ctx.order.opaque`) with the G-buffer program, in
    /// the state the caller set.
    fn draw_gbuffer_objects(
        &self,
        ctx: &mut FrameContext,
        range: std::ops::Range<usize>,
    ) -> Result<(), Error> {
        // The pass stores each surface point as its depth and window offset (gbuffer.frag),
        // through the same mapping the light pass reads it back with.
        let (half, _) = half_extent(ctx);
        let viewport = [ctx.viewport.0 as f32, ctx.viewport.1 as f32];
        // Directional lights are the composite's: the G-buffer variant is the same without.
        let features = ctx.features;
        ctx.features = features.with(ShaderFeatures::DIRECTIONAL, false);
        let scale = accumulation_scale(ctx);
        let mut drawn = Ok(());
        let mut bound = None;
        for k in range {
            let i = ctx.order.opaque[k];
            let mut bind = |p: &GBufferProgram, dev: &Device| {
                p.viewport.set(dev, viewport);
                p.half_extent.set(dev, half);
                p.accum_scale.set(dev, scale);
            };
            drawn = shade_object(ctx, i, "gbuffer", 1, &mut bind, &mut bound);
            if drawn.is_err() {
                break;
            }
        }
        ctx.features = features;
        drawn
    }

    /// Where transparent objects follow, the opaque objects' depth laid again over the
    /// composite's copy, as forward lays it: a 24-bit depth read back as a float and written
    /// again lands a step farther at some depths on Mesa's and ANGLE's drivers, and a
    /// transparent surface on an opaque one (a highlight drawn over a mesh) then showed where
    /// forward hides it. `LESS` keeps what lies nearer (the application's geometry, a copy
    /// that came back nearer). Cut-outs take the G-buffer program, which cuts them, with
    /// colour writes off.
    fn exact_depth_under_transparent(&self, ctx: &mut FrameContext) -> Result<(), Error> {
        if ctx.order.transparent.is_empty() || ctx.features.counting() {
            return Ok(());
        }
        if ctx.order.cut_out_from > 0 {
            super::geometry::depth_prepass(ctx)?;
        }
        let cut_outs = ctx.order.cut_out_from..ctx.order.opaque.len();
        let drawn = if cut_outs.is_empty() {
            Ok(())
        } else {
            RenderState {
                color_write: false,
                ..RenderState::DEPTH_PREPASS
            }
            .apply(ctx.dev);
            self.draw_gbuffer_objects(ctx, cut_outs)
        };
        ctx.dev.set_depth_bias(0.0);
        drawn
    }

    fn light_pass(&mut self, ctx: &mut FrameContext) -> Result<LightPass, Error> {
        let dev = ctx.dev;
        let gb = self.gbuffer.get().expect("allocated");
        gb.begin_accumulation(dev);
        gb.bind_textures(dev, UNIT_G_ALBEDO);
        // Metallic-roughness compiled in only where a material uses it (the BRDF is then
        // chosen per pixel from the G-buffer); directional lights are the composite's.
        let features = ctx
            .features
            .with(ShaderFeatures::SPECULAR, gb.has_specular())
            .with(
                ShaderFeatures::METALLIC_ROUGHNESS,
                in_gbuffer_any(ctx, Material::is_metallic_roughness),
            )
            .with(ShaderFeatures::DIRECTIONAL, false);
        let (half, ortho) = half_extent(ctx);
        let scale = accumulation_scale(ctx);
        let viewport = [ctx.viewport.0 as f32, ctx.viewport.1 as f32];
        let reach = ProxyReach {
            camera: &ctx.scene.camera,
            near: ctx.near as f32,
            far: ctx.scene.camera.far_clip_range().0 as f32,
            projection: ctx.projection.as_dmat4(),
            eye_plane_unreliable: dev.caps().loses_triangles_crossing_the_eye_plane(),
            sides_unreliable: dev.caps().clips_shared_edges_apart(),
            rows: ctx.viewport.1,
            biased_toward: in_gbuffer_any(ctx, |m| m.depth_bias > 0.0),
            biased_away: in_gbuffer_any(ctx, |m| m.depth_bias < 0.0),
        };
        // Lights with the same proxy drawn together, as instances of it, in their order: the
        // state, program, uniforms and arrays set once for them. `k` numbers the lights drawn,
        // whatever their proxy.
        let drawn = || {
            ctx.lights
                .iter()
                .filter(|l| l.cull_radius > 0.0)
                .enumerate()
        };
        // A still frame (nothing the instances are made from changed) draws the last ones.
        let key = InstancesKey {
            lights_generation: ctx.lights_generation,
            projection: ctx.scene.camera.projection,
            near: ctx.near.to_bits(),
            far: ctx.far.to_bits(),
            rows: ctx.viewport.1,
            scale: scale.to_bits(),
            spots: features.has(ShaderFeatures::SPOT),
            biased_toward: reach.biased_toward,
        };
        let reused = self.instances_key == Some(key)
            && self.lights.hold_all()
            && !self.lights.note_still_frame();
        self.instances_key = None;
        let mut uploaded = 0;
        for (slot, proxy) in Proxy::ALL.into_iter().enumerate() {
            let (shader, mesh) = if proxy.full_screen() {
                ("deferred_light_fullscreen", self.fullscreen.as_ref())
            } else {
                ("deferred_light", self.sphere.as_ref())
            };
            let program = ProgramKey {
                shader,
                features: features.0,
                dialect: dev.es(),
            };
            let defines = || features.defines(dev.es(), 1);
            let mut lights = drawn().filter(|(_, l)| reach.proxy(l) == proxy).peekable();
            let none = if reused {
                self.lights.held(slot) == Some(0)
            } else {
                lights.peek().is_none()
            };
            if none {
                self.lights.draw_none(dev, slot);
                if ctx.warm_up {
                    // Built all the same: a light may take this proxy in a later frame.
                    ctx.programs.bind::<LightProgram>(dev, program, defines)?;
                }
                continue;
            }
            RenderState {
                depth_test: reach.depth_test(proxy),
                depth_write: false,
                blend: Blend::Additive,
                cull: proxy.cull(),
                color_write: true,
            }
            .apply(dev);
            let p = ctx.programs.bind::<LightProgram>(dev, program, defines)?;
            p.g_albedo.set(dev, UNIT_G_ALBEDO);
            p.g_normal_depth.set(dev, UNIT_G_NORMAL_DEPTH);
            p.g_specular.set(dev, UNIT_G_SPECULAR);
            p.viewport.set(dev, viewport);
            p.half_extent.set(dev, half);
            p.orthographic.set(dev, if ortho { 1.0 } else { 0.0 });
            if let Some(projection) = &p.projection {
                projection.set(dev, ctx.projection);
            }
            let mesh = (mesh.expect("allocated").bind_single_chunk(dev))
                .expect("a proxy mesh is one chunk");
            if reused {
                self.lights.draw_held(dev, slot, &mesh);
                continue;
            }
            // The proxy bounds the light's reach: its culling radius (the radius, or less under
            // a light cut-off). A count adds 1 in one channel, light by light in turn (see
            // COUNT_CHANNELS).
            let instances = lights.map(|(k, light)| {
                let bound = if proxy == Proxy::Bounded {
                    reach.bound_depth(light)
                } else {
                    0.0
                };
                light_instance(
                    light,
                    [reach.radius(light), bound],
                    k % COUNT_CHANNELS,
                    scale,
                )
            });
            let vec4s = light_instances::light_vec4s(features.has(ShaderFeatures::SPOT));
            uploaded += self.lights.draw(dev, slot, &mesh, vec4s, instances)?;
        }
        Ok(LightPass {
            uploaded,
            reused,
            key,
        })
    }

    fn composite(
        &self,
        ctx: &mut FrameContext,
        target: Option<glow::Framebuffer>,
    ) -> Result<(), Error> {
        let dev = ctx.dev;
        dev.bind_framebuffer(target);
        let [x, y] = ctx.origin.map(|v| v as i32);
        dev.viewport(x, y, ctx.viewport.0 as i32, ctx.viewport.1 as i32);
        // The composite also gives the target the geometry pass's depth (for the transparent
        // objects drawn after it, which have it laid again exactly, and for whatever the
        // application draws next): written by the shader, so it works into a target of any
        // depth format, where a depth blit needs both formats to match exactly (ES 3.0:
        // GL_INVALID_OPERATION otherwise; SwiftShader's DEPTH_COMPONENT24 texture and
        // renderbuffer differ, and a game's back buffer may too).
        // Against the application's depth where the frame keeps it (its geometry hides what
        // lies behind); over a cleared depth the test passes wherever there is a surface.
        let mut state = RenderState::FULL_SCREEN_WITH_DEPTH;
        if ctx.clear == crate::options::Clear::Nothing {
            state.depth_test = crate::gl::state::DepthTest::LessEqual;
        }
        state.apply(dev);
        let (half, ortho) = half_extent(ctx);
        // Directional lights are shaded here, with the light pass's full material.
        let sun = ctx.features.has(ShaderFeatures::DIRECTIONAL);
        let specular = self.gbuffer.get().is_some_and(GBuffer::has_specular);
        let features = ctx
            .features
            .with(ShaderFeatures::SPECULAR, sun && specular)
            .with(
                ShaderFeatures::METALLIC_ROUGHNESS,
                sun && in_gbuffer_any(ctx, Material::is_metallic_roughness),
            );
        let accum_to_radiance = accumulation_scale(ctx).recip();
        let key = ProgramKey {
            shader: "deferred_composite",
            features: features.0,
            dialect: dev.es(),
        };
        let p = ctx
            .programs
            .bind::<CompositeProgram>(dev, key, || features.defines(dev.es(), 1))?;
        let gbuffer = self.gbuffer.get().expect("allocated");
        gbuffer.bind_textures(dev, UNIT_G_ALBEDO);
        gbuffer.bind_depth_texture(dev, UNIT_G_DEPTH);
        p.g_albedo.set(dev, UNIT_G_ALBEDO);
        p.g_normal_depth.set(dev, UNIT_G_NORMAL_DEPTH);
        p.accum.set(dev, UNIT_ACCUM);
        p.g_depth.set(dev, UNIT_G_DEPTH);
        p.frame_origin.set(dev, ctx.origin.map(|v| v as f32));
        p.ambient.set(dev, ctx.scene.ambient);
        p.exposure.set(dev, ctx.options.exposure_ev.exp2());
        p.accum_to_radiance.set(dev, accum_to_radiance);
        p.alpha.set(dev, 1.0);
        p.heat_scale.set(dev, ctx.options.heat_scale.max(1.0));
        p.g_specular.set(dev, UNIT_G_SPECULAR);
        p.viewport
            .set(dev, [ctx.viewport.0 as f32, ctx.viewport.1 as f32]);
        p.half_extent.set(dev, half);
        p.orthographic.set(dev, if ortho { 1.0 } else { 0.0 });
        p.directional.set(dev, &ctx.directional);
        self.fullscreen.as_ref().expect("allocated").draw(dev);
        Ok(())
    }
}

/// Whether the frame draws an opaque object (cut-outs included), which the G-buffer passes
/// are for: the objects [`sort_objects`] lists as opaque.
fn draws_opaque(ctx: &FrameContext) -> bool {
    let scene = ctx.scene;
    let opaque = |o: &crate::scene::Object| !scene.materials[o.material].is_transparent();
    !ctx.transparent_only && scene.objects.iter().any(opaque)
}

/// Whether the frame's G-buffer needs its specular target: a material it holds has a
/// specular lobe or is metallic-roughness (every variant has them with `full_variants`). A
/// shared variant's specular term of 0 changes nothing: its output has no target to go to.
fn needs_specular_target(ctx: &FrameContext) -> bool {
    let specular = |m: &Material| m.has_specular() || m.is_metallic_roughness();
    ctx.options.measure.full_variants || in_gbuffer_any(ctx, specular)
}

/// Whether a material an opaque object draws with, one the G-buffer holds, is `such`: a
/// material no object draws with (an OBJ loader's unused default) or only transparent ones
/// do (the forward fallback's) changes neither its targets nor the light pass's variant.
fn in_gbuffer_any(ctx: &FrameContext, such: impl Fn(&Material) -> bool) -> bool {
    let scene = ctx.scene;
    (scene.objects.iter())
        .filter_map(|o| scene.materials.get(o.material))
        .any(|m| !m.is_transparent() && such(m))
}

/// View-space half extents of the projection (per unit depth when perspective) and whether it
/// is orthographic: how the G-buffer passes map window positions to view space.
fn half_extent(ctx: &FrameContext) -> ([f32; 2], bool) {
    GridProjection::from_matrix(&ctx.projection.as_dmat4()).half_extents()
}

impl ShadingMethod for Deferred {
    fn name(&self) -> &'static str {
        DESC.name
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats<'_>, Error> {
        let dev = ctx.dev;
        let exact = COUNT_CHANNELS * gbuffer::HALF_FLOAT_EXACT_COUNT;
        if ctx.features.has(ShaderFeatures::COUNT_EVALS)
            && !ctx.features.has(ShaderFeatures::COUNT_HEATMAP)
            && gbuffer::half_float_accumulation(dev.caps())
            && ctx.lights.len() > exact
        {
            // A count that stopped short would pass for an exact one (a heatmap's colours
            // stop long before).
            return Err(Error::Limit(format!(
                "deferred counts its proxies in a half-float buffer here (no \
                 GL_EXT_float_blend), exact up to {exact} lights at a pixel; the scene has {}",
                ctx.lights.len()
            )));
        }
        let target = ctx.target;
        sort_objects(ctx);
        let mut light_pass = None;
        let mut stats = if ctx.order.opaque.is_empty() {
            // Nothing opaque in the scene: a G-buffer would hold nothing and its light pass
            // light nothing (the composite writes surfaces only). Kept a while, as without
            // lights.
            if super::idle_for_long(&mut self.idle_frames) {
                self.free_gbuffer_passes(dev);
            }
            MethodStats {
                gbuffer_bytes: self.gbuffer.both().map(GBuffer::gpu_bytes).sum(),
                lists_reused: true,
                ..MethodStats::default()
            }
        } else {
            self.idle_frames = 0;
            let specular = self.keeps_specular(needs_specular_target(ctx));
            self.ensure_resources(dev, ctx.viewport, specular)?;
            self.geometry_pass(ctx)?;
            let pass = self.light_pass(ctx)?;
            self.composite(ctx, target)?;
            self.exact_depth_under_transparent(ctx)?;
            let stats = MethodStats {
                gbuffer_bytes: self.gbuffer.both().map(GBuffer::gpu_bytes).sum(),
                upload_bytes: pass.uploaded,
                lists_reused: pass.reused,
                ..MethodStats::default()
            };
            light_pass = Some(pass.key);
            stats
        };
        if !ctx.order.transparent.is_empty() && !ctx.features.counting() {
            // Forward fallback for what a G-buffer cannot hold: plain forward over the
            // transparent objects only, tested against the depth the composite wrote.
            let mut sub = FrameContext {
                programs: &mut *ctx.programs,
                order: &mut *ctx.order,
                transparent_only: true,
                ..*ctx
            };
            let transparent = self.transparent.render(&mut sub)?;
            stats.upload_bytes += transparent.upload_bytes;
            stats.lists_reused &= transparent.lists_reused;
        }
        // A frame that fails after this (its error may be the instance upload's) leaves none to
        // draw again: the renderer's next frame has lights of a new generation.
        if light_pass.is_some() {
            self.instances_key = light_pass;
        }
        Ok(stats)
    }

    fn gpu_bytes(&self) -> usize {
        self.gbuffer.both().map(GBuffer::gpu_bytes).sum::<usize>()
            + self.sphere.as_ref().map_or(0, GpuMesh::gpu_bytes)
            + self.fullscreen.as_ref().map_or(0, GpuMesh::gpu_bytes)
            + self.lights.gpu_bytes()
            + self.transparent.gpu_bytes()
    }

    fn fit_buffers(&mut self, in_use: bool) {
        self.lights.fit_buffers();
        self.transparent.fit_buffers(in_use);
    }

    fn skip_frame(&mut self, dev: &Device) {
        if super::idle_for_long(&mut self.idle_frames) {
            self.destroy(dev);
        }
    }

    fn destroy(&mut self, dev: &Device) {
        self.free_gbuffer_passes(dev);
        self.transparent.destroy(dev);
    }
}
