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
    /// Needs GLSL ES 3.00 (`texelFetch` on float G-buffers, multiple outputs).
    pub es3_only: bool,
    /// Declares its own fragment outputs (multiple render targets), so the prelude's single
    /// `o_color` is left out.
    pub mrt: bool,
}

/// Every program the renderer builds.
pub const SHADERS: &[ShaderDesc] = &[
    ShaderDesc {
        name: "depth",
        vertex: "mesh.vert",
        fragment: "depth.frag",
        es3_only: false,
        mrt: false,
    },
    ShaderDesc {
        name: "forward",
        vertex: "mesh.vert",
        fragment: "forward.frag",
        es3_only: false,
        mrt: false,
    },
    ShaderDesc {
        name: "clustered",
        vertex: "mesh.vert",
        fragment: "clustered.frag",
        es3_only: false,
        mrt: false,
    },
    ShaderDesc {
        name: "precision_probe",
        vertex: "fullscreen.vert",
        fragment: "precision_probe.frag",
        es3_only: false,
        mrt: false,
    },
    ShaderDesc {
        name: "msaa_resolve",
        vertex: "msaa_resolve.vert",
        fragment: "msaa_resolve.frag",
        es3_only: false,
        mrt: false,
    },
    ShaderDesc {
        name: "solid",
        vertex: "fullscreen.vert",
        fragment: "solid.frag",
        es3_only: false,
        mrt: false,
    },
    ShaderDesc {
        name: "gbuffer",
        vertex: "mesh.vert",
        fragment: "gbuffer.frag",
        es3_only: true,
        mrt: true,
    },
    ShaderDesc {
        name: "deferred_light",
        vertex: "light_volume.vert",
        fragment: "deferred_light.frag",
        es3_only: true,
        mrt: false,
    },
    ShaderDesc {
        name: "deferred_light_fullscreen",
        vertex: "light_fullscreen.vert",
        fragment: "deferred_light.frag",
        es3_only: true,
        mrt: false,
    },
    ShaderDesc {
        name: "deferred_composite",
        vertex: "fullscreen.vert",
        fragment: "deferred_composite.frag",
        es3_only: true,
        mrt: false,
    },
];

/// The files of `glsl/`, embedded so the binary needs no data files.
pub const FILES: &[(&str, &str)] = &[
    ("mesh.vert", include_str!("../../glsl/mesh.vert")),
    ("depth.frag", include_str!("../../glsl/depth.frag")),
    (
        "msaa_resolve.vert",
        include_str!("../../glsl/msaa_resolve.vert"),
    ),
    (
        "msaa_resolve.frag",
        include_str!("../../glsl/msaa_resolve.frag"),
    ),
    ("forward.frag", include_str!("../../glsl/forward.frag")),
    ("solid.frag", include_str!("../../glsl/solid.frag")),
    (
        "light_model.glsl",
        include_str!("../../glsl/light_model.glsl"),
    ),
    (
        "light_data.glsl",
        include_str!("../../glsl/light_data.glsl"),
    ),
    ("surface.glsl", include_str!("../../glsl/surface.glsl")),
    (
        "directional.glsl",
        include_str!("../../glsl/directional.glsl"),
    ),
    (
        "surface_maps.glsl",
        include_str!("../../glsl/surface_maps.glsl"),
    ),
    (
        "light_struct.glsl",
        include_str!("../../glsl/light_struct.glsl"),
    ),
    ("gbuffer.frag", include_str!("../../glsl/gbuffer.frag")),
    (
        "deferred_common.glsl",
        include_str!("../../glsl/deferred_common.glsl"),
    ),
    (
        "deferred_light.frag",
        include_str!("../../glsl/deferred_light.frag"),
    ),
    (
        "deferred_composite.frag",
        include_str!("../../glsl/deferred_composite.frag"),
    ),
    (
        "light_volume.vert",
        include_str!("../../glsl/light_volume.vert"),
    ),
    (
        "light_fullscreen.vert",
        include_str!("../../glsl/light_fullscreen.vert"),
    ),
    (
        "deferred_light_instance.glsl",
        include_str!("../../glsl/deferred_light_instance.glsl"),
    ),
    (
        "deferred_light_varyings.glsl",
        include_str!("../../glsl/deferred_light_varyings.glsl"),
    ),
    (
        "fullscreen.vert",
        include_str!("../../glsl/fullscreen.vert"),
    ),
    (
        "precision_probe.frag",
        include_str!("../../glsl/precision_probe.frag"),
    ),
    (
        "data_texture.glsl",
        include_str!("../../glsl/data_texture.glsl"),
    ),
    ("clustered.frag", include_str!("../../glsl/clustered.frag")),
    (
        "cluster_lookup.glsl",
        include_str!("../../glsl/cluster_lookup.glsl"),
    ),
    (
        "frame_position.glsl",
        include_str!("../../glsl/frame_position.glsl"),
    ),
];

