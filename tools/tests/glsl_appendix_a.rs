//! Every shader variant validated offline with glslangValidator: GLSL ES 1.00 under the
//! Appendix A limits strict mobile compilers enforce (no non-inductive or while loops, no
//! general indexing) and the ES 2.0 minimum resource limits; GLSL ES 3.00 with the defaults.
//! Mesa accepts far more than phones do, so compiling on llvmpipe proves little for ES 2.0.
//! The uniform, varying and attribute space of the ES 2.0 variants is counted here by §A.7's
//! packing (`glsl_packing`), which glslangValidator does not do.

use std::path::{Path, PathBuf};
use std::process::Command;

use manylight::gl::shader_source::{assemble, assemble_without_fragment_highp, Stage, SHADERS};
use manylight::methods::ShaderFeatures;
use manylight::EsVersion;

mod common;
mod glsl_packing;

use glsl_packing::{attribute_slots, declarations, packs, rows_needed};

/// Whether this run validates: glslangValidator must run here, or the test is skipped (a failure where
/// `MANYLIGHT_REQUIRE_ALL_TESTS` is set, as in CI, which installs it). False, without a
/// skip, in a run on another GLES implementation: validation is offline and runs once.
fn validates_here() -> bool {
    if common::independent_of_the_implementation("offline shader validation") {
        return false;
    }
    let found = Command::new("glslangValidator").arg("-v").output().is_ok();
    if !found {
        common::skip("glslangValidator not found: install the Debian package glslang-tools");
    }
    found
}

/// glslangValidator's default resource file with Appendix A switched on and the ES 2.0
/// minimum limits (GLSL ES 1.00 spec §7.4).
fn appendix_a_config(dir: &Path) -> std::path::PathBuf {
    let out = Command::new("glslangValidator")
        .arg("-c")
        .output()
        .expect("glslangValidator not found: install the Debian package glslang-tools");
    let mut conf = String::from_utf8(out.stdout).unwrap();
    let set = |conf: &mut String, key: &str, value: i32| {
        let line = conf
            .lines()
            .find(|l| l.split_whitespace().next() == Some(key))
            .unwrap_or_else(|| panic!("{key} missing from glslangValidator -c"))
            .to_string();
        *conf = conf.replace(&line, &format!("{key} {value}"));
    };
    for key in [
        "nonInductiveForLoops",
        "whileLoops",
        "doWhileLoops",
        "generalUniformIndexing",
        "generalAttributeMatrixVectorIndexing",
        "generalVaryingIndexing",
        "generalSamplerIndexing",
        "generalVariableIndexing",
        "generalConstantMatrixVectorIndexing",
    ] {
        set(&mut conf, key, 0);
    }
    for (key, v) in [
        ("MaxVertexAttribs", 8),
        ("MaxVertexUniformVectors", 128),
        ("MaxVaryingVectors", 8),
        ("MaxVertexTextureImageUnits", 0),
        ("MaxCombinedTextureImageUnits", 8),
        ("MaxTextureImageUnits", 8),
        // Not enforced by glslangValidator (a fragment shader of 40 vec4 uniforms passes):
        // every_es2_variant_fits_the_minimum_resources_of_every_device counts them.
        ("MaxFragmentUniformVectors", 16),
        ("MaxDrawBuffers", 1),
    ] {
        set(&mut conf, key, v);
    }
    let path = dir.join("appendix_a.conf");
    std::fs::write(&path, conf).unwrap();
    path
}

fn validate(conf: Option<&Path>, file: &Path) -> Result<(), String> {
    validate_all(conf, std::slice::from_ref(&file))
}

/// [`validate`] for many files in one run of the validator (a run per file spent most of this
/// test's minute starting processes).
fn validate_all(conf: Option<&Path>, files: &[&Path]) -> Result<(), String> {
    let mut cmd = Command::new("glslangValidator");
    if let Some(c) = conf {
        cmd.arg(c);
    }
    let out = cmd.args(files).output().expect("run glslangValidator");
    if out.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&out.stdout).into_owned())
    }
}

