//! Build script: only decides whether the tests that need the real third-party scenes run.
//!
//! With `MANYLIGHT_ASSETS` set at build time, `cfg(manylight_assets)` is on and those tests
//! run; without it they are compiled as `#[ignore]`d with the reason, so `cargo test` lists
//! them as ignored instead of passing them silently.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(manylight_assets)");
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=MANYLIGHT_ASSETS");
    if std::env::var_os("MANYLIGHT_ASSETS").is_some_and(|v| !v.is_empty()) {
        println!("cargo::rustc-cfg=manylight_assets");
    }
}
