//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod child;
pub mod cli;
pub mod files;
pub mod game_target;
pub mod gltf;
pub mod gltf_models;
pub mod light_lattice;
pub mod warnings;

use std::path::PathBuf;

use manylight::gl::program::ProgramCache;
use manylight::gl::{HeadlessContext, Restrictions};
use manylight::metrics::cpu_reference::{self, Encoding};
use std::sync::{Arc, Mutex, OnceLock};

use glam::{DMat4, DVec3, Vec3};
use manylight::scene::meshbuild::MeshBuilder;
use manylight::scene::{Camera, Cone, Light, Material, Object, Scene};
use manylight::{EsVersion, RenderOptions, Renderer};

/// A headless context and a new renderer on it. The context, and the programs the renderers
/// on it built, come from an earlier test of the same program where one has finished (see
/// [`POOL`]); [`Gpu::fresh`] builds every program anew.
pub struct Gpu {
    pub renderer: Option<Renderer>,
    ctx: Option<HeadlessContext>,
    kind: ContextKind,
}

/// What a context's renderers are made for: their ES level and restrictions.
type ContextKind = (EsVersion, Restrictions);

/// Contexts whose tests have finished, each with the programs built on it. SwiftShader compiles
/// a program's code again in every new context (about a second a shader variant): with a new
/// context in every test, `stability` took 413 s there instead of 108 s (docs/testing.md).
static POOL: Mutex<Vec<(ContextKind, HeadlessContext, ProgramCache)>> = Mutex::new(Vec::new());

impl Gpu {
    pub fn new(es: EsVersion) -> Gpu {
        Gpu::restricted(es, &Restrictions::default())
    }

    /// A renderer playing an ES 2.0 device whose fragment stage has no highp (Mali-400 class).
    pub fn without_fragment_highp() -> Gpu {
        let restrictions = Restrictions {
            no_fragment_highp: true,
            ..Default::default()
        };
        Gpu::restricted(EsVersion::Es2, &restrictions)
    }

    /// A renderer playing a weaker device (see `manylight::gl::Restrictions`).
    pub fn restricted(es: EsVersion, restrictions: &Restrictions) -> Gpu {
        // A test that reads its warnings back finds every one its renderers logged.
        warnings::install();
        let restrictions = &as_this_child_plays(es, restrictions);
        let kind = (es, *restrictions);
        let pooled = {
            let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
            // The context with the most programs: another one of the kind only serves a test
            // holding two renderers at once, and each context builds its programs itself.
            let found = (pool.iter().enumerate())
                .filter(|(_, (k, _, _))| *k == kind)
                .max_by_key(|(_, (_, _, programs))| programs.len())
                .map(|(i, _)| i);
            found.map(|i| pool.swap_remove(i))
        };
        let Some((_, ctx, programs)) = pooled else {
            return Gpu::fresh_restricted(es, restrictions);
        };
        ctx.make_current().expect("a pooled context made current");
        let mut renderer =
            Renderer::restricted(ctx.load_gl().unwrap(), es, restrictions).expect("renderer");
        renderer.adopt_programs(programs);
        Gpu {
            renderer: Some(renderer),
            ctx: Some(ctx),
            kind,
        }
    }

    /// A new context and renderer, which builds every program it draws with: for tests of
    /// what a renderer builds or holds.
    pub fn fresh(es: EsVersion) -> Gpu {
        Gpu::fresh_restricted(es, &as_this_child_plays(es, &Restrictions::default()))
    }

    /// [`Gpu::fresh`] with `restrictions` as given (the entry points add a child's own).
    fn fresh_restricted(es: EsVersion, restrictions: &Restrictions) -> Gpu {
        warnings::install();
        let ctx = HeadlessContext::new(es).unwrap_or_else(|e| {
            panic!("no headless {es} context ({e}); install libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri")
        });
        let renderer =
            Renderer::restricted(ctx.load_gl().unwrap(), es, restrictions).expect("renderer");
        Gpu {
            renderer: Some(renderer),
            ctx: Some(ctx),
            kind: (es, *restrictions),
        }
    }

