//! The geometry pass shared by the forward-style methods: every object drawn once with its
//! material's shader variant, the method adding its own uniforms and textures.

use super::directional::DirectionalUniforms;
use super::uniforms::{is_mirroring, Surface, SurfaceFrame, Transforms};
use super::{FrameContext, ShaderFeatures};
use crate::gl::program::{ProgramKey, Resolver, UniformSet};
use crate::gl::state::{Cull, RenderState};
use crate::gl::Device;
use crate::Error;

/// Texture unit of the diffuse map.
pub const UNIT_ALBEDO: u32 = 0;
/// First texture unit a method may use for its data textures.
pub const UNIT_METHOD: u32 = 1;

// The material's maps follow the three units clustered's geometry pass uses.
const _: () = assert!(super::maps::UNIT_MAPS == UNIT_METHOD + 3);

/// The uniforms of a geometry-pass program: the shared transforms and surface, and the
/// method's own (set by the method's `bind_method`).
pub trait GeometryProgram: UniformSet {
    /// `mesh.vert`'s uniforms.
    fn transforms(&self) -> &Transforms;
    /// `surface.glsl`'s uniforms.
    fn surface(&self) -> &Surface;
    /// `directional.glsl`'s uniforms, for programs that shade directional lights.
    fn directional(&self) -> Option<&DirectionalUniforms> {
        None
    }
}

/// The depth prepass: transforms only (its fragment stage writes no colour).
pub(crate) struct DepthProgram(Transforms);

impl UniformSet for DepthProgram {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        DepthProgram(Transforms::resolve(r, false))
    }
}

/// The objects of a frame in draw order: indices into the scene's objects, in buffers the
/// renderer keeps from frame to frame (so ordering them allocates nothing once they have
/// grown to the scene's object count).
#[derive(Debug, Default)]
pub struct DrawOrder {
    /// Opaque objects, in scene order, those cut out by a texture's alpha (glTF `MASK`) last,
    /// from [`DrawOrder::cut_out_from`] on.
    pub opaque: Vec<usize>,
    /// Where the cut-out objects start in `opaque`: they take no depth prepass (the prepass
    /// does not sample textures), and are drawn after the others with their own depth writes.
    pub cut_out_from: usize,
    /// Transparent objects, back to front.
    pub transparent: Vec<usize>,
    /// Some opaque object's material is single-sided: the opaque passes set culling object
    /// by object (in `shade_object` and the depth prepass); else the passes' own (none)
    /// holds and they set nothing.
    pub single_sided: bool,
    /// (view depth, object) of the transparent objects, to sort them.
    depths: Vec<(f64, usize)>,
}

/// Puts the frame's opaque objects in scene order, then the transparent ones back to front (by
/// the view depth of their bounds' centre; equal depths in scene order), into `ctx.order`.
/// With `ctx.transparent_only` the opaque list stays empty.
pub(crate) fn sort_objects(ctx: &mut FrameContext) {
    let scene = ctx.scene;
    let order = &mut *ctx.order;
    order.opaque.clear();
    order.depths.clear();
    order.single_sided = false;
    let cut_out = |o: &crate::scene::Object| scene.materials[o.material].alpha_cutoff.is_some();
    for (i, o) in scene.objects.iter().enumerate() {
        if scene.materials[o.material].is_transparent() {
            let centre = ctx
                .gpu_scene
                .world_bounds(o)
                .map_or(glam::DVec3::ZERO, |b| b.center());
            order.depths.push((-ctx.view.transform_point3(centre).z, i));
        } else if !ctx.transparent_only {
            order.single_sided |= !scene.materials[o.material].double_sided;
            if !cut_out(o) {
                order.opaque.push(i);
            }
        }
    }
    order.cut_out_from = order.opaque.len();
    if !ctx.transparent_only {
        let cut = scene.objects.iter().enumerate();
        order.opaque.extend(
            cut.filter(|(_, o)| !scene.materials[o.material].is_transparent() && cut_out(o))
                .map(|(i, _)| i),
        );
    }
    // Farthest first; the index makes the order that of a stable sort without its buffer.
    order
        .depths
        .sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    order.transparent.clear();
    order
        .transparent
        .extend(order.depths.iter().map(|&(_, i)| i));
}

