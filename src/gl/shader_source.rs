//! GLSL assembly. One source per shader in `glsl/` (embedded at compile time), assembled as:
//!
//! ```text
//! version line  →  prelude (precision, dialect macros)  →  #defines  →  body with #include
//! ```
//!
//! Bodies are written once for both dialects using the prelude's macros instead of
//! redefining keywords: `ATTRIBUTE`, `VARYING`, `TEXTURE2D`, `FRAG_COLOR`, `HIGHP`, and
//! `GLSL_ES` (100 or 300) for the few places that differ (data-texture reads, loop bounds).
//! `#include "file.glsl"` pulls in a shared chunk (the light model, light-data reads).
//!
//! This file is GL-free so tests can validate every variant with `glslangValidator`.

use super::{EsVersion, GlError};

/// Shader stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Vertex shader.
    Vertex,
    /// Fragment shader.
    Fragment,
}

impl Stage {
    /// `vertex` or `fragment`.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Vertex => "vertex",
            Stage::Fragment => "fragment",
        }
    }
}

/// A program: its vertex and fragment files.
#[derive(Clone, Copy, Debug)]
pub struct ShaderDesc {
    /// Name used in the program cache and in errors.
    pub name: &'static str,
    /// Vertex file in `glsl/`.
    pub vertex: &'static str,
    /// Fragment file in `glsl/`.
    pub fragment: &'static str,
}

/// Every program the renderer builds.
pub const SHADERS: &[ShaderDesc] = &[
    ShaderDesc {
        name: "depth",
        vertex: "mesh.vert",
        fragment: "depth.frag",
    },
    ShaderDesc {
        name: "forward",
        vertex: "mesh.vert",
        fragment: "forward.frag",
    },
    ShaderDesc {
        name: "clustered",
        vertex: "mesh.vert",
        fragment: "clustered.frag",
    },
    ShaderDesc {
        name: "precision_probe",
        vertex: "fullscreen.vert",
        fragment: "precision_probe.frag",
    },
];

/// The files of `glsl/`, embedded so the binary needs no data files.
pub const FILES: &[(&str, &str)] = &[
    ("mesh.vert", include_str!("../../glsl/mesh.vert")),
    ("depth.frag", include_str!("../../glsl/depth.frag")),
    ("forward.frag", include_str!("../../glsl/forward.frag")),
    (
        "light_model.glsl",
        include_str!("../../glsl/light_model.glsl"),
    ),
    (
        "light_data.glsl",
        include_str!("../../glsl/light_data.glsl"),
    ),
    ("surface.glsl", include_str!("../../glsl/surface.glsl")),
    ("fullscreen.vert", include_str!("../../glsl/fullscreen.vert")),
    ("precision_probe.frag", include_str!("../../glsl/precision_probe.frag")),
    (
        "data_texture.glsl",
        include_str!("../../glsl/data_texture.glsl"),
    ),
    ("clustered.frag", include_str!("../../glsl/clustered.frag")),
    (
        "cluster_lookup.glsl",
        include_str!("../../glsl/cluster_lookup.glsl"),
    ),
];

/// Looks up a shader by name.
pub fn shader(name: &str) -> Result<&'static ShaderDesc, GlError> {
    SHADERS
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| GlError::ShaderSource(format!("no shader named `{name}`")))
}

fn file(name: &str) -> Result<&'static str, GlError> {
    FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .ok_or_else(|| GlError::ShaderSource(format!("no file `{name}` in glsl/")))
}

fn prelude(stage: Stage, dialect: EsVersion) -> &'static str {
    match (dialect, stage) {
        (EsVersion::Es2, Stage::Vertex) => {
            "#version 100\n#define GLSL_ES 100\nprecision highp float;\nprecision highp int;\n\
             #define HIGHP highp\n#define ATTRIBUTE attribute\n#define VARYING varying\n"
        }
        (EsVersion::Es3, Stage::Vertex) => {
            "#version 300 es\n#define GLSL_ES 300\nprecision highp float;\nprecision highp int;\n\
             #define HIGHP highp\n#define ATTRIBUTE in\n#define VARYING out\n"
        }
        // ES 2.0 fragment stages may lack highp; everything then runs at mediump, which the
        // caps report and the stability tests measure.
        (EsVersion::Es2, Stage::Fragment) => {
            "#version 100\n#define GLSL_ES 100\n#ifdef GL_FRAGMENT_PRECISION_HIGH\n\
             precision highp float;\nprecision highp int;\n#define HIGHP highp\n#else\n\
             precision mediump float;\nprecision mediump int;\n#define HIGHP mediump\n#endif\n\
             #define VARYING varying\n#define TEXTURE2D texture2D\n#define FRAG_COLOR gl_FragColor\n"
        }
        (EsVersion::Es3, Stage::Fragment) => {
            "#version 300 es\n#define GLSL_ES 300\nprecision highp float;\nprecision highp int;\n\
             #define HIGHP highp\n#define VARYING in\n#define TEXTURE2D texture\n\
             out vec4 o_color;\n#define FRAG_COLOR o_color\n"
        }
    }
}

/// Assembles the source of one stage of `shader` for `dialect` with the given `#define`s.
pub fn assemble(
    shader_name: &str,
    stage: Stage,
    dialect: EsVersion,
    defines: &[(String, String)],
) -> Result<String, GlError> {
    let desc = shader(shader_name)?;
    let body = match stage {
        Stage::Vertex => desc.vertex,
        Stage::Fragment => desc.fragment,
    };
    let mut out = String::from(prelude(stage, dialect));
    for (name, value) in defines {
        out.push_str(&format!("#define {name} {value}\n"));
    }
    let mut stack = Vec::new();
    expand(body, &mut out, &mut stack)?;
    Ok(out)
}

fn expand(name: &str, out: &mut String, stack: &mut Vec<String>) -> Result<(), GlError> {
    if stack.iter().any(|s| s == name) {
        return Err(GlError::ShaderSource(format!(
            "include cycle: {} → {name}",
            stack.join(" → ")
        )));
    }
    stack.push(name.to_string());
    for line in file(name)?.lines() {
        match line.trim().strip_prefix("#include") {
            Some(rest) => expand(rest.trim().trim_matches('"'), out, stack)?,
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    stack.pop();
    Ok(())
}

/// The source with line numbers, as shown in compile errors.
pub fn numbered(source: &str) -> String {
    source
        .lines()
        .enumerate()
        .map(|(i, l)| format!("{:4} | {l}\n", i + 1))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assembles_every_shader_in_both_dialects() {
        for s in SHADERS {
            for d in [EsVersion::Es2, EsVersion::Es3] {
                for stage in [Stage::Vertex, Stage::Fragment] {
                    let src = assemble(s.name, stage, d, &[("FOO".into(), "1".into())]).unwrap();
                    let first = src.lines().next().unwrap();
                    assert_eq!(
                        first,
                        if d == EsVersion::Es2 {
                            "#version 100"
                        } else {
                            "#version 300 es"
                        }
                    );
                    assert!(src.contains("#define FOO 1"));
                    assert!(!src.contains("#include"));
                }
            }
        }
    }

    #[test]
    fn numbered_source_counts_lines() {
        assert_eq!(numbered("a\nb"), "   1 | a\n   2 | b\n");
    }
}
