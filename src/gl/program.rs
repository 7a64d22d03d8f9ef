//! Programs: compile, link, typed uniforms resolved at link time, and the cache keyed by
//! (shader, feature bits, dialect).
//!
//! Each program is linked together with a [`UniformSet`]: a struct of [`Uniform`] fields,
//! one per uniform the caller sets, whose locations are looked up once here. At link time
//! every field's name must be declared by the shader's sources (a misspelt name fails in
//! every variant), must match the GLSL type it is declared as, and must be active in the
//! linked program when the set says the variant needs it; otherwise the build fails with
//! [`GlError::ProgramLink`] naming the uniform.
#![allow(unsafe_code)]

use std::any::Any;
use std::cell::Cell;
use std::collections::HashMap;
use std::marker::PhantomData;

use glam::{Mat3, Mat4, Vec3, Vec4};
use glow::HasContext;

use super::shader_source::{self, numbered, Stage};
use super::{Device, EsVersion, GlError};

/// Vertex attribute locations shared by every program (bound before linking).
pub const ATTRIBUTES: &[(u32, &str)] = &[
    (0, "a_position"),
    (1, "a_normal"),
    (2, "a_uv"),
    (3, "a_color"),
    (4, "a_tangent"),
    (5, "a_uv1"),
];

/// A linked program and the uniform set resolved for it.
pub struct Program {
    raw: glow::Program,
    /// The [`UniformSet`] it was linked with.
    uniforms: Box<dyn Any + Send>,
    /// Total assembled source size in bytes (vertex + fragment), for stats.
    pub source_bytes: usize,
    destroyed: bool,
}

/// A GLSL uniform type: the GL types it may be declared as, and how a value is set.
pub trait UniformType {
    /// What a value is set from (compared with the last value set, which is not set again).
    type Value: Copy + PartialEq + Send;
    /// The GLSL type, for errors.
    const GLSL: &'static str;
    /// Elements: 1, or an array's length.
    const LEN: i32 = 1;
    /// Whether a uniform the driver reports with type `gl_type` takes this.
    fn accepts(gl_type: u32) -> bool;
    /// Sets the uniform at `location` of the current program.
    fn set(dev: &Device, location: &glow::UniformLocation, value: Self::Value);
}

/// A `sampler2D` or `usampler2D` uniform, set to a texture unit.
pub struct Sampler;

macro_rules! uniform_type {
    ($ty:ty, $value:ty, $glsl:literal, [$($gl:path),+], $set:expr) => {
        impl UniformType for $ty {
            type Value = $value;
            const GLSL: &'static str = $glsl;
            fn accepts(gl_type: u32) -> bool {
                [$($gl),+].contains(&gl_type)
            }
            fn set(dev: &Device, location: &glow::UniformLocation, value: $value) {
                let set: fn(&glow::Context, &glow::UniformLocation, $value) = $set;
                set(&dev.gl, location, value);
            }
        }
    };
}

uniform_type!(f32, f32, "float", [glow::FLOAT], |gl, l, v| unsafe {
    gl.uniform_1_f32(Some(l), v)
});
uniform_type!(i32, i32, "int", [glow::INT], |gl, l, v| unsafe {
    gl.uniform_1_i32(Some(l), v)
});
uniform_type!(
    Sampler,
    u32,
    "sampler2D",
    [
        glow::SAMPLER_2D,
        glow::INT_SAMPLER_2D,
        glow::UNSIGNED_INT_SAMPLER_2D
    ],
    |gl, l, unit| unsafe { gl.uniform_1_i32(Some(l), unit as i32) }
);
uniform_type!(
    [f32; 2],
    [f32; 2],
    "vec2",
    [glow::FLOAT_VEC2],
    |gl, l, v| unsafe { gl.uniform_2_f32(Some(l), v[0], v[1]) }
);
uniform_type!(Vec3, Vec3, "vec3", [glow::FLOAT_VEC3], |gl, l, v| unsafe {
    gl.uniform_3_f32(Some(l), v.x, v.y, v.z)
});
uniform_type!(Vec4, Vec4, "vec4", [glow::FLOAT_VEC4], |gl, l, v| unsafe {
    gl.uniform_4_f32(Some(l), v.x, v.y, v.z, v.w)
});
uniform_type!(Mat3, Mat3, "mat3", [glow::FLOAT_MAT3], |gl, l, m| unsafe {
    gl.uniform_matrix_3_f32_slice(Some(l), false, &m.to_cols_array())
});
uniform_type!(Mat4, Mat4, "mat4", [glow::FLOAT_MAT4], |gl, l, m| unsafe {
    gl.uniform_matrix_4_f32_slice(Some(l), false, &m.to_cols_array())
});
impl UniformType for [Vec3; 4] {
    type Value = [Vec3; 4];
    const GLSL: &'static str = "vec3[4]";
    const LEN: i32 = 4;
    fn accepts(gl_type: u32) -> bool {
        gl_type == glow::FLOAT_VEC3
    }
    fn set(dev: &Device, location: &glow::UniformLocation, value: [Vec3; 4]) {
        let flat: [f32; 12] = std::array::from_fn(|i| value[i / 3][i % 3]);
        unsafe { dev.gl.uniform_3_f32_slice(Some(location), &flat) }
    }
}