/// Lays down the opaque objects' depth only, so the shading pass runs its light loop once per
/// pixel instead of once per overlapping surface.
pub(crate) fn depth_prepass(ctx: &mut FrameContext) -> Result<(), Error> {
    let dev = ctx.dev;
    RenderState::DEPTH_PREPASS.apply(dev);
    let key = ProgramKey {
        shader: "depth",
        features: 0,
        dialect: dev.es(),
    };
    let DepthProgram(transforms) = ctx.programs.bind::<DepthProgram>(dev, key, Vec::new)?;
    for &i in &ctx.order.opaque[..ctx.order.cut_out_from] {
        let (mesh, model) = ctx.gpu_scene.drawn(i, &ctx.scene.objects[i]);
        let view_model = ctx.view * model;
        let material = &ctx.scene.materials[ctx.scene.objects[i].material];
        if ctx.order.single_sided {
            Cull::for_surface(material.double_sided, is_mirroring(&view_model)).apply(dev);
        }
        // The depth its shading pass tests against: biased as that pass draws it.
        dev.set_depth_bias(material.depth_bias);
        transforms.set(dev, &view_model, &ctx.projection);
        mesh.draw(dev);
    }
    Ok(())
}

/// Draws the scene with `shader`: a depth prepass of the opaque objects (where the shader has a
/// light loop), the opaque objects,
/// then the transparent ones back to front — each in two passes, back faces then front faces,
/// so a closed convex object blends in the right order (a single-sided one in the second
/// alone). `bind_method` is called on each
/// program before a draw so the method can set its uniforms and bind its textures; transparent
/// surfaces are lit by the same data (the dense grid covers every depth, not just the visible
/// surface).
pub fn draw_objects<P: GeometryProgram>(
    ctx: &mut FrameContext,
    shader: &'static str,
    max_lights: u32,
    bind_method: &mut dyn FnMut(&P, &Device),
) -> Result<(), Error> {
    sort_objects(ctx);
    // Without a light loop a fragment costs about what a depth-only one does: the opaque
    // objects are then tested and written against their own depth, as the cut-out ones are.
    // Nothing opaque but cut-outs (or transparent objects alone): no prepass, no program.
    let prepass = !ctx.features.has(ShaderFeatures::NO_LIGHTS) && ctx.order.cut_out_from > 0;
    if prepass {
        depth_prepass(ctx)?;
    }
    let mut bound = None;
    for k in 0..ctx.order.opaque.len() {
        if k == 0 || k == ctx.order.cut_out_from {
            let state = if prepass && k < ctx.order.cut_out_from {
                RenderState::OPAQUE_AFTER_PREPASS
            } else {
                RenderState::CUT_OUT
            };
            state.apply(ctx.dev);
        }
        let i = ctx.order.opaque[k];
        shade_object(ctx, i, shader, max_lights, bind_method, &mut bound)?;
    }
    // Counts are of the visible opaque surface: blending would mix two counts in 8 bits.
    let transparent = if ctx.features.counting() {
        0
    } else {
        ctx.order.transparent.len()
    };
    for k in 0..transparent {
        let i = ctx.order.transparent[k];
        // The far side first: GL's back faces (clockwise on screen), which are the front ones
        // of an object a mirroring transform places.
        let (_, model) = ctx.gpu_scene.drawn(i, &ctx.scene.objects[i]);
        let mut passes = [
            RenderState::TRANSPARENT_BACK_FACES,
            RenderState::TRANSPARENT_FRONT_FACES,
        ];
        if is_mirroring(&(ctx.view * model)) {
            passes.reverse();
        }
        // A single-sided surface has its front only: the second pass. One whose triangles
        // face one way shows one side from any eye: one pass without culling draws it.
        let object = &ctx.scene.objects[i];
        let passes = match ctx.scene.materials[object.material].double_sided {
            false => &passes[1..],
            true if ctx.gpu_scene.faces_one_way(object) => &[RenderState::TRANSPARENT_BOTH_SIDES],
            true => &passes[..],
        };
        for state in passes {
            state.apply(ctx.dev);
            shade_object(ctx, i, shader, max_lights, bind_method, &mut bound)?;
        }
    }
    // What draws next (an MSAA resolve, a method's own passes) lies where it is.
    ctx.dev.set_depth_bias(0.0);
    crate::gl::device::gl_check!(ctx.dev, "geometry pass");
    Ok(())
}