/// Looks up a shader by name.
pub fn shader(name: &str) -> Result<&'static ShaderDesc, GlError> {
    SHADERS
        .iter()
        .find(|s| s.name == name)
        .ok_or_else(|| GlError::ShaderSource(format!("no shader named `{name}`")))
}

/// The uniforms `shader_name`'s two stages declare, in any variant (feature blocks and dialect
/// branches included): the names a program's typed uniforms may use.
pub fn declared_uniforms(shader_name: &str) -> Result<Vec<String>, GlError> {
    let desc = shader(shader_name)?;
    let mut text = String::new();
    for file in [desc.vertex, desc.fragment] {
        expand(file, &mut text, &mut Vec::new())?;
    }
    let mut names: Vec<String> = Vec::new();
    for line in text.lines() {
        let Some(declaration) = line.trim().strip_prefix("uniform ") else {
            continue;
        };
        let name = declaration.split(';').next().unwrap_or_default();
        // An array's name without its size (`u_x[N]`).
        let name = name.split('[').next().unwrap_or_default();
        if let Some(name) = name.split_whitespace().last() {
            if !names.iter().any(|n| n == name) {
                names.push(name.to_string());
            }
        }
    }
    Ok(names)
}

fn file(name: &str) -> Result<&'static str, GlError> {
    FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
        .ok_or_else(|| GlError::ShaderSource(format!("no file `{name}` in glsl/")))
}

/// The ES 2.0 fragment prelude of a device without fragment highp: what the preprocessor
/// branch of the normal prelude picks on such a device, chosen outright so a driver that has
/// highp can play one that has not.
const ES2_FRAGMENT_MEDIUMP_ONLY: &str = "#version 100\n#define GLSL_ES 100\n#define CENTROID\n\
     precision mediump float;\nprecision mediump int;\n#define HIGHP mediump\n\
     #define VARYING varying\n#define TEXTURE2D texture2D\n#define FRAG_COLOR gl_FragColor\n";

