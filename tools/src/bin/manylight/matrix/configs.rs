//! The configurations of `manylight matrix`: each a name, the ES version asked for and the
//! driver restriction its child runs under.

use super::restriction::Shows;

/// The driver switches the configurations set: cleared in every cell first, so a row is
/// the restriction its label names and no other the caller's environment carried.
pub(super) const DRIVER_ENV: [&str; 3] = [
    "MESA_GLES_VERSION_OVERRIDE",
    "MESA_EXTENSION_OVERRIDE",
    "GALLIUM_DRIVER",
];

/// One configuration: a name, the ES version asked for, and the environment that restricts
/// the driver.
pub(super) struct Config {
    pub(super) name: &'static str,
    pub(super) slug: &'static str,
    pub(super) es: &'static str,
    pub(super) env: &'static [(&'static str, &'static str)],
    /// Extra arguments of the child (restrictions the renderer plays itself).
    pub(super) args: &'static [&'static str],
    /// Image size instead of the matrix's (a slow driver renders a smaller image).
    pub(super) size: Option<&'static str>,
    /// Which row groups have it.
    pub(super) groups: Groups,
    /// What its context shows when `env` took effect.
    pub(super) shows: Shows,
}

/// The row groups a configuration belongs to.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Groups {
    /// Every implementation's.
    All,
    /// The system's alone: a Mesa switch (environment override, second driver).
    System,
    /// The other implementations': a restriction the renderer plays where no Mesa switch exists.
    Others,
}

pub(super) const CONFIGS: &[Config] = &[
    Config {
        name: "ES 2.0",
        slug: "es2",
        es: "2",
        env: &[],
        args: &[],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        name: "ES 2.0 without fragment highp (played)",
        slug: "es2-mediump",
        es: "2",
        env: &[],
        args: &["--no-fragment-highp"],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        // A Mali-400's pair: its lights as 16-bit RGBA8 records decoded in fp16.
        name: "ES 2.0 without fragment highp or float textures (played)",
        slug: "es2-mediump-rgba8",
        es: "2",
        env: &[],
        args: &["--no-fragment-highp", "--no-float-textures"],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        name: "ES 2.0 with RGBA8 light data (played)",
        slug: "es2-rgba8",
        es: "2",
        env: &[],
        args: &["--no-float-textures"],
        groups: Groups::Others,
        size: None,
        shows: Shows::Nothing,
    },
    Config {
        name: "ES 2.0 without float textures",
        slug: "es2-nofloat",
        es: "2",
        env: &[(
            "MESA_EXTENSION_OVERRIDE",
            "-GL_OES_texture_float -GL_OES_texture_half_float",
        )],
        args: &[],
        groups: Groups::System,
        size: None,
        shows: Shows::NoFloatTextures,
    },
    Config {
        name: "ES 2.0 driver (capped)",
        slug: "es2-capped",
        es: "2",
        env: &[("MESA_GLES_VERSION_OVERRIDE", "2.0")],
        args: &[],
        groups: Groups::System,
        size: None,
        shows: Shows::GlVersion("OpenGL ES 2.0"),
    },
    Config {
        name: "ES 3.0 driver (capped)",
        slug: "es3-capped",
        es: "3",
        env: &[("MESA_GLES_VERSION_OVERRIDE", "3.0")],
        args: &[],
        groups: Groups::System,
        size: None,
        shows: Shows::GlVersion("OpenGL ES 3.0"),
    },
    Config {
        name: "ES 3.x as the driver gives it",
        slug: "es3",
        es: "3",
        env: &[],
        args: &[],
        groups: Groups::All,
        size: None,
        shows: Shows::Nothing,
    },
    // A second Mesa rasterizer (mediump at fp32, no LLVM): slow, so a small image. Where it
    // and llvmpipe differ, it is on triangle edges only (tests/second_driver.rs).
    Config {
        name: "ES 3.x on softpipe (second Mesa driver)",
        slug: "es3-softpipe",
        es: "3",
        env: &[("GALLIUM_DRIVER", "softpipe")],
        args: &[],
        groups: Groups::System,
        size: Some("96x54"),
        shows: Shows::Renderer("softpipe"),
    },
];
