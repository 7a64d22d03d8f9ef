//! Plain forward shading: every active light evaluated for every fragment, in one geometry
//! pass. It is also the correctness oracle of the other methods, so it stays simple and runs
//! at the highest fragment precision available.
//!
//! Lights come from a data texture (`cluster::pack`): RGBA32F on ES 3.0 and on ES 2.0 with
//! `OES_texture_float`, else the lossy RGBA8 packing. On ES 2.0 the loop has the constant bound
//! [`max_lights`] and exits with `break` (GLSL ES 1.00 Appendix A). A scene with more active
//! lights than that (only reachable without fragment highp: 1 023) keeps the ones that matter
//! most to the view ([`super::forward_cap`]), with a warning and the rest counted.

use super::directional::DirectionalUniforms;
use super::forward_cap::CapView;
use super::geometry::{self, GeometryProgram, UNIT_METHOD};
use super::uniforms::{self, LightData, Surface, Transforms};
use super::{FrameContext, MethodDesc, MethodStats, ShaderFeatures, ShadingMethod, Support};
use crate::cluster::pack::{
    pack_lights_into, LightEncoding, LightLayout, PackedLights, DATA_TEXTURE_WIDTH,
};
use crate::cluster::view_light::GpuLight;
use crate::gl::program::{Resolver, Uniform, UniformSet};
use crate::gl::texture::{DataFormat, DataTexture};
use crate::gl::{Caps, Device, EsVersion};
use crate::Error;

/// The table row.
pub const DESC: MethodDesc = MethodDesc {
    name: "forward",
    summary: "every light for every fragment (the reference)",
    min_es: EsVersion::Es2,
    required_extensions: &[],
    supported,
    multisample: true,
    create: |_| Ok(Box::new(Forward::default())),
};

pub(super) fn supported(caps: &Caps) -> Support {
    if let Some(why) = data_textures_unfit(caps) {
        return Support::Unsupported(why);
    }
    let mut notes = Vec::new();
    if !caps.float_textures {
        notes.push("lights packed as RGBA8 (lossy) because GL_OES_texture_float is missing");
    }
    if !caps.fragment_has_highp() {
        notes.push("fragment shaders run at mediump (no highp in the fragment stage)");
    }
    if notes.is_empty() {
        Support::Supported
    } else {
        Support::Fallback(notes.join("; "))
    }
}

/// Why the light, grid and index data textures (`DATA_TEXTURE_WIDTH` texels wide) cannot be
/// made on `caps`' context, if they cannot: every method reads them (deferred for its
/// transparent objects). ES 2.0 only requires `GL_MAX_TEXTURE_SIZE` 64, ES 3.0 2048.
pub(crate) fn data_textures_unfit(caps: &Caps) -> Option<String> {
    (caps.max_texture_size < DATA_TEXTURE_WIDTH as i32).then(|| {
        format!(
            "its data textures are {DATA_TEXTURE_WIDTH} texels wide, past this context's \
             GL_MAX_TEXTURE_SIZE {}",
            caps.max_texture_size
        )
    })
}

/// Largest light count one forward draw can loop over on this context. ES 2.0 needs a constant
/// loop bound that fits the fragment `int` precision: highp ints reach ±2¹⁶, mediump only ±2¹⁰;
/// and a driver that ends long loops early bounds any loop ([`Caps::light_loop_budget`]).
pub fn max_lights(caps: &Caps) -> u32 {
    let texture_rows = caps.max_texture_size.max(1) as u32;
    let by_texture = texture_rows * (DATA_TEXTURE_WIDTH / LightLayout::MOST_TEXELS_PER_LIGHT);
    let by_loop = match (caps.es, caps.fragment_has_highp()) {
        (EsVersion::Es3, _) => u32::MAX,
        (EsVersion::Es2, true) => 65_535,
        (EsVersion::Es2, false) => 1_023,
    };
    by_texture.min(by_loop).min(caps.light_loop_budget())
}

/// The `forward` shader's uniforms: every light from the light texture, up to the count.
pub struct ForwardProgram {
    transforms: Transforms,
    surface: Surface,
    lights: LightData,
    count: Uniform<i32>,
    directional: DirectionalUniforms,
}