    /// The renderer, its context made current first: a test may hold several contexts (the
    /// renderer refuses to draw while another is current).
    pub fn r(&mut self) -> &mut Renderer {
        if let Some(ctx) = &self.ctx {
            ctx.make_current().expect("the test's context made current");
        }
        self.renderer.as_mut().unwrap()
    }

    /// The context's GL functions, for a test playing the game's side; the context made
    /// current first.
    pub fn gl(&mut self) -> manylight::glow::Context {
        let ctx = self.ctx.as_ref().expect("a context");
        ctx.make_current().expect("the test's context made current");
        ctx.load_gl().unwrap()
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

    /// A frame rendered with the method `method` (which must run here), and its stats.
    pub fn render_with(
        &mut self,
        method: &str,
        scene: &Scene,
        (w, h): (u32, u32),
        opts: &RenderOptions,
    ) -> (image::RgbaImage, manylight::FrameStats) {
        self.r().set_method_named(method).unwrap();
        self.r()
            .render_offscreen(scene, w, h, opts)
            .unwrap_or_else(|e| panic!("{method}: {e}"))
    }
}

/// `restrictions`, plus a device without float textures on ES 2.0 in a child that plays one
/// ([`child::rerun_with_rgba8_lights`]).
fn as_this_child_plays(es: EsVersion, restrictions: &Restrictions) -> Restrictions {
    let mut restrictions = *restrictions;
    if es == EsVersion::Es2 && child::plays_rgba8_lights() {
        restrictions.no_float_textures = true;
    }
    restrictions
}

impl Drop for Gpu {
    /// Frees the renderer and pools the context with its programs, released so that the next
    /// test's thread can make it current; after a failure (a panic) nothing is pooled, so that
    /// one test's broken state cannot fail the next, nor where contexts cannot move between
    /// threads (ANGLE).
    fn drop(&mut self) {
        let (Some(renderer), Some(ctx)) = (self.renderer.take(), self.ctx.take()) else {
            return;
        };
        // The renderer frees its objects only in its own context.
        let _ = ctx.make_current();
        if std::thread::panicking() || !ctx.can_move_between_threads() {
            renderer.destroy();
            return;
        }
        let programs = renderer.destroy_keeping_programs();
        ctx.release_current().expect("the context released");
        let mut pool = POOL.lock().unwrap_or_else(|e| e.into_inner());
        pool.push((self.kind, ctx, programs));
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
/// sub-pixel snapping of the rasterizer `caps` describes, triangle edges skipped): the largest
/// error in 8-bit steps, where it is, and how many pixels were compared.
pub fn max_oracle_error(
    img: &image::RgbaImage,
    scene: &Scene,
    encoding: Encoding,
    caps: &manylight::gl::Caps,
) -> (f64, (u32, u32), usize) {
    let (w, h) = img.dimensions();
    let subpixel = cpu_reference::snapping_reach(caps.subpixel_bits);
    let set = cpu_reference::reference_samples(scene, w, h, (w * h) as usize, encoding, subpixel);
    let e = cpu_reference::compare(img, &set);
    (e.max_abs, e.worst, e.samples)
}

/// The methods a context of `es` runs: deferred needs ES 3.0.
pub fn methods_on(es: EsVersion) -> &'static [&'static str] {
    match es {
        EsVersion::Es2 => &["forward", "tiled", "clustered"],
        EsVersion::Es3 => &["forward", "tiled", "clustered", "deferred"],
    }
}

/// Calls `check(es, method, gpu)` with `gpu`'s renderer set to each method of ES 2.0 and then
/// of ES 3.0 ([`methods_on`]), one context per version.
pub fn each_method(mut check: impl FnMut(EsVersion, &str, &mut Gpu)) {
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let mut gpu = Gpu::new(es);
        for method in methods_on(es) {
            gpu.r().set_method_named(method).unwrap();
            check(es, method, &mut gpu);
        }
    }
}

/// Calls `check(es, method, gpu, picture)` with `scene` drawn by each method ([`each_method`])
/// at `w` × `h` in linear output, lit by an ambient light of one alone: every surface shows its
/// colour, and every texel its value, as they are.
pub fn each_method_showing_colours(
    scene: &Scene,
    w: u32,
    h: u32,
    mut check: impl FnMut(EsVersion, &str, &mut Gpu, &image::RgbaImage),
) {
    let mut scene = scene.clone();
    scene.ambient = Vec3::ONE;
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    each_method(|es, method, gpu| {
        let picture = gpu.render(&scene, w, h, &opts);
        check(es, method, gpu, &picture);
    });
}

/// The mean of a picture's red, green and blue values, in 8-bit steps.
pub fn mean(img: &image::RgbaImage) -> f64 {
    let sum: u64 = img
        .pixels()
        .map(|p| p[0] as u64 + p[1] as u64 + p[2] as u64)
        .sum();
    sum as f64 / (3 * img.width() * img.height()) as f64
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

/// For a test about a Mesa feature (its `MESA_*` overrides, its second driver, OSMesa against
/// Mesa's EGL): true, after saying so on stderr, when this run renders with another GLES
/// implementation (`MANYLIGHT_GLES_LIB`; docs/drivers.md) or the system's GL is not Mesa
/// (NVIDIA's), where the feature does not exist. Unlike [`skip`] this is not something missing
/// from the environment: the test runs in the suite's run on the system's Mesa, so
/// `MANYLIGHT_REQUIRE_ALL_TESTS` does not turn it into a failure.
pub fn other_implementation_than_mesa(what: &str) -> bool {
    if not_applicable_on_another_implementation(|dir| {
        format!("{what} is a Mesa feature; this run renders with {dir}")
    }) {
        return true;
    }
    let system = system_implementation();
    if system.starts_with("Mesa") {
        return false;
    }
    eprintln!("NOT APPLICABLE: {what} is a Mesa feature; the system's GL is {system}");
    true
}

/// Whether this run renders with Mesa: the system's GL, no `MANYLIGHT_GLES_LIB`.
pub fn renders_with_mesa() -> bool {
    manylight::gl::gles_lib::chosen_folder().is_none()
        && system_implementation().starts_with("Mesa")
}

/// The system's GL implementation as the renderer names it (`Caps::implementation`), asked
/// once per test program.
fn system_implementation() -> &'static str {
    static NAME: OnceLock<String> = OnceLock::new();
    NAME.get_or_init(|| Gpu::new(EsVersion::Es2).r().caps().implementation())
}

/// For a test whose child processes each pick their own GLES implementation (the tests of
/// every implementation against forward): true, after saying so on stderr, when this run
/// renders with another implementation (`MANYLIGHT_GLES_LIB`). Its children do the same work
/// whatever this run's implementation is, so it runs once, in the suite's run on the system's
/// GL, and `MANYLIGHT_REQUIRE_ALL_TESTS` does not turn this into a failure.
pub fn picks_its_own_implementations(what: &str) -> bool {
    not_applicable_on_another_implementation(|dir| {
        format!("{what} picks its implementations itself; it runs without MANYLIGHT_GLES_LIB, not again with {dir}")
    })
}

/// For a test that never touches GL (offline shader validation): true, after saying so on
/// stderr, when this run renders with another GLES implementation (`MANYLIGHT_GLES_LIB`).
/// Its result is the same on every implementation, so it runs once, in the suite's run on the
/// system's GL, and `MANYLIGHT_REQUIRE_ALL_TESTS` does not turn this into a failure.
pub fn independent_of_the_implementation(what: &str) -> bool {
    not_applicable_on_another_implementation(|dir| {
        format!("{what} does not use GL; it runs without MANYLIGHT_GLES_LIB, not again with {dir}")
    })
}

/// For a test of what the command line does with its arguments and output files, whose renders
/// only lead up to that (a tiny frame, then a write that fails or a file checked): true, after
/// saying so on stderr, when this run renders with another GLES implementation
/// (`MANYLIGHT_GLES_LIB`). Its verdict is the same on every implementation, so it runs once, in
/// the suite's run on the system's GL, and `MANYLIGHT_REQUIRE_ALL_TESTS` does not turn this
/// into a failure. Not for standard output (a driver may print there) or what a render shows.
pub fn checks_the_command_line_alone(what: &str) -> bool {
    not_applicable_on_another_implementation(|dir| {
        format!("{what} checks the command line's files and arguments, whatever renders; it runs without MANYLIGHT_GLES_LIB, not again with {dir}")
    })
}

/// True, after printing `NOT APPLICABLE:` and `why` (given the implementation's folder) on
/// stderr, when this run renders with another GLES implementation (`MANYLIGHT_GLES_LIB`).
fn not_applicable_on_another_implementation(why: impl FnOnce(&str) -> String) -> bool {
    match manylight::gl::gles_lib::chosen_folder() {
        Some(dir) => {
            eprintln!("NOT APPLICABLE: {}", why(&dir.display().to_string()));
            true
        }
        None => false,
    }
}

/// A scene of one grey floor, 12 m square at y = 0 around the origin: no lights, the default
/// camera.
pub fn floor_12m() -> Scene {
    let mut s = Scene::empty();
    let grey = s.add_material(Material::flat("floor", Vec3::splat(0.7)));
    let mut floor = MeshBuilder::new();
    let c = |x, z| Vec3::new(x, 0.0, z);
    floor.quad(c(-6.0, 6.0), c(6.0, 6.0), c(6.0, -6.0), c(-6.0, -6.0));
    s.add_object(floor.build().unwrap(), grey, DMat4::IDENTITY);
    s
}

/// The built-in pillars under `count` (at least 8) small warm lights that stand still, the
/// eighth a spot pointing down.
pub fn pillars_lit(count: usize) -> Scene {
    let mut s = manylight::scene::builtin::build("pillars", None).unwrap();
    s.lights = (0..count)
        .map(|i| {
            let f = i as f64;
            let at = DVec3::new((f * 0.7).sin() * 10.0, 0.6, (f * 0.13).cos() * 12.0);
            Light::point(at, 3.5, Vec3::new(1.0, 0.8, 0.5), 1.5)
        })
        .collect();
    let cone = Cone {
        direction: DVec3::NEG_Y,
        inner_deg: 25.0,
        outer_deg: 40.0,
    };
    s.lights[7] = Light::spot(DVec3::new(1.0, 3.0, 2.0), 6.0, Vec3::ONE, 2.0, cone);
    s
}

/// A white square turned 30° about the view axis on black, lit by ambient light alone: each
/// pixel's value is its coverage.
pub fn turned_square() -> Scene {
    let mut s = Scene::empty();
    let white = s.add_material(Material::flat("white", Vec3::ONE));
    let mut square = MeshBuilder::new();
    square.quad(
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    );
    s.objects.push(Object {
        mesh: Arc::new(square.build().unwrap()),
        material: white,
        transform: DMat4::from_rotation_z(30f64.to_radians()),
    });
    s.ambient = Vec3::ONE;
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, 60.0, 0.1, 10.0);
    s
}