/// One object with its material's shader variant. An opaque one's back faces are culled here
/// when its material is single-sided, as in the depth prepass, so every opaque pass (shading,
/// deferred's G-buffer) covers the same pixels; a transparent one's culling is its pass's.
/// `bind_method` runs where the program differs from the one `bound` names, the last it ran
/// for: what it binds and sets holds for the frame, on texture units no object binds.
pub(crate) fn shade_object<P: GeometryProgram>(
    ctx: &mut FrameContext,
    index: usize,
    shader: &'static str,
    max_lights: u32,
    bind_method: &mut dyn FnMut(&P, &Device),
    bound: &mut Option<ProgramKey>,
) -> Result<(), Error> {
    let dev = ctx.dev;
    let dialect = dev.es();
    let object = &ctx.scene.objects[index];
    let material = &ctx.scene.materials[object.material];
    let units = dev.caps().max_texture_image_units;
    let mapped = super::maps::base_textured(material, &object.mesh);
    let own_texture = ctx.gpu_scene.texture_for(material).filter(|_| mapped);
    let own = super::surface_variants::own(material, &object.mesh, own_texture.is_some(), units);
    let features = if ctx.features.counting() {
        // A count reads no surface input and cuts no fragment.
        let kept =
            ShaderFeatures::TEXTURE | ShaderFeatures::SPECULAR | ShaderFeatures::METALLIC_ROUGHNESS;
        ShaderFeatures(own.0 & kept)
    } else {
        // Only a light reads the shading normal, the specular lobe and the metallic-roughness
        // terms (the ambient term is albedo's alone): without one, one variant for every
        // lighting model, which would compile them out anyway.
        let shades = !ctx.features.has(ShaderFeatures::NO_LIGHTS)
            || ctx.features.has(ShaderFeatures::DIRECTIONAL);
        let lit_only = [
            ShaderFeatures::NORMAL_MAP,
            ShaderFeatures::SPECULAR,
            ShaderFeatures::METALLIC_ROUGHNESS,
            ShaderFeatures::MR_TEXTURE,
        ];
        let own = (lit_only.into_iter()).fold(own, |f, bit| f.with(bit, f.has(bit) && shades));
        if ctx.shared_surfaces {
            super::surface_variants::shared(own, units)
        } else {
            own
        }
    };
    let texture = own_texture.or_else(|| {
        let white = features.has(ShaderFeatures::TEXTURE);
        white.then(|| ctx.gpu_scene.white()).flatten()
    });
    let features = ShaderFeatures(ctx.features.0 | features.0);
    let key = ProgramKey {
        shader,
        features: features.0,
        dialect,
    };
    let program: &P = ctx
        .programs
        .bind(dev, key, || features.defines(dialect, max_lights))?;
    // The camera is subtracted in f64 here, so far-from-origin scenes stay exact in f32.
    let (mesh, model) = ctx.gpu_scene.drawn(index, object);
    let view_model = ctx.view * model;
    let mirrored = is_mirroring(&view_model);
    if ctx.order.single_sided && !material.is_transparent() {
        Cull::for_surface(material.double_sided, mirrored).apply(dev);
    }
    dev.set_depth_bias(material.depth_bias);
    program.transforms().set(dev, &view_model, &ctx.projection);
    if let Some(t) = texture {
        let sampling = material
            .diffuse_texture
            .as_ref()
            .map_or_else(Default::default, |t| t.sampling);
        t.bind(dev, UNIT_ALBEDO, &sampling);
    }
    // The lights came pre-exposed (`FrameContext::pre_exposure`); the exposure does the rest.
    let pre_exposure = ctx.pre_exposure;
    let frame = SurfaceFrame {
        ambient: super::uniforms::ambient_uniform(
            super::features::pre_exposed(ctx.scene.ambient, pre_exposure),
            ctx.features.has(ShaderFeatures::FP16_LIGHTS),
        ),
        exposure: ctx.options.exposure_ev.exp2() / pre_exposure,
        orthographic: ctx.orthographic,
        heat_scale: ctx.options.heat_scale.max(1.0),
    };
    program.surface().set(
        dev,
        material,
        texture.is_some().then_some(UNIT_ALBEDO),
        &frame,
        features.has(ShaderFeatures::COUNT_HEATMAP),
    );
    program.surface().set_mirrored(dev, mirrored);
    if let Some(directional) = program.directional() {
        directional.set(dev, &ctx.directional);
    }
    program
        .surface()
        .maps()
        .set(dev, material, features, own, ctx.gpu_scene, pre_exposure);
    if *bound != Some(key) {
        bind_method(program, dev);
        *bound = Some(key);
    }
    mesh.draw(dev);
    Ok(())
}
