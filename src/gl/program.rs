//! Programs: compile, link, uniforms, and the cache keyed by (shader, feature bits, dialect).
#![allow(unsafe_code)]

use std::collections::HashMap;

use glam::{Mat3, Mat4, Vec3, Vec4};
use glow::HasContext;

use super::shader_source::{self, numbered, Stage};
use super::{Device, EsVersion, GlError};

/// Vertex attribute locations shared by every program (bound before linking).
pub const ATTRIBUTES: &[(u32, &str)] = &[(0, "a_position"), (1, "a_normal"), (2, "a_uv")];

/// A linked program with a uniform-location cache.
pub struct Program {
    raw: glow::Program,
    uniforms: HashMap<String, Option<glow::UniformLocation>>,
    /// Total assembled source size in bytes (vertex + fragment), for stats.
    pub source_bytes: usize,
    destroyed: bool,
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
    /// Assembles, compiles and links `shader` with `defines`.
    pub fn build(
        dev: &Device,
        shader: &str,
        defines: &[(String, String)],
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
        unsafe {
            let raw = dev.create_program()?;
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
            Ok(Program {
                raw,
                uniforms: HashMap::new(),
                source_bytes: vs_len + fs_len,
                destroyed: false,
            })
        }
    }

    /// Makes this the current program.
    pub fn bind(&self, dev: &Device) {
        unsafe { dev.gl.use_program(Some(self.raw)) }
    }

    fn location(&mut self, dev: &Device, name: &str) -> Option<glow::UniformLocation> {
        if let Some(l) = self.uniforms.get(name) {
            return *l;
        }
        let l = unsafe { dev.gl.get_uniform_location(self.raw, name) };
        self.uniforms.insert(name.to_string(), l);
        l
    }

    /// Sets a `float` uniform (ignored when the variant compiled it out).
    pub fn set_f32(&mut self, dev: &Device, name: &str, v: f32) {
        let l = self.location(dev, name);
        unsafe { dev.gl.uniform_1_f32(l.as_ref(), v) }
    }

    /// Sets an `int` or sampler uniform.
    pub fn set_i32(&mut self, dev: &Device, name: &str, v: i32) {
        let l = self.location(dev, name);
        unsafe { dev.gl.uniform_1_i32(l.as_ref(), v) }
    }

    /// Sets a `vec2` uniform.
    pub fn set_vec2(&mut self, dev: &Device, name: &str, v: [f32; 2]) {
        let l = self.location(dev, name);
        unsafe { dev.gl.uniform_2_f32(l.as_ref(), v[0], v[1]) }
    }

    /// Sets a `vec3` uniform.
    pub fn set_vec3(&mut self, dev: &Device, name: &str, v: Vec3) {
        let l = self.location(dev, name);
        unsafe { dev.gl.uniform_3_f32(l.as_ref(), v.x, v.y, v.z) }
    }

    /// Sets a `vec4` uniform.
    pub fn set_vec4(&mut self, dev: &Device, name: &str, v: Vec4) {
        let l = self.location(dev, name);
        unsafe { dev.gl.uniform_4_f32(l.as_ref(), v.x, v.y, v.z, v.w) }
    }

    /// Sets a `mat3` uniform.
    pub fn set_mat3(&mut self, dev: &Device, name: &str, m: &Mat3) {
        let l = self.location(dev, name);
        unsafe {
            dev.gl
                .uniform_matrix_3_f32_slice(l.as_ref(), false, &m.to_cols_array())
        }
    }

    /// Sets a `mat4` uniform.
    pub fn set_mat4(&mut self, dev: &Device, name: &str, m: &Mat4) {
        let l = self.location(dev, name);
        unsafe {
            dev.gl
                .uniform_matrix_4_f32_slice(l.as_ref(), false, &m.to_cols_array())
        }
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
        if !self.destroyed {
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

/// Built programs by key.
#[derive(Default)]
pub struct ProgramCache {
    programs: HashMap<ProgramKey, Program>,
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

    /// The program for `key`, building it with `defines()` on first use. `defines` must be a
    /// function of the key alone.
    pub fn get_or_build(
        &mut self,
        dev: &Device,
        key: ProgramKey,
        defines: impl FnOnce() -> Vec<(String, String)>,
    ) -> Result<&mut Program, GlError> {
        match self.programs.entry(key) {
            std::collections::hash_map::Entry::Occupied(e) => Ok(e.into_mut()),
            std::collections::hash_map::Entry::Vacant(e) => {
                Ok(e.insert(Program::build(dev, key.shader, &defines())?))
            }
        }
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
                source_bytes: p.source_bytes,
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

    /// Frees every program.
    pub fn destroy(&mut self, dev: &Device) {
        for (_, mut p) in self.programs.drain() {
            p.destroy(dev);
        }
    }
}