/// A square of metallic-roughness `base` colour (rough, dielectric) facing the camera, its
/// occlusion map of 1 × N texels reading `ao` (0–255) across it at full strength, under an
/// `ambient`, with eight lights of rising intensity over it: a bright ambient that the map
/// darkens to nothing in places.
pub fn occluded_quad(base: f32, ao: &[u8], ambient: f32) -> Scene {
    use manylight::scene::surface_maps::MapTexture;
    use manylight::scene::Texture;
    let mut s = turned_square();
    let texels = image::RgbaImage::from_fn(ao.len() as u32, 1, |x, _| {
        image::Rgba([ao[x as usize], 0, 0, 255])
    });
    let mut m = Material::metallic_roughness("occluded", Vec3::splat(base), 0.0, 1.0);
    m.maps.occlusion = Some(MapTexture {
        texture: Arc::new(Texture::new("ao", texels)),
        transform: Default::default(),
    });
    s.materials[0] = m;
    s.objects[0].transform = DMat4::IDENTITY;
    s.ambient = Vec3::splat(ambient);
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 1.8), DVec3::ZERO, 60.0, 0.1, 10.0);
    s.lights = (0..8)
        .map(|i| {
            let f = i as f64;
            let at = DVec3::new(0.25 * f - 0.9, 0.4 * (f * 1.3).sin(), 0.3);
            Light::point(at, 1.5, Vec3::ONE, 0.02 * (1.0 + f * f) as f32)
        })
        .collect();
    s
}