/// Files validated together; a group that fails is validated file by file, so that each
/// failure names its own variant.
const BATCH: usize = 200;

/// Every combination of feature bits a colour variant can have, the count variants
/// (evaluations, reaching lights, heatmap) with and without spots and RGBA8 light data, the
/// tone-mapped variants, the uniform-light-loop workaround and directional lights.
fn all_features() -> Vec<ShaderFeatures> {
    let mut all = colour_features();
    for count in [
        ShaderFeatures::COUNT_EVALS,
        ShaderFeatures::COUNT_REACHING,
        ShaderFeatures::COUNT_EVALS | ShaderFeatures::COUNT_HEATMAP,
    ] {
        for extra in [
            0,
            ShaderFeatures::SPOT,
            ShaderFeatures::LIGHTS_RGBA8,
            ShaderFeatures::SPOT | ShaderFeatures::LIGHTS_RGBA8,
            ShaderFeatures::NO_LIGHTS,
        ] {
            all.push(ShaderFeatures(count | extra));
        }
    }
    // The tone maps, each with linear output and with the material and light features.
    for curve in [
        ShaderFeatures::TONEMAP_REINHARD,
        ShaderFeatures::TONEMAP_ACES,
        ShaderFeatures::TONEMAP_NEUTRAL,
    ] {
        for extra in [
            0,
            ShaderFeatures::OUTPUT_LINEAR,
            ShaderFeatures::TEXTURE | ShaderFeatures::SPOT | ShaderFeatures::SPECULAR,
            ShaderFeatures::LIGHTS_RGBA8 | ShaderFeatures::REFERENCE_PRECISION,
            ShaderFeatures::NO_LIGHTS,
        ] {
            all.push(ShaderFeatures(curve | extra));
        }
    }
    // The driver workaround's light loop (SwiftShader, ES 2.0), with the material and light
    // features and counting.
    for extra in [
        0,
        ShaderFeatures::TEXTURE | ShaderFeatures::SPOT | ShaderFeatures::SPECULAR,
        ShaderFeatures::LIGHTS_RGBA8 | ShaderFeatures::SPOT,
        ShaderFeatures::COUNT_EVALS,
    ] {
        all.push(ShaderFeatures(ShaderFeatures::UNIFORM_LIGHT_LOOP | extra));
    }
    // The metallic-roughness BRDF with the material, light, precision and output features
    // (the deferred light pass's per-pixel choice among them).
    for extra in [
        0,
        ShaderFeatures::TEXTURE | ShaderFeatures::SPOT,
        ShaderFeatures::SPECULAR | ShaderFeatures::SPOT,
        ShaderFeatures::LIGHTS_RGBA8 | ShaderFeatures::REFERENCE_PRECISION,
        ShaderFeatures::OUTPUT_HDR | ShaderFeatures::TONEMAP_ACES,
        ShaderFeatures::UNIFORM_LIGHT_LOOP | ShaderFeatures::SPOT,
        ShaderFeatures::COUNT_EVALS,
    ] {
        all.push(ShaderFeatures(ShaderFeatures::METALLIC_ROUGHNESS | extra));
    }
    // Directional lights (their own loop over uniforms), with the material and light features,
    // without point lights, the workaround's loop, the precisions, HDR output and counting.
    for extra in [
        0,
        ShaderFeatures::SPECULAR,
        ShaderFeatures::TEXTURE | ShaderFeatures::SPOT | ShaderFeatures::SPECULAR,
        ShaderFeatures::LIGHTS_RGBA8 | ShaderFeatures::SPOT | ShaderFeatures::SPECULAR,
        ShaderFeatures::NO_LIGHTS | ShaderFeatures::SPECULAR,
        ShaderFeatures::UNIFORM_LIGHT_LOOP | ShaderFeatures::SPECULAR,
        ShaderFeatures::REFERENCE_PRECISION | ShaderFeatures::SPECULAR,
        ShaderFeatures::OUTPUT_HDR | ShaderFeatures::TONEMAP_ACES,
        ShaderFeatures::COUNT_EVALS,
        ShaderFeatures::METALLIC_ROUGHNESS | ShaderFeatures::SPOT,
    ] {
        all.push(ShaderFeatures(ShaderFeatures::DIRECTIONAL | extra));
    }
    // The glTF surface inputs, alone and together, with the material and light features, the
    // texture transform, RGBA8 light data and no lights.
    type F = ShaderFeatures;
    for input in [
        F::VERTEX_COLOR,
        F::VERTEX_COLOR | F::VERTEX_ALPHA,
        F::VERTEX_COLOR | F::VERTEX_ALPHA | F::ALPHA_MASK,
        F::NORMAL_MAP,
        F::EMISSIVE,
        F::EMISSIVE | F::EMISSIVE_MAP,
        F::OCCLUSION,
        F::MR_TEXTURE | F::METALLIC_ROUGHNESS,
        F::SECOND_UVS | F::TEXTURE_TRANSFORM | F::OCCLUSION,
        F::SURFACE_INPUTS | F::METALLIC_ROUGHNESS | F::DIRECTIONAL,
    ] {
        for extra in [
            0,
            F::TEXTURE | F::SPOT | F::SPECULAR | F::TEXTURE_TRANSFORM,
            F::LIGHTS_RGBA8 | F::OUTPUT_LINEAR,
            F::NO_LIGHTS | F::TEXTURE,
            F::UNIFORM_LIGHT_LOOP | F::TEXTURE_TRANSFORM,
        ] {
            all.push(ShaderFeatures(input | extra));
        }
    }
    all
}