/// One uniform of a linked program, its location looked up at link time. Setting one the
/// variant compiled out (no location) does nothing.
pub struct Uniform<T: UniformType> {
    location: Option<glow::UniformLocation>,
    /// The value set last: a program keeps its uniforms, and only this crate sets them.
    last: Cell<Option<T::Value>>,
    ty: PhantomData<fn(T)>,
}

impl<T: UniformType> Uniform<T> {
    fn inactive() -> Self {
        Uniform {
            location: None,
            last: Cell::new(None),
            ty: PhantomData,
        }
    }

    /// Sets the uniform of the current program (which must be the one it was resolved in),
    /// unless it holds `value` already.
    pub fn set(&self, dev: &Device, value: T::Value) {
        if let Some(l) = &self.location {
            if self.last.get() != Some(value) {
                T::set(dev, l, value);
                dev.count_state_call(|c| c.uniforms_set += 1);
                self.last.set(Some(value));
            }
        }
    }
}

/// The typed uniforms of one kind of program: resolved once when a program is linked.
pub trait UniformSet: Sized + Send + 'static {
    /// Looks up every uniform of the set in `r`'s program, saying which ones the variant
    /// ([`Resolver::features`], [`Resolver::es`]) must have.
    fn resolve(r: &mut Resolver<'_>) -> Self;
}

/// Looks up a just-linked program's uniforms for a [`UniformSet`], collecting every problem.
pub struct Resolver<'a> {
    dev: &'a Device,
    raw: glow::Program,
    shader: &'a str,
    features: u64,
    /// Every uniform the shader's sources declare, in any variant.
    declared: Vec<String>,
    /// The linked program's active uniforms, their GL types and sizes (elements).
    active: Vec<(String, u32, i32)>,
    problems: Vec<String>,
}

impl Resolver<'_> {
    /// The shader name.
    pub fn shader(&self) -> &str {
        self.shader
    }

    /// The variant's feature bits (the program key's).
    pub fn features(&self) -> u64 {
        self.features
    }

    /// The GLSL dialect the program was built for.
    pub fn es(&self) -> EsVersion {
        self.dev.es()
    }

    /// A uniform every variant of the shader must have.
    pub fn required<T: UniformType>(&mut self, name: &'static str) -> Uniform<T> {
        self.required_when(true, name)
    }

    /// A uniform some variants compile or optimise out.
    pub fn optional<T: UniformType>(&mut self, name: &'static str) -> Uniform<T> {
        self.required_when(false, name)
    }

    /// A uniform this variant must have when `required`, else one it may lack.
    pub fn required_when<T: UniformType>(
        &mut self,
        required: bool,
        name: &'static str,
    ) -> Uniform<T> {
        if !self.declared.iter().any(|d| d == name) {
            self.problems.push(format!(
                "uniform `{name}` is not declared by shader `{}`",
                self.shader
            ));
            return Uniform::inactive();
        }
        // GL names an array uniform by its first element.
        let is_name = |n: &str| n == name || n.strip_suffix("[0]") == Some(name);
        match self.active.iter().find(|(n, _, _)| is_name(n)) {
            None => {
                if required {
                    self.problems.push(format!(
                        "uniform `{name}` is required but not active in this variant"
                    ));
                }
                Uniform::inactive()
            }
            Some(&(_, gl_type, size)) if !T::accepts(gl_type) || size != T::LEN => {
                self.problems.push(format!(
                    "uniform `{name}` is declared `{}`, set as `{}`",
                    gl_type_name(gl_type, size),
                    T::GLSL
                ));
                Uniform::inactive()
            }
            Some(_) => Uniform {
                location: unsafe { self.dev.gl.get_uniform_location(self.raw, name) },
                last: Cell::new(None),
                ty: PhantomData,
            },
        }
    }
}