impl UniformSet for ForwardProgram {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        let f = uniforms::features(r);
        let no_lights = f.has(ShaderFeatures::NO_LIGHTS);
        let lit = !f.counting() && !no_lights;
        ForwardProgram {
            transforms: Transforms::resolve(r, lit),
            surface: Surface::shaded(r, lit),
            // Evaluation counts are the light count alone; reaching counts read the lights.
            lights: LightData::resolve(r, !no_lights && !f.has(ShaderFeatures::COUNT_EVALS)),
            count: r.required_when(!no_lights, "u_lightCount"),
            directional: DirectionalUniforms::resolve(r, !f.counting()),
        }
    }
}

impl GeometryProgram for ForwardProgram {
    fn transforms(&self) -> &Transforms {
        &self.transforms
    }
    fn surface(&self) -> &Surface {
        &self.surface
    }
    fn directional(&self) -> Option<&DirectionalUniforms> {
        Some(&self.directional)
    }
}

/// Plain forward's GPU state: the light texture, and the buffers a frame fills (kept, so a
/// frame allocates nothing once they have grown).
#[derive(Default)]
pub struct Forward {
    lights: Option<(DataTexture, LightEncoding)>,
    /// The light cap was announced (once per renderer: it holds frame after frame).
    warned_cap: bool,
    /// The lights packed for upload.
    packed: PackedLights,
    /// The lights kept under the cap, and the selection's buffer.
    capped: Vec<GpuLight>,
    cap_order: Vec<usize>,
    /// RGBA8 records: the lights with those that reach no pixel darkened (see
    /// [`darken_unseen_into`]).
    seen: Vec<GpuLight>,
    /// What the texture's records were packed from, once uploaded.
    uploaded: Option<RecordsKey>,
}

impl Forward {
    /// Packs the frame's records: the lights that matter most to the view when there are
    /// more than one draw loops over (`limit`), with those out of view darkened for RGBA8.
    fn pack(&mut self, ctx: &FrameContext, limit: u32, layout: LightLayout) {
        let lights = if ctx.lights.len() > limit as usize {
            super::forward_cap::keep_most_important_into(
                ctx.lights,
                limit as usize,
                &CapView::new(&ctx.projection, ctx.near),
                &mut self.cap_order,
                &mut self.capped,
            );
            if !self.warned_cap {
                log::warn!(
                    "forward loops over at most {limit} lights on this context; {} of the \
                     scene's {} active lights, those that matter least to the view, are left \
                     out (FrameStats::lights.overflowed counts them each frame)",
                    ctx.lights.len() - limit as usize,
                    ctx.lights.len()
                );
                self.warned_cap = true;
            }
            &self.capped[..]
        } else {
            ctx.lights
        };
        let lights = match layout.encoding {
            LightEncoding::Rgba8 => {
                darken_unseen_into(ctx, lights, &mut self.seen);
                &self.seen[..]
            }
            LightEncoding::Float32 => lights,
        };
        pack_lights_into(lights, layout, &mut self.packed);
    }
}

/// Everything a frame's packed records are a function of: the lights (by generation), their
/// layout, and the view where the cap or RGBA8's darkening selects lights by it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct RecordsKey {
    lights_generation: u64,
    layout: LightLayout,
    /// The projection, near plane and farthest geometry, where lights are selected by them
    /// (elsewhere a zoom or a moving object keeps the records).
    view: Option<([u32; 16], u64, u64)>,
}

impl RecordsKey {
    fn new(ctx: &FrameContext, layout: LightLayout, limit: u32) -> RecordsKey {
        let by_view = layout.encoding == LightEncoding::Rgba8 || ctx.lights.len() > limit as usize;
        RecordsKey {
            lights_generation: ctx.lights_generation,
            layout,
            view: by_view.then(|| {
                (
                    ctx.projection.to_cols_array().map(f32::to_bits),
                    ctx.near.to_bits(),
                    ctx.content_far.to_bits(),
                )
            }),
        }
    }
}