/// Every combination of the colour variants' feature bits.
fn colour_features() -> Vec<ShaderFeatures> {
    let bits = [
        ShaderFeatures::TEXTURE,
        ShaderFeatures::SPOT,
        ShaderFeatures::SPECULAR,
        ShaderFeatures::LIGHTS_RGBA8,
        ShaderFeatures::OUTPUT_LINEAR,
        ShaderFeatures::OUTPUT_HDR,
        ShaderFeatures::NO_LIGHTS,
        ShaderFeatures::REFERENCE_PRECISION,
    ];
    (0..1u64 << bits.len())
        .map(|mask| {
            ShaderFeatures(
                bits.iter()
                    .enumerate()
                    .filter(|(i, _)| mask & (1 << i) != 0)
                    .fold(0, |acc, (_, b)| acc | b),
            )
        })
        .collect()
}

/// The name a `#define` line defines.
fn defined_name(line: &str) -> Option<&str> {
    line.strip_prefix("#define ")
        .map(|rest| rest.split([' ', '(']).next().unwrap_or(""))
}

/// The source without `#define` lines of macros nothing mentions (as a token, in the body or
/// in another macro's value): two variants that differ only there compile to the same program.
fn strip_unused_defines(src: &str) -> String {
    let mut used = std::collections::HashSet::new();
    for line in src.lines() {
        // A `#define` line uses what its value names, not its own name.
        let uses = match defined_name(line) {
            Some(name) => &line["#define ".len() + name.len()..],
            None => line,
        };
        used.extend(
            uses.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                .filter(|t| !t.is_empty()),
        );
    }
    src.lines()
        .filter(|l| defined_name(l).is_none_or(|name| used.contains(name)))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The distinct sources of every variant, written to a folder: (file, variant's name) for
/// ES 3.0 and for ES 2.0, and how many variants they came from.
struct Sources {
    es3: Vec<(PathBuf, String)>,
    es2: Vec<(PathBuf, String)>,
    variants: usize,
    distinct: usize,
}

fn write_distinct_sources(dir: &Path) -> Sources {
    let mut variants = 0;
    let (mut es3, mut es2): (Vec<(PathBuf, String)>, Vec<_>) = Default::default();
    // Variants whose assembled text is identical (a define the shader does not use) are
    // written once.
    let mut seen = std::collections::HashSet::new();
    for shader in SHADERS {
        for es in [EsVersion::Es2, EsVersion::Es3] {
            if shader.es3_only && es == EsVersion::Es2 {
                continue;
            }
            // On ES 2.0 also as a device without fragment highp compiles them: every float
            // mediump, radiance in its fp16-range form, the loop bound mediump ints allow.
            let targets: &[bool] = if es == EsVersion::Es2 {
                &[false, true]
            } else {
                &[false]
            };
            for (features, &mediump_only) in all_features()
                .into_iter()
                .flat_map(|f| targets.iter().map(move |t| (f, t)))
            {
                let (features, max_lights) = if mediump_only {
                    (features.with(ShaderFeatures::FP16_LIGHTS, true), 1_023)
                } else {
                    (features, 65_535)
                };
                let defines = features.defines(es, max_lights);
                for (stage, ext) in [(Stage::Vertex, "vert"), (Stage::Fragment, "frag")] {
                    let src = if mediump_only {
                        assemble_without_fragment_highp(shader.name, stage, &defines).unwrap()
                    } else {
                        assemble(shader.name, stage, es, &defines).unwrap()
                    };
                    variants += 1;
                    if !seen.insert(strip_unused_defines(&src)) {
                        continue;
                    }
                    let file = dir.join(format!(
                        "{}_{}_{:x}{}.{ext}",
                        shader.name,
                        es.major(),
                        features.0,
                        if mediump_only { "_mediump" } else { "" }
                    ));
                    std::fs::write(&file, &src).unwrap();
                    let name = format!(
                        "{} {es}{} {stage:?} features {:#x}",
                        shader.name,
                        if mediump_only {
                            " (no fragment highp)"
                        } else {
                            ""
                        },
                        features.0
                    );
                    match es {
                        EsVersion::Es2 => es2.push((file, name)),
                        EsVersion::Es3 => es3.push((file, name)),
                    }
                }
            }
        }
    }
    Sources {
        es3,
        es2,
        variants,
        distinct: seen.len(),
    }
}

#[test]
fn every_shader_variant_passes_the_strict_validator() {
    if !validates_here() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let conf = appendix_a_config(dir.path());
    let sources = write_distinct_sources(dir.path());
    let mut failures = Vec::new();
    eprintln!(
        "{} variants, {} distinct sources",
        sources.variants, sources.distinct
    );
    for (conf, group) in [(None, &sources.es3), (Some(conf.as_path()), &sources.es2)] {
        for batch in group.chunks(BATCH) {
            let files: Vec<&Path> = batch.iter().map(|(f, _)| f.as_path()).collect();
            if validate_all(conf, &files).is_ok() {
                continue;
            }
            for (file, name) in batch {
                if let Err(log) = validate(conf, file) {
                    failures.push(format!("{name}:\n{log}"));
                }
            }
        }
    }
    assert!(
        sources.variants
            >= (SHADERS.len() + 2 * SHADERS.iter().filter(|s| !s.es3_only).count()) * 2 * 256,
        "only {} variants checked",
        sources.variants
    );
    assert!(
        sources.distinct > SHADERS.len() * 4,
        "only {} distinct sources",
        sources.distinct
    );
    assert!(
        failures.is_empty(),
        "{} variants failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// The ES 2.0 minimum resources (GLSL ES 1.00 §7.4, §A.7) a variant may use: uniform rows and
/// texture units per stage, varying rows, attribute slots. Every ES 2.0 device offers these.
const FRAGMENT_UNIFORM_ROWS: usize = 16;
const VERTEX_UNIFORM_ROWS: usize = 128;
const VARYING_ROWS: usize = 8;
const FRAGMENT_SAMPLERS: usize = 8;
const ATTRIBUTE_SLOTS: usize = 8;

/// Every ES 2.0 variant's uniforms, varyings, samplers and attributes fit the minimum
/// resources by §A.7's packing, so no device may refuse one for space (glslangValidator does
/// not check this: a fragment shader of 40 vec4 uniforms passes it).
#[test]
fn every_es2_variant_fits_the_minimum_resources_of_every_device() {
    if !validates_here() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let sources = write_distinct_sources(dir.path());
    let mut failures = Vec::new();
    let mut fullest = (0, String::new());
    for batch in sources.es2.chunks(BATCH) {
        let files: Vec<&Path> = batch.iter().map(|(f, _)| f.as_path()).collect();
        for ((file, name), text) in batch.iter().zip(preprocessed(&files)) {
            let found = declarations(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
            let fragment = file.extension().is_some_and(|e| e == "frag");
            let (uniform_rows, samplers) = if fragment {
                (FRAGMENT_UNIFORM_ROWS, FRAGMENT_SAMPLERS)
            } else {
                // ES 2.0 need not have vertex texture units.
                (VERTEX_UNIFORM_ROWS, 0)
            };
            let needed = rows_needed(&found.uniforms);
            if fragment && needed > fullest.0 {
                fullest = (needed, name.clone());
            }
            if !packs(&found.uniforms, uniform_rows) {
                failures.push(format!(
                    "{name}: uniforms need {needed} rows of {uniform_rows}"
                ));
            }
            if found.samplers > samplers {
                failures.push(format!(
                    "{name}: {} samplers, {samplers} units",
                    found.samplers
                ));
            }
            if !packs(&found.varyings, VARYING_ROWS) {
                failures.push(format!(
                    "{name}: varyings need {} rows of {VARYING_ROWS}",
                    rows_needed(&found.varyings)
                ));
            }
            if attribute_slots(&found.attributes) > ATTRIBUTE_SLOTS {
                failures.push(format!(
                    "{name}: more than {ATTRIBUTE_SLOTS} attribute slots"
                ));
            }
        }
    }
    eprintln!(
        "fullest fragment variant: {} ({} of {FRAGMENT_UNIFORM_ROWS} uniform rows)",
        fullest.1, fullest.0
    );
    assert!(
        failures.is_empty(),
        "{} variants past the ES 2.0 minimums:\n{}",
        failures.len(),
        failures.join("\n")
    );
    // The count read the sources: the sun, surface-input and cluster uniforms of the fullest
    // variant take most of the grid.
    assert!(fullest.0 > FRAGMENT_UNIFORM_ROWS / 2, "{fullest:?}");
}

/// `files` preprocessed by glslangValidator (`-E`), one text a file, in order.
fn preprocessed(files: &[&Path]) -> Vec<String> {
    let out = Command::new("glslangValidator")
        .arg("-E")
        .args(files)
        .output()
        .expect("run glslangValidator");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    // Each file's text starts with its `#version` line.
    let mut texts: Vec<String> = Vec::new();
    for line in text.lines() {
        if line.starts_with("#version") {
            texts.push(String::new());
        }
        if let Some(t) = texts.last_mut() {
            t.push_str(line);
            t.push('\n');
        }
    }
    assert_eq!(texts.len(), files.len(), "one preprocessed text a file");
    texts
}

/// The configuration has teeth: a loop bounded by a uniform, accepted by Mesa, is rejected.
#[test]
fn the_appendix_a_configuration_rejects_a_uniform_loop_bound() {
    if !validates_here() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let conf = appendix_a_config(dir.path());
    let file = dir.path().join("bad.frag");
    std::fs::write(
        &file,
        "#version 100\nprecision mediump float;\nuniform int n;\nvoid main() {\n  float s = 0.0;\n  for (int i = 0; i < n; i++) { s += 1.0; }\n  gl_FragColor = vec4(s);\n}\n",
    )
    .unwrap();
    let err = validate(Some(&conf), &file).expect_err("a uniform loop bound must be rejected");
    assert!(err.contains("inductive"), "{err}");
    // Among valid files in one run of the validator too (how the variants are validated).
    let good = dir.path().join("good.frag");
    std::fs::write(
        &good,
        "#version 100\nprecision mediump float;\nvoid main() { gl_FragColor = vec4(1.0); }\n",
    )
    .unwrap();
    assert!(validate_all(Some(&conf), &[&good, &good]).is_ok());
    let err = validate_all(Some(&conf), &[&good, &file, &good])
        .expect_err("a batch with a uniform loop bound must be rejected");
    assert!(err.contains("inductive"), "{err}");
    // And the same file passes without the limits, so it is the configuration that bites.
    assert!(validate(None, &file).is_ok());
}