fn gl_type_name(gl_type: u32, size: i32) -> String {
    let name = match gl_type {
        glow::FLOAT => "float".into(),
        glow::FLOAT_VEC2 => "vec2".into(),
        glow::FLOAT_VEC3 => "vec3".into(),
        glow::FLOAT_VEC4 => "vec4".into(),
        glow::INT => "int".into(),
        glow::FLOAT_MAT3 => "mat3".into(),
        glow::FLOAT_MAT4 => "mat4".into(),
        glow::SAMPLER_2D => "sampler2D".into(),
        glow::UNSIGNED_INT_SAMPLER_2D => "usampler2D".into(),
        other => format!("GL type 0x{other:04x}"),
    };
    if size == 1 {
        name
    } else {
        format!("{name}[{size}]")
    }
}

/// Resolves `U` in the linked program `raw`, or says every problem found, one per line.
fn resolve<U: UniformSet>(
    dev: &Device,
    raw: glow::Program,
    shader: &str,
    features: u64,
) -> Result<U, String> {
    let gl = &dev.gl;
    let declared = shader_source::declared_uniforms(shader).map_err(|e| e.to_string())?;
    let active = unsafe {
        (0..gl.get_active_uniforms(raw))
            .filter_map(|i| gl.get_active_uniform(raw, i))
            .map(|u| (u.name, u.utype, u.size))
            .collect()
    };
    let mut r = Resolver {
        dev,
        raw,
        shader,
        features,
        declared,
        active,
        problems: Vec::new(),
    };
    let set = U::resolve(&mut r);
    if r.problems.is_empty() {
        Ok(set)
    } else {
        Err(r.problems.join("\n"))
    }
}

fn compile(
    dev: &Device,
    name: &str,
    stage: Stage,
    defines: &[(String, String)],
) -> Result<(glow::Shader, usize), GlError> {
    let gl = &dev.gl;
    let caps = dev.caps();
    let source = if caps.fragment_has_highp() {
        shader_source::assemble_for(name, stage, dev.es(), caps.desktop, defines)?
    } else {
        shader_source::assemble_without_fragment_highp(name, stage, defines)?
    };
    let kind = match stage {
        Stage::Vertex => glow::VERTEX_SHADER,
        Stage::Fragment => glow::FRAGMENT_SHADER,
    };
    unsafe {
        let shader = gl.create_shader(kind).map_err(GlError::Create)?;
        gl.shader_source(shader, &source);
        gl.compile_shader(shader);
        if !gl.get_shader_compile_status(shader) {
            let log = gl.get_shader_info_log(shader);
            gl.delete_shader(shader);
            return Err(GlError::ShaderCompile {
                shader: name.to_string(),
                stage: stage.name(),
                dialect: dev.es(),
                defines: format_defines(defines),
                log,
                numbered_source: numbered(&source),
            });
        }
        Ok((shader, source.len()))
    }
}

