//! The library stays a renderer: the tools' dependencies never come back into its manifest.

/// The names under `[dependencies]` of the library's Cargo.toml.
fn dependencies() -> Vec<String> {
    let manifest = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml"))
        .expect("the library's Cargo.toml");
    let mut in_dependencies = false;
    let mut names = Vec::new();
    for line in manifest.lines().map(str::trim) {
        if let Some(name) = line
            .strip_prefix("[dependencies.")
            .and_then(|rest| rest.strip_suffix(']'))
        {
            // The table form a published manifest uses.
            names.push(name.trim_matches('"').to_string());
            in_dependencies = false;
        } else if line.starts_with('[') {
            in_dependencies = line == "[dependencies]";
        } else if in_dependencies && !line.is_empty() && !line.starts_with('#') {
            if let Some((name, _)) = line.split_once('=') {
                names.push(name.trim().to_string());
            }
        }
    }
    names
}

#[test]
fn the_library_depends_on_no_tooling_crate() {
    let deps = dependencies();
    assert!(deps.iter().any(|d| d == "glow"), "parsed {deps:?}");
    for tool in [
        "clap",
        "indicatif",
        "plotters",
        "env_logger",
        "font8x8",
        "criterion",
    ] {
        assert!(
            !deps.iter().any(|d| d == tool),
            "{tool} is a library dependency: {deps:?}"
        );
    }
}