impl ShadingMethod for Forward {
    fn name(&self) -> &'static str {
        DESC.name
    }

    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats<'_>, Error> {
        let dev = ctx.dev;
        let limit = max_lights(dev.caps());
        if ctx.lights.len() > limit as usize && ctx.features.counting() {
            // A count over a subset of the lights is no lower bound and no evaluation count.
            return Err(Error::Limit(format!(
                "light counts need every light in one forward loop, which holds at most \
                 {limit} here; the scene has {}",
                ctx.lights.len()
            )));
        }
        let layout = ctx.features.light_layout();
        // Recreate the texture when the encoding changes.
        if self
            .lights
            .as_ref()
            .is_some_and(|(_, e)| *e != layout.encoding)
        {
            if let Some((mut t, _)) = self.lights.take() {
                t.destroy(dev);
            }
        }
        let fresh = self.lights.is_none();
        if fresh {
            self.uploaded = None;
            let format = match layout.encoding {
                LightEncoding::Float32 => DataFormat::Rgba32F,
                LightEncoding::Rgba8 => DataFormat::Rgba8,
            };
            self.lights = Some((DataTexture::new(dev, format)?, layout.encoding));
        }
        let key = RecordsKey::new(ctx, layout, limit);
        // A still frame (nothing the records are packed from changed) draws with the last ones,
        // unless they have filled a quarter of the texture for long: then it uploads them again,
        // which shrinks it.
        let reused = self.uploaded == Some(key)
            && !(self.lights.as_mut()).is_some_and(|(t, _)| t.note_still_frame());
        let mut upload_bytes = 0;
        if !reused {
            self.uploaded = None;
            self.pack(ctx, limit, layout);
            let packed = &self.packed;
            // With no lights the shader never reads the texture: upload only to give it storage.
            if packed.count > 0 || fresh {
                let (texture, _) = self.lights.as_mut().expect("created above");
                texture.upload(dev, packed.width, packed.height, &packed.bytes)?;
                upload_bytes = packed.bytes.len();
            }
            self.uploaded = Some(key);
        }
        let count = self.packed.count;
        let stats = MethodStats {
            upload_bytes,
            dropped_lights: (ctx.lights.len() - count) as u64,
            lists_reused: reused,
            ..MethodStats::default()
        };
        let ranges = [self.packed.pos_range, self.packed.radius_range];
        let (texture, _) = self.lights.as_ref().expect("created above");
        geometry::draw_objects(ctx, "forward", limit, &mut |p: &ForwardProgram, dev| {
            p.lights.bind(dev, texture, UNIT_METHOD, ranges);
            p.count.set(dev, count as i32);
        })?;
        Ok(stats)
    }

    fn gpu_bytes(&self) -> usize {
        self.lights.as_ref().map_or(0, |(t, _)| t.gpu_bytes())
    }

    /// Every CPU buffer is the frame's scratch: a still frame draws the texture, and one that
    /// uploads again (to shrink it) packs anew; the packed count and ranges stay.
    fn fit_buffers(&mut self, _in_use: bool) {
        use crate::cluster::headroom::fit_empty;
        fit_empty(&mut self.packed.bytes);
        fit_empty(&mut self.capped);
        fit_empty(&mut self.cap_order);
        fit_empty(&mut self.seen);
    }

    fn destroy(&mut self, dev: &Device) {
        if let Some((mut t, _)) = self.lights.take() {
            t.destroy(dev);
        }
    }
}

/// `lights` into `seen`, each that reaches nothing in view darkened
/// ([`darkened_if_unseen`](super::unseen_lights::darkened_if_unseen)). Forward still loops
/// over it, so its counts stay every light.
fn darken_unseen_into(ctx: &FrameContext, lights: &[GpuLight], seen: &mut Vec<GpuLight>) {
    let volume = ctx.view_volume();
    seen.clear();
    seen.extend((lights.iter()).map(|l| super::unseen_lights::darkened_if_unseen(&volume, l)));
}

/// A frame without lights: ambient only, with the light loop compiled out and nothing uploaded.
pub fn draw_ambient_only(ctx: &mut FrameContext) -> Result<MethodStats<'static>, Error> {
    // One variant whether the scene has spots out of view or no lights at all.
    ctx.features =
        (ctx.features.with(ShaderFeatures::NO_LIGHTS, true)).with(ShaderFeatures::SPOT, false);
    geometry::draw_objects::<ForwardProgram>(ctx, "forward", 1, &mut |_, _| {})?;
    Ok(MethodStats::default())
}
