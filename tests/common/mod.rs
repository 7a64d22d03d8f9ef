//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::PathBuf;

use manylight::gl::HeadlessContext;
use manylight::metrics::cpu_reference::{self, Encoding};
use manylight::scene::Scene;
use manylight::{EsVersion, RenderOptions, Renderer};

/// A headless context and a renderer on it (the context must outlive the renderer).
pub struct Gpu {
    pub renderer: Option<Renderer>,
    _ctx: HeadlessContext,
}

impl Gpu {
    pub fn new(es: EsVersion) -> Gpu {
        Gpu::restricted(es, &manylight::gl::Restrictions::default())
    }

    /// A renderer playing a weaker device (see `manylight::gl::Restrictions`).
    pub fn restricted(es: EsVersion, restrictions: &manylight::gl::Restrictions) -> Gpu {
        let ctx = HeadlessContext::new(es).unwrap_or_else(|e| {
            panic!("no headless {es} context ({e}); install libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri")
        });
        let renderer = Renderer::restricted(ctx.load_gl(), es, restrictions).expect("renderer");
        Gpu {
            renderer: Some(renderer),
            _ctx: ctx,
        }
    }

    pub fn r(&mut self) -> &mut Renderer {
        self.renderer.as_mut().unwrap()
    }

    pub fn render(
        &mut self,
        scene: &Scene,
        w: u32,
        h: u32,
        opts: &RenderOptions,
    ) -> image::RgbaImage {
        self.r()
            .render_offscreen(scene, w, h, opts)
            .expect("render")
            .0
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        if let Some(r) = self.renderer.take() {
            r.destroy();
        }
    }
}

/// The folder of third-party scenes named by `$MANYLIGHT_ASSETS` (nothing outside the
/// repository is assumed: CI sets the variable; `scripts/fetch-assets` makes such a folder).
/// Only called by tests marked `#[cfg_attr(not(manylight_assets), ignore = …)]`, which run
/// only when the variable was set at build time: a set variable naming no folder is a failure,
/// not a skip.
pub fn assets_dir() -> PathBuf {
    let dir = std::env::var_os("MANYLIGHT_ASSETS")
        .map(PathBuf::from)
        .expect("MANYLIGHT_ASSETS was set when the tests were built but is not set now");
    assert!(
        dir.is_dir(),
        "MANYLIGHT_ASSETS names {}, which is not a folder (scripts/fetch-assets makes one)",
        dir.display()
    );
    dir
}

/// A file of the real scenes, which must exist when `MANYLIGHT_ASSETS` is set.
pub fn asset(relative: &str) -> PathBuf {
    let path = assets_dir().join(relative);
    assert!(
        path.is_file(),
        "{} is missing from MANYLIGHT_ASSETS (scripts/fetch-assets makes the folder)",
        path.display()
    );
    path
}

/// The image against the light model evaluated on the CPU in f64 at every pixel the
/// reference can speak for (`manylight::metrics::cpu_reference`: an interval over the
/// rasterizer's sub-pixel snapping, triangle edges skipped): the largest error in 8-bit steps,
/// where it is, and how many pixels were compared.
pub fn max_oracle_error(
    img: &image::RgbaImage,
    scene: &Scene,
    encoding: Encoding,
) -> (f64, (u32, u32), usize) {
    let (w, h) = img.dimensions();
    let set = cpu_reference::reference_samples(scene, w, h, (w * h) as usize, encoding);
    let e = cpu_reference::compare(img, &set);
    (e.max_abs, e.worst, e.samples)
}

/// A test that cannot run in this environment (no Xvfb, no libOSMesa, a driver without Mesa's
/// overrides) says so on stderr and returns. With `MANYLIGHT_REQUIRE_ALL_TESTS` set (CI sets
/// it, where everything is installed) a skip is a failure instead, so nothing passes unrun.
pub fn skip(reason: &str) {
    if std::env::var_os("MANYLIGHT_REQUIRE_ALL_TESTS").is_some() {
        panic!("would skip ({reason}), but MANYLIGHT_REQUIRE_ALL_TESTS is set");
    }
    eprintln!("SKIPPED: {reason}");
}