fn format_defines(defines: &[(String, String)]) -> String {
    defines
        .iter()
        .map(|(k, v)| format!("{k}={v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Program {
    /// Assembles, compiles and links `shader` with `defines`, then resolves its uniform set
    /// `U` for the variant `features` (see the module docs for what is checked).
    pub fn build<U: UniformSet>(
        dev: &Device,
        shader: &str,
        defines: &[(String, String)],
        features: u64,
    ) -> Result<Program, GlError> {
        let gl = &dev.gl;
        let (vs, vs_len) = compile(dev, shader, Stage::Vertex, defines)?;
        let (fs, fs_len) = match compile(dev, shader, Stage::Fragment, defines) {
            Ok(f) => f,
            Err(e) => {
                unsafe { gl.delete_shader(vs) };
                return Err(e);
            }
        };
        let raw = unsafe {
            let raw = match dev.create_program() {
                Ok(raw) => raw,
                Err(e) => {
                    gl.delete_shader(vs);
                    gl.delete_shader(fs);
                    return Err(e);
                }
            };
            gl.attach_shader(raw, vs);
            gl.attach_shader(raw, fs);
            for (loc, name) in ATTRIBUTES {
                gl.bind_attrib_location(raw, *loc, name);
            }
            gl.link_program(raw);
            gl.detach_shader(raw, vs);
            gl.detach_shader(raw, fs);
            gl.delete_shader(vs);
            gl.delete_shader(fs);
            if !gl.get_program_link_status(raw) {
                let log = gl.get_program_info_log(raw);
                dev.delete_program(raw);
                return Err(GlError::ProgramLink {
                    shader: shader.to_string(),
                    defines: format_defines(defines),
                    log,
                });
            }
            raw
        };
        match resolve::<U>(dev, raw, shader, features) {
            Ok(uniforms) => Ok(Program {
                raw,
                uniforms: Box::new(uniforms),
                source_bytes: vs_len + fs_len,
                destroyed: false,
            }),
            Err(log) => {
                dev.delete_program(raw);
                Err(GlError::ProgramLink {
                    shader: shader.to_string(),
                    defines: format_defines(defines),
                    log,
                })
            }
        }
    }

    /// Makes this the current program.
    pub fn bind(&self, dev: &Device) {
        dev.use_program(self.raw)
    }

    /// The uniform set the program was linked with, when it is a `U`.
    pub fn uniforms<U: UniformSet>(&self) -> Option<&U> {
        self.uniforms.downcast_ref()
    }

    /// Frees the program.
    pub fn destroy(&mut self, dev: &Device) {
        if !self.destroyed {
            dev.delete_program(self.raw);
            self.destroyed = true;
        }
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        if !self.destroyed && !super::left_objects::left_on_purpose() {
            log::warn!("Program dropped without destroy(): GL program leaked");
        }
    }
}

/// Cache key: shader name, the variant's feature bits, and the dialect. The light count is
/// never part of a key: variants depend only on what a scene has, not how much of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ProgramKey {
    /// Shader name in [`shader_source::SHADERS`].
    pub shader: &'static str,
    /// Feature bitset the `#define`s are derived from.
    pub features: u64,
    /// GLSL dialect.
    pub dialect: EsVersion,
}

/// Built programs by key, each with the frame that last used it.
pub struct ProgramCache {
    programs: HashMap<ProgramKey, Cached>,
    /// Frames that bound a program: a frame refused before it drew is not one.
    frames: u64,
    /// The frame a bind counts for: the current one, or the next one between frames.
    stamp: u64,
    /// A frame has begun and not bound a program yet.
    frame_pending: bool,
}

impl Default for ProgramCache {
    /// Empty; the programs bound before the first frame count as its.
    fn default() -> Self {
        ProgramCache {
            programs: HashMap::new(),
            frames: 0,
            stamp: 1,
            frame_pending: false,
        }
    }
}

struct Cached {
    program: Program,
    last_used: u64,
}

/// One built variant, for reports.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct ProgramInfo {
    /// Shader name.
    pub shader: &'static str,
    /// Feature bits.
    pub features: u64,
    /// Dialect.
    pub dialect: EsVersion,
    /// Assembled vertex + fragment source size in bytes.
    pub source_bytes: usize,
}