/// Asserts that `img` (of [`turned_square`], linear, 4 samples) resolved every pixel to a
/// coverage of 4 samples, k/4 of white, with the square's edges partly covered and its inside
/// and outside untouched.
pub fn assert_coverage_of_4_samples(img: &image::RgbaImage) {
    let mut partial = 0;
    for p in img.pixels() {
        // The resolve averages 4 samples: k/4 of white, k = 0..=4.
        let k = (p[0] as f64 / 255.0 * 4.0).round();
        assert!(
            (p[0] as f64 - k * 255.0 / 4.0).abs() <= 1.0,
            "{} is not a coverage of 4 samples",
            p[0]
        );
        partial += usize::from(k > 0.0 && k < 4.0);
    }
    // The square's outline is about 166 pixels long at 96×96 (sides of 41.6 px); with 4
    // samples 100 of the pixels it crosses come out partly covered on llvmpipe.
    assert!(
        partial > 60,
        "only {partial} edge pixels are partly covered"
    );
    // Away from the edges nothing changes.
    let (w, h) = img.dimensions();
    assert_eq!(img.get_pixel(w / 2, h / 2)[0], 255);
    assert_eq!(img.get_pixel(2, 2)[0], 0);
}

/// Options asking for `samples` samples per pixel (MSAA above 1), the rest default.
pub fn msaa(samples: u32) -> RenderOptions {
    RenderOptions {
        samples,
        ..RenderOptions::default()
    }
}