fn prelude(stage: Stage, dialect: EsVersion, mrt: bool) -> &'static str {
    match (dialect, stage) {
        (EsVersion::Es3, Stage::Fragment) if mrt => {
            "#version 300 es\n#define GLSL_ES 300\n#define CENTROID centroid\n\
             precision highp float;\nprecision highp int;\n\
             #define HIGHP highp\n#define VARYING in\n#define TEXTURE2D texture\n"
        }
        (EsVersion::Es2, Stage::Vertex) => {
            "#version 100\n#define GLSL_ES 100\n#define CENTROID\n\
             precision highp float;\nprecision highp int;\n\
             #define HIGHP highp\n#define ATTRIBUTE attribute\n#define VARYING varying\n"
        }
        (EsVersion::Es3, Stage::Vertex) => {
            "#version 300 es\n#define GLSL_ES 300\n#define CENTROID centroid\n\
             precision highp float;\nprecision highp int;\n\
             #define HIGHP highp\n#define ATTRIBUTE in\n#define VARYING out\n"
        }
        // ES 2.0 fragment stages may lack highp; everything then runs at mediump (see
        // ES2_FRAGMENT_MEDIUMP_ONLY), which the caps report and the stability tests measure.
        (EsVersion::Es2, Stage::Fragment) => {
            "#version 100\n#define GLSL_ES 100\n#define CENTROID\n\
             #ifdef GL_FRAGMENT_PRECISION_HIGH\n\
             precision highp float;\nprecision highp int;\n#define HIGHP highp\n#else\n\
             precision mediump float;\nprecision mediump int;\n#define HIGHP mediump\n#endif\n\
             #define VARYING varying\n#define TEXTURE2D texture2D\n#define FRAG_COLOR gl_FragColor\n"
        }
        (EsVersion::Es3, Stage::Fragment) => {
            "#version 300 es\n#define GLSL_ES 300\n#define CENTROID centroid\n\
             precision highp float;\nprecision highp int;\n\
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
    assemble_for(shader_name, stage, dialect, false, defines)
}

/// [`assemble`] for a desktop GL context when `desktop`: the GLSL ES 3.00 source with a
/// `#version 330 core` line (the two languages agree on everything the shaders use).
pub fn assemble_for(
    shader_name: &str,
    stage: Stage,
    dialect: EsVersion,
    desktop: bool,
    defines: &[(String, String)],
) -> Result<String, GlError> {
    let source = assemble_es(shader_name, stage, dialect, defines)?;
    Ok(if desktop {
        source.replacen("#version 300 es", "#version 330 core", 1)
    } else {
        source
    })
}

/// [`assemble`] at the ES 2.0 level for a device without fragment highp (see
/// [`super::Restrictions`]): fragment shaders get the all-`mediump` prelude.
pub fn assemble_without_fragment_highp(
    shader_name: &str,
    stage: Stage,
    defines: &[(String, String)],
) -> Result<String, GlError> {
    let prelude = match stage {
        Stage::Fragment => Some(ES2_FRAGMENT_MEDIUMP_ONLY),
        Stage::Vertex => None,
    };
    assemble_with(shader_name, stage, EsVersion::Es2, prelude, defines)
}

fn assemble_es(
    shader_name: &str,
    stage: Stage,
    dialect: EsVersion,
    defines: &[(String, String)],
) -> Result<String, GlError> {
    assemble_with(shader_name, stage, dialect, None, defines)
}

/// Assembly with the dialect's prelude, or `prelude` instead when given.
fn assemble_with(
    shader_name: &str,
    stage: Stage,
    dialect: EsVersion,
    prelude_override: Option<&str>,
    defines: &[(String, String)],
) -> Result<String, GlError> {
    let desc = shader(shader_name)?;
    let body = match stage {
        Stage::Vertex => desc.vertex,
        Stage::Fragment => desc.fragment,
    };
    if desc.es3_only && dialect == EsVersion::Es2 {
        return Err(GlError::ShaderSource(format!(
            "shader `{shader_name}` needs GLSL ES 3.00"
        )));
    }
    let mut out =
        String::from(prelude_override.unwrap_or_else(|| prelude(stage, dialect, desc.mrt)));
    for (name, value) in defines {
        out.push_str(&format!("#define {name} {value}\n"));
    }
    let mut stack = Vec::new();
    let mut body_text = String::new();
    expand(body, &mut body_text, &mut stack)?;
    out.push_str(&strip_feature_blocks(&body_text, defines)?);
    Ok(out)
}

/// Removes `#if FLAG` / `#if !FLAG` blocks whose flag is a `#define`d 0 or 1, keeping only the
/// taken branch, so a variant's source holds no code for features the scene lacks (what the
/// tests check, and what a driver has to parse). Other conditionals (`GLSL_ES == 100`,
/// `GL_FRAGMENT_PRECISION_HIGH`) are left for the GLSL preprocessor.
pub fn strip_feature_blocks(source: &str, defines: &[(String, String)]) -> Result<String, GlError> {
    let flag = |cond: &str| -> Option<bool> {
        let cond = cond.trim();
        let (negate, name) = match cond.strip_prefix('!') {
            Some(rest) => (true, rest.trim()),
            None => (false, cond),
        };
        let value = defines.iter().find(|(n, _)| n == name)?.1.trim();
        let on = match value {
            "0" => false,
            "1" => true,
            _ => return None,
        };
        Some(on != negate)
    };
    enum Frame {
        Known { parent: bool, taken: bool },
        Unknown { parent: bool },
    }
    let mut out = String::with_capacity(source.len());
    let mut stack: Vec<Frame> = Vec::new();
    let mut active = true;
    for line in source.lines() {
        let t = line.trim_start();
        let directive = |d: &str| {
            t.strip_prefix(d)
                .filter(|r| r.is_empty() || r.starts_with(char::is_whitespace))
        };
        if let Some(cond) = directive("#if") {
            match flag(cond) {
                Some(on) => {
                    stack.push(Frame::Known {
                        parent: active,
                        taken: on,
                    });
                    active = active && on;
                }
                None => {
                    stack.push(Frame::Unknown { parent: active });
                    if active {
                        out.push_str(line);
                        out.push('\n');
                    }
                }
            }
            continue;
        }
        if directive("#ifdef").is_some() || directive("#ifndef").is_some() {
            stack.push(Frame::Unknown { parent: active });
            if active {
                out.push_str(line);
                out.push('\n');
            }
            continue;
        }
        let elif = directive("#elif");
        let is_else = directive("#else").is_some();
        let is_endif = directive("#endif").is_some();
        if elif.is_none() && !is_else && !is_endif {
            if active {
                out.push_str(line);
                out.push('\n');
            }
            continue;
        }
        let top = stack
            .last_mut()
            .ok_or_else(|| GlError::ShaderSource(format!("unmatched `{}`", t.trim())))?;
        match top {
            Frame::Known { parent, taken } => {
                if let Some(cond) = elif {
                    let on = flag(cond).ok_or_else(|| {
                        GlError::ShaderSource(format!(
                            "`{}` mixes a feature flag with another condition",
                            t.trim()
                        ))
                    })?;
                    active = *parent && !*taken && on;
                    *taken |= on;
                } else if is_else {
                    active = *parent && !*taken;
                    *taken = true;
                } else {
                    active = *parent;
                    stack.pop();
                }
            }
            Frame::Unknown { parent } => {
                let parent = *parent;
                if parent {
                    out.push_str(line);
                    out.push('\n');
                }
                if is_endif {
                    active = parent;
                    stack.pop();
                }
            }
        }
    }
    if !stack.is_empty() {
        return Err(GlError::ShaderSource("unterminated #if".into()));
    }
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
mod fp16_literal_tests;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assembles_every_shader_in_both_dialects() {
        for s in SHADERS {
            for d in [EsVersion::Es2, EsVersion::Es3] {
                if s.es3_only && d == EsVersion::Es2 {
                    assert!(assemble(s.name, Stage::Vertex, d, &[]).is_err());
                    continue;
                }
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
    fn feature_blocks_are_stripped_and_others_kept() {
        let src = "a\n#if HAS_X\nx\n#if GLSL_ES == 100\nx100\n#else\nx300\n#endif\n#else\nnox\n#endif\n#if !HAS_X\nnotx\n#endif\n#if HAS_Y\ny\n#elif HAS_X\nyx\n#else\nnone\n#endif\nb\n";
        let d = |x: &str, y: &str| {
            vec![
                ("HAS_X".to_string(), x.to_string()),
                ("HAS_Y".to_string(), y.to_string()),
            ]
        };
        assert_eq!(
            strip_feature_blocks(src, &d("1", "0")).unwrap(),
            "a\nx\n#if GLSL_ES == 100\nx100\n#else\nx300\n#endif\nyx\nb\n"
        );
        assert_eq!(
            strip_feature_blocks(src, &d("0", "0")).unwrap(),
            "a\nnox\nnotx\nnone\nb\n"
        );
        assert_eq!(
            strip_feature_blocks(src, &d("0", "1")).unwrap(),
            "a\nnox\nnotx\ny\nb\n"
        );
        assert!(strip_feature_blocks("#endif\n", &[]).is_err());
        assert!(strip_feature_blocks("#if HAS_X\n", &d("1", "1")).is_err());
    }

    #[test]
    fn declared_uniforms_cover_both_stages_and_every_branch() {
        let names = declared_uniforms("clustered").unwrap();
        // Vertex stage, an include, a dialect branch and a feature block.
        for name in [
            "u_modelView",
            "u_lights",
            "u_gridInvHeight",
            "u_longestList",
        ] {
            assert!(names.iter().any(|n| n == name), "{name} in {names:?}");
        }
        // An array, by its name alone.
        assert!(
            names.iter().any(|n| n == "u_directionalRadiance"),
            "{names:?}"
        );
        // Declared twice (one per dialect), listed once.
        assert_eq!(names.iter().filter(|n| *n == "u_grid").count(), 1);
        assert!(!names.iter().any(|n| n.contains(';') || n == "u_grid;"));
        assert_eq!(
            declared_uniforms("precision_probe").unwrap(),
            ["u_big", "u_one"]
        );
        assert!(declared_uniforms("nope").is_err());
    }

    #[test]
    fn numbered_source_counts_lines() {
        assert_eq!(numbered("a\nb"), "   1 | a\n   2 | b\n");
    }
}