impl ProgramCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes the program for `key` current, building it with `defines()` and the uniform set
    /// `U` on first use, and returns its uniforms. `defines` must be a function of the key
    /// alone, and a shader is always used with the same `U`.
    pub fn bind<U: UniformSet>(
        &mut self,
        dev: &Device,
        key: ProgramKey,
        defines: impl FnOnce() -> Vec<(String, String)>,
    ) -> Result<&U, GlError> {
        if self.frame_pending {
            self.frame_pending = false;
            self.frames += 1;
            self.stamp = self.frames;
        }
        let cached = match self.programs.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => e.insert(Cached {
                program: Program::build::<U>(dev, key.shader, &defines(), key.features)?,
                last_used: 0,
            }),
        };
        cached.last_used = self.stamp;
        let program = &cached.program;
        program.bind(dev);
        program.uniforms().ok_or_else(|| GlError::ProgramLink {
            shader: key.shader.to_string(),
            defines: String::new(),
            log: format!(
                "asked for uniform set {}, but built with another",
                std::any::type_name::<U>()
            ),
        })
    }

    /// Every cached variant, sorted by shader and features.
    pub fn report(&self) -> Vec<ProgramInfo> {
        let mut v: Vec<ProgramInfo> = self
            .programs
            .iter()
            .map(|(k, p)| ProgramInfo {
                shader: k.shader,
                features: k.features,
                dialect: k.dialect,
                source_bytes: p.program.source_bytes,
            })
            .collect();
        v.sort_by_key(|p| (p.shader, p.features));
        v
    }

    /// Number of cached programs.
    pub fn len(&self) -> usize {
        self.programs.len()
    }

    /// True when no program is cached.
    pub fn is_empty(&self) -> bool {
        self.programs.is_empty()
    }

    /// Starts a frame: the programs bound from now on count as its, and its first bind counts
    /// it among the frames.
    pub fn begin_frame(&mut self) {
        self.frame_pending = true;
    }

    /// Counts the programs bound from now until the next frame as that frame's (a warm-up
    /// builds them for it).
    pub fn count_for_next_frame(&mut self) {
        self.frame_pending = false;
        self.stamp = self.frames + 1;
    }

    /// Frees the programs none of the last `frames` frames used, nor anything since them
    /// ([`ProgramCache::count_for_next_frame`]), and returns how many. A frame that bound no
    /// program (refused, or failed before it drew) is not counted.
    pub fn free_unused(&mut self, dev: &Device, frames: u64) -> usize {
        let oldest_kept = self.frames.saturating_sub(frames) + 1;
        let before = self.programs.len();
        self.programs.retain(|_, cached| {
            let keep = cached.last_used >= oldest_kept;
            if !keep {
                cached.program.destroy(dev);
            }
            keep
        });
        before - self.programs.len()
    }

    /// Frees every program.
    pub fn destroy(&mut self, dev: &Device) {
        for (_, mut cached) in self.programs.drain() {
            cached.program.destroy(dev);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::context::context_or_skip;
    use crate::gl::HeadlessContext;

    /// Every attribute location is one whose state a call saves and gives back.
    #[test]
    fn attribute_locations_are_those_the_host_state_keeps() {
        for (location, name) in ATTRIBUTES {
            assert!(
                (*location as usize) < crate::gl::host_attributes::LOCATIONS,
                "{name} at {location}"
            );
        }
    }

    /// A headless ES 3.0 device, or `None` (a skip) on a machine without EGL.
    fn device() -> Option<(Device, HeadlessContext)> {
        let ctx = context_or_skip(EsVersion::Es3)?;
        Some((
            Device::new(ctx.load_gl().expect("gl"), EsVersion::Es3).expect("device"),
            ctx,
        ))
    }

    /// The link-time problems of `U` on `shader`, or "" when it links.
    fn problems<U: UniformSet>(dev: &Device, shader: &str) -> String {
        match Program::build::<U>(dev, shader, &[], 0) {
            Ok(mut p) => {
                p.destroy(dev);
                String::new()
            }
            Err(GlError::ProgramLink { log, .. }) => log,
            Err(e) => panic!("{e}"),
        }
    }

    struct Probe {
        big: Uniform<f32>,
    }
    impl UniformSet for Probe {
        fn resolve(r: &mut Resolver<'_>) -> Self {
            Probe {
                big: r.required("u_big"),
            }
        }
    }

    struct Misspelt(#[allow(dead_code)] Uniform<f32>);
    impl UniformSet for Misspelt {
        fn resolve(r: &mut Resolver<'_>) -> Self {
            Misspelt(r.optional("u_bigg"))
        }
    }

    struct WrongType(#[allow(dead_code)] Uniform<i32>);
    impl UniformSet for WrongType {
        fn resolve(r: &mut Resolver<'_>) -> Self {
            WrongType(r.required("u_big"))
        }
    }

    /// The albedo texture, compiled out of a variant without the texture feature.
    struct AlbedoTexture<const REQUIRED: bool>(Uniform<Sampler>);
    impl<const REQUIRED: bool> UniformSet for AlbedoTexture<REQUIRED> {
        fn resolve(r: &mut Resolver<'_>) -> Self {
            AlbedoTexture(r.required_when(REQUIRED, "u_albedoTex"))
        }
    }

    #[test]
    fn uniforms_are_checked_when_the_program_links() {
        let Some((dev, _ctx)) = device() else {
            return;
        };
        assert_eq!(problems::<Probe>(&dev, "precision_probe"), "");
        assert_eq!(
            problems::<Misspelt>(&dev, "precision_probe"),
            "uniform `u_bigg` is not declared by shader `precision_probe`"
        );
        assert_eq!(
            problems::<WrongType>(&dev, "precision_probe"),
            "uniform `u_big` is declared `float`, set as `int`"
        );
        let untextured = crate::methods::ShaderFeatures::default().defines(EsVersion::Es3, 1);
        match Program::build::<AlbedoTexture<true>>(&dev, "forward", &untextured, 0) {
            Err(GlError::ProgramLink { log, .. }) => assert_eq!(
                log,
                "uniform `u_albedoTex` is required but not active in this variant"
            ),
            other => panic!("{:?}", other.map(|_| "linked")),
        }
        let mut forward =
            Program::build::<AlbedoTexture<false>>(&dev, "forward", &untextured, 0).unwrap();
        assert!(forward
            .uniforms::<AlbedoTexture<false>>()
            .unwrap()
            .0
            .location
            .is_none());
        forward.destroy(&dev);
    }

    /// The suns' radiance, an array uniform, taken as `T`.
    struct SunRadiance<T: UniformType>(Uniform<T>);
    impl<T: UniformType + 'static> UniformSet for SunRadiance<T> {
        fn resolve(r: &mut Resolver<'_>) -> Self {
            SunRadiance(r.required("u_directionalRadiance"))
        }
    }

    #[test]
    fn an_array_uniform_is_found_by_its_name_and_checked_for_its_length() {
        let Some((dev, _ctx)) = device() else {
            return;
        };
        let sunny = crate::methods::ShaderFeatures(crate::methods::ShaderFeatures::DIRECTIONAL)
            .defines(EsVersion::Es3, 1);
        let mut forward =
            Program::build::<SunRadiance<[Vec3; 4]>>(&dev, "forward", &sunny, 0).unwrap();
        assert!(forward
            .uniforms::<SunRadiance<[Vec3; 4]>>()
            .unwrap()
            .0
            .location
            .is_some());
        forward.destroy(&dev);
        match Program::build::<SunRadiance<Vec3>>(&dev, "forward", &sunny, 0) {
            Err(GlError::ProgramLink { log, .. }) => assert_eq!(
                log,
                "uniform `u_directionalRadiance` is declared `vec3[4]`, set as `vec3`"
            ),
            other => panic!("{:?}", other.map(|_| "linked")),
        }
    }

    #[test]
    fn a_cached_program_is_used_with_the_set_it_was_built_with() {
        let Some((dev, _ctx)) = device() else {
            return;
        };
        let mut cache = ProgramCache::new();
        let key = ProgramKey {
            shader: "precision_probe",
            features: 0,
            dialect: EsVersion::Es3,
        };
        let probe = cache.bind::<Probe>(&dev, key, Vec::new).unwrap();
        assert!(probe.big.location.is_some());
        assert!(cache.bind::<Probe>(&dev, key, Vec::new).is_ok());
        assert!(cache
            .bind::<AlbedoTexture<false>>(&dev, key, Vec::new)
            .is_err());
        cache.destroy(&dev);
    }
}