/// Renders the courtyard (64 lights) at 128×72 with 4 samples through every method that
/// supports MSAA and asserts each within 2/255 of forward with 4 samples, reporting 4 samples
/// and `bytes_per_pixel` bytes of MSAA target per pixel; returns forward's picture.
pub fn assert_methods_match_forward_with_4_samples(
    gpu: &mut Gpu,
    bytes_per_pixel: usize,
) -> image::RgbaImage {
    let scene = manylight::scene::builtin::build("courtyard", Some((64, 2))).unwrap();
    gpu.r().set_method_named("forward").unwrap();
    let reference = gpu.render(&scene, 128, 72, &msaa(4));
    for method in ["tiled", "clustered", "auto"] {
        gpu.r().set_method_named(method).unwrap();
        let (img, stats) = gpu.r().render_offscreen(&scene, 128, 72, &msaa(4)).unwrap();
        assert_eq!(stats.samples, 4);
        assert_eq!(stats.memory.msaa_bytes, 128 * 72 * bytes_per_pixel);
        let d = manylight::metrics::diff(&reference, &img);
        assert!(d.max_abs <= 2, "{method}: {} / 255 from forward", d.max_abs);
    }
    reference
}

/// Which of `texels` (pure colours: each channel 0 or not) a pixel shows: the one whose set
/// of lit channels is the pixel's channels above half its brightest; `None` for a dark pixel
/// or a blend no texel matches.
pub fn texel_shown(p: &image::Rgba<u8>, texels: &[[u8; 3]]) -> Option<usize> {
    let max = p[0].max(p[1]).max(p[2]);
    if max < 40 {
        return None;
    }
    let bright = [0, 1, 2].map(|c| p[c] as u32 * 2 > max as u32);
    texels.iter().position(|t| t.map(|c| c > 0) == bright)
}
