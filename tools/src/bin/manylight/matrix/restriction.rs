//! Whether a row's driver switch (a Mesa environment override, a second Mesa driver) took
//! effect: another implementation ignores Mesa's switches, and a row that claims a restriction
//! its context does not show would pass on the unrestricted driver under the restriction's name.

use serde_json::{json, Value};

/// What a row's context shows when its switch took effect.
#[derive(Clone, Copy)]
pub enum Shows {
    /// The row sets no switch.
    Nothing,
    /// No float textures listed (`MESA_EXTENSION_OVERRIDE` removed them).
    NoFloatTextures,
    /// A `GL_VERSION` starting so (`MESA_GLES_VERSION_OVERRIDE` capped the driver).
    GlVersion(&'static str),
    /// A `GL_RENDERER` naming this driver (`GALLIUM_DRIVER` picked it).
    Renderer(&'static str),
}

impl Shows {
    /// Why `row`'s context does not show the switch, if it does not.
    fn missing(self, row: &Value) -> Option<String> {
        let text = |key: &str| row[key].as_str().unwrap_or("nothing").to_string();
        match self {
            Shows::Nothing => None,
            Shows::NoFloatTextures => (row["float_textures"] != false)
                .then(|| "its context still lists float textures".to_string()),
            Shows::GlVersion(v) => (!text("gl_version").starts_with(v))
                .then(|| format!("its context is {}, not {v}", text("gl_version"))),
            Shows::Renderer(r) => (!text("renderer").contains(r))
                .then(|| format!("its renderer is {}, not {r}", text("renderer"))),
        }
    }
}

/// Marks `row` when its switch (`switches`, each `VAR=value`, shown as `shows`) did not take
/// effect: unavailable on an implementation other than Mesa, whose switches it ignores, and a
/// failure on Mesa itself. Its methods ran without the restriction, so they are dropped.
pub fn check(row: &mut Value, shows: Shows, switches: &[String]) {
    if row["error"].is_string() {
        return;
    }
    let Some(missing) = shows.missing(row) else {
        return;
    };
    let implementation = row["implementation"].as_str().unwrap_or("?").to_string();
    let mesa = implementation.starts_with("Mesa");
    let why = if mesa {
        "Mesa did not apply it"
    } else {
        "a Mesa switch, which this implementation ignores"
    };
    row["error"] = json!(format!(
        "{} not applied ({why}): {missing}",
        switches.join(" ")
    ));
    row["refused"] = json!(!mesa);
    row["methods"] = json!([]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(implementation: &str, float: bool, version: &str, renderer: &str) -> Value {
        json!({"implementation": implementation, "float_textures": float,
               "gl_version": version, "renderer": renderer,
               "methods": [{"name": "forward", "max_abs_vs_forward": 0}]})
    }

    fn switch(text: &str) -> Vec<String> {
        vec![text.to_string()]
    }

    const NO_FLOAT: &str = "MESA_EXTENSION_OVERRIDE=-GL_OES_texture_float";

    #[test]
    fn a_switch_that_took_effect_leaves_the_row_as_it_was() {
        let cases = [
            (
                Shows::NoFloatTextures,
                row("Mesa llvmpipe", false, "OpenGL ES 2.0 Mesa", "llvmpipe"),
            ),
            (
                Shows::GlVersion("OpenGL ES 2.0"),
                row("Mesa llvmpipe", true, "OpenGL ES 2.0 Mesa", "llvmpipe"),
            ),
            (
                Shows::Renderer("softpipe"),
                row("Mesa softpipe", true, "OpenGL ES 3.1 Mesa", "softpipe"),
            ),
            (
                Shows::Nothing,
                row(
                    "SwiftShader",
                    true,
                    "OpenGL ES 3.0 SwiftShader",
                    "Google SwiftShader",
                ),
            ),
        ];
        for (shows, mut r) in cases {
            let before = r.clone();
            check(&mut r, shows, &switch(NO_FLOAT));
            assert_eq!(r, before);
        }
    }

    #[test]
    fn another_implementation_ignoring_a_mesa_switch_is_unavailable_and_unjudged() {
        let mut r = row(
            "SwiftShader",
            true,
            "OpenGL ES 2.0 SwiftShader 4.0",
            "Google SwiftShader",
        );
        check(&mut r, Shows::NoFloatTextures, &switch(NO_FLOAT));
        assert_eq!(r["refused"], true);
        assert_eq!(r["methods"], json!([]));
        let error = r["error"].as_str().unwrap();
        assert!(
            error.contains("MESA_EXTENSION_OVERRIDE=-GL_OES_texture_float not applied"),
            "{error}"
        );
        assert!(error.contains("still lists float textures"), "{error}");
        let mut r = row(
            "SwiftShader",
            true,
            "OpenGL ES 3.0 SwiftShader 4.0",
            "Google SwiftShader",
        );
        check(
            &mut r,
            Shows::Renderer("softpipe"),
            &switch("GALLIUM_DRIVER=softpipe"),
        );
        assert!(r["error"]
            .as_str()
            .unwrap()
            .contains("renderer is Google SwiftShader"));
    }

    #[test]
    fn mesa_ignoring_its_own_switch_fails_the_row() {
        let mut r = row(
            "Mesa llvmpipe",
            true,
            "OpenGL ES 3.2 Mesa 22.3.6",
            "llvmpipe",
        );
        check(
            &mut r,
            Shows::GlVersion("OpenGL ES 2.0"),
            &switch("MESA_GLES_VERSION_OVERRIDE=2.0"),
        );
        assert_eq!(r["refused"], false);
        assert!(r["error"]
            .as_str()
            .unwrap()
            .contains("OpenGL ES 3.2 Mesa 22.3.6, not OpenGL ES 2.0"));
    }

    #[test]
    fn a_failed_cell_keeps_its_own_error() {
        let mut r = json!({"error": "no context", "methods": []});
        check(&mut r, Shows::NoFloatTextures, &switch(NO_FLOAT));
        assert_eq!(r["error"], "no context");
    }
}
