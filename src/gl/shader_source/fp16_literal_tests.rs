//! Every constant a fragment shader without `highp` may hold is a normal fp16 number: NVIDIA
//! flushes fp16 subnormals (below 2⁻¹⁴) to zero, and past 65 504 fp16 is infinity. Llvmpipe
//! keeps subnormals, so only this check catches a `max(x, 1e-6)` turned into `max(x, 0)`.

use super::FILES;
use crate::gl::EsVersion;
use crate::methods::features::ShaderFeatures;

/// Files never compiled without fragment `highp`, and why.
const HIGHP_ONLY: &[(&str, &str)] = &[
    (
        "cluster_lookup.glsl",
        "tiled and clustered need fragment highp",
    ),
    ("clustered.frag", "tiled and clustered need fragment highp"),
    (
        "frame_position.glsl",
        "ES 3.0 tiled, clustered and deferred only, where fragment highp is required",
    ),
    ("precision_probe.frag", "it measures the precision itself"),
    (
        "deferred_common.glsl",
        "ES 3.0 only, where fragment highp is required",
    ),
    ("deferred_light.frag", "ES 3.0 only"),
    ("deferred_composite.frag", "ES 3.0 only"),
    ("gbuffer.frag", "ES 3.0 only"),
];

/// Whether `v` survives as itself in fp16: zero, or a normal number within range.
fn fp16_normal(v: f64) -> bool {
    v == 0.0 || (2f64.powi(-14)..=65504.0).contains(&v.abs())
}

/// The float literals of `code` (comments removed): digits with a point or an exponent.
fn float_literals(code: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in code.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        let bytes = code.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let starts = bytes[i].is_ascii_digit()
                || (bytes[i] == b'.' && i + 1 < bytes.len() && bytes[i + 1].is_ascii_digit());
            let after_name =
                i > 0 && (bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
            if !starts || after_name {
                i += 1;
                continue;
            }
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                i += 1;
                if i < bytes.len() && (bytes[i] == b'+' || bytes[i] == b'-') {
                    i += 1;
                }
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
            }
            let text = &code[start..i];
            if text.contains(['.', 'e', 'E']) {
                found.push((n + 1, text.to_string()));
            }
        }
    }
    found
}

#[test]
fn literals_finds_floats_and_skips_names_and_integers() {
    let code = "vec2 v2 = x * 1e-6 + .5 - 2.0E3 + 7; // 1e-9\nfloat f = 3.;";
    let texts: Vec<String> = float_literals(code).into_iter().map(|(_, t)| t).collect();
    assert_eq!(texts, ["1e-6", ".5", "2.0E3", "3."]);
}

#[test]
fn constants_without_fragment_highp_are_normal_fp16_numbers() {
    for (name, _) in HIGHP_ONLY {
        assert!(FILES.iter().any(|(file, _)| file == name), "no glsl/{name}");
    }
    let mut bad = Vec::new();
    for (file, code) in FILES {
        if HIGHP_ONLY.iter().any(|(name, _)| name == file) {
            continue;
        }
        for (line, text) in float_literals(code) {
            let value: f64 = text.trim_end_matches('.').parse().expect("a float literal");
            if !fp16_normal(value) {
                bad.push(format!("glsl/{file}:{line}: {text}"));
            }
        }
    }
    // The constants Rust defines into every variant.
    for (name, value) in ShaderFeatures::default().defines(EsVersion::Es2, 1023) {
        if let Ok(v) = value.parse::<f64>() {
            if !fp16_normal(v) {
                bad.push(format!("#define {name} {value}"));
            }
        }
    }
    assert!(bad.is_empty(), "not a normal fp16 number: {bad:#?}");
}
