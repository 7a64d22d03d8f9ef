//! Build script: only decides whether the tests that need files from outside the repository
//! run: the real third-party scenes (`MANYLIGHT_ASSETS`, `cfg(manylight_assets)`) and the
//! other GLES implementations (`MANYLIGHT_GLES_DIR` from `scripts/fetch-gles`,
//! `cfg(manylight_gles)`).
//!
//! With the variable set at build time the cfg is on and those tests run; without it they are
//! compiled as `#[ignore]`d with the reason, so `cargo test` lists them as ignored instead of
//! passing them silently.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(manylight_assets)");
    // This script serves both packages (tools/ names it `../build.rs`); the path is taken
    // from the package's folder, where the script runs. A path that names no file would make
    // every cargo command run it again and rebuild the package.
    let script = if std::path::Path::new("build.rs").exists() {
        "build.rs"
    } else {
        "../build.rs"
    };
    println!("cargo::rerun-if-changed={script}");
    println!("cargo::rerun-if-env-changed=MANYLIGHT_ASSETS");
    if std::env::var_os("MANYLIGHT_ASSETS").is_some_and(|v| !v.is_empty()) {
        println!("cargo::rustc-cfg=manylight_assets");
    }
    println!("cargo::rustc-check-cfg=cfg(manylight_gles)");
    println!("cargo::rerun-if-env-changed=MANYLIGHT_GLES_DIR");
    println!("cargo::rerun-if-env-changed=MANYLIGHT_REQUIRE_ALL_TESTS");
    // Where every test must run (CI), the implementation tests run and fail with the reason
    // if the folder is missing, instead of being compiled ignored.
    let set = |name| std::env::var_os(name).is_some_and(|v| !v.is_empty());
    if set("MANYLIGHT_GLES_DIR") || set("MANYLIGHT_REQUIRE_ALL_TESTS") {
        println!("cargo::rustc-cfg=manylight_gles");
    }
}
