//! [`Renderer::warm_up`]: the shader programs, meshes and textures a scene's frames need,
//! built before the first frame (a loading screen's work) rather than during it.

use std::time::Instant;

use super::{FrameStats, Renderer};
use crate::gl::framebuffer::OffscreenTarget;
use crate::methods;
use crate::options::{CountKind, RenderOptions};
use crate::scene::Scene;
use crate::Error;

/// The size of the frames a warm-up draws: programs do not depend on it, and a small frame
/// costs the GPU next to nothing.
const WARM_UP_SIZE: (u32, u32) = (32, 18);

/// What [`Renderer::warm_up`] did.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct WarmUp {
    /// Shader programs compiled and linked: the variants the renderer had not built before.
    pub programs_built: usize,
    /// The methods a frame was drawn with: the renderer's, or for `auto` each it may pick on
    /// this context.
    pub methods: Vec<&'static str>,
    /// Wall time in milliseconds, the GPU's work included.
    pub ms: f64,
}

impl Renderer {
    /// Builds what drawing `scene` with `options` into the framebuffer bound now needs (every
    /// shader variant of its materials and lights, its meshes and textures), so that the first
    /// [`Renderer::render`] builds nothing: compiling a variant takes a driver milliseconds to
    /// tens of milliseconds, a visible hitch. A game calls it while it shows a loading screen,
    /// and again when the scene gains a kind of material or light (a first spot light, a first
    /// normal map), or when the options change what is drawn (tone map, MSAA, linear output).
    /// The ambient-only variants, which draw a frame with no light in view, are built too.
    ///
    /// It draws one small frame offscreen with the current method, or with each method `auto`
    /// may pick (forward, clustered, deferred), including the passes the camera does not need
    /// yet (deferred's full-screen lights). The method's own state (its grid, its
    /// thread choice, `auto`'s choice) is not touched: the frames are drawn by fresh instances,
    /// freed afterwards. Like a frame, it gives the application's GL state back as it was.
    /// [`FrameStats::programs_built`] says what a frame built after all.
    pub fn warm_up(&mut self, scene: &Scene, options: &RenderOptions) -> Result<WarmUp, Error> {
        self.hosted(|r| r.warm_up_hosted(scene, options))
    }

    fn warm_up_hosted(&mut self, scene: &Scene, options: &RenderOptions) -> Result<WarmUp, Error> {
        let start = Instant::now();
        let programs = self.programs.len();
        // What `render` would draw with into the framebuffer bound now: linear output into one
        // that encodes sRGB, and no MSAA of the renderer's own into one multisampled itself.
        let bound = self
            .dev
            .target_format(self.dev.host_framebuffer(), Default::default());
        let srgb = bound.srgb;
        let mut options = RenderOptions {
            linear: options.linear || srgb,
            gpu_timer: false,
            wait_for_gpu: true,
            origin: [0, 0],
            ..options.clone()
        };
        if bound.samples > 0 || options.count != CountKind::None {
            options.samples = 1;
        }
        options.measure.timed_frames = 0;
        let own_msaa = options.samples > 1;
        let names = if self.method.name() == methods::auto::DESC.name {
            methods::auto::methods_it_may_run(self.dev.caps(), own_msaa)
        } else {
            vec![self.method.name()]
        };
        let (width, height) = WARM_UP_SIZE;
        let mut target = OffscreenTarget::new(&self.dev, width, height)?;
        target.bind(&self.dev);
        // The game's multisampled target stays as it is (a frame would make it again).
        let kept_msaa = std::mem::take(&mut self.msaa);
        self.warming_up = true;
        let drawn = self.restoring(
            |r| r.warm_up_frames(scene, &names, &options),
            move |r| {
                r.warming_up = false;
                for mut m in std::mem::replace(&mut r.msaa, kept_msaa).take_all() {
                    m.destroy(&r.dev);
                }
                target.destroy(&r.dev);
            },
        );
        drawn?;
        let fills = self.dev.caps().clears_one_sample_of_srgb_msaa();
        if srgb && own_msaa && fills && self.dev.es() == crate::gl::EsVersion::Es3 {
            // The sRGB multisampled target's fill, which the frames' RGBA8 target did not need.
            crate::gl::multisample::build_fill_program(&self.dev, &mut self.programs)?;
        }
        self.dev.check("the warm-up")?;
        Ok(WarmUp {
            programs_built: self.programs.len() - programs,
            methods: names,
            ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }

    /// One frame of `scene` into the bound target with a fresh instance of each method of
    /// `names`, the renderer's own method kept aside meanwhile.
    fn warm_up_frames(
        &mut self,
        scene: &Scene,
        names: &[&'static str],
        options: &RenderOptions,
    ) -> Result<(), Error> {
        for name in names {
            self.warm_up_frame(scene, name, options)?;
        }
        // A frame with no light in view is drawn ambient-only, whatever the method.
        if !scene.lights.is_empty() {
            // Everything but the lights and their motion: a copy of those would cost a scene
            // of a million lights about 100 MB for one frame that draws none of them.
            let unlit = Scene {
                objects: scene.objects.clone(),
                materials: scene.materials.clone(),
                lights: Vec::new(),
                directional_lights: scene.directional_lights.clone(),
                ambient: scene.ambient,
                camera: scene.camera,
                animation: Vec::new(),
            };
            self.warm_up_frame(&unlit, methods::forward::DESC.name, options)?;
        }
        Ok(())
    }

    /// One frame of `scene` with a fresh instance of the method `name`.
    fn warm_up_frame(
        &mut self,
        scene: &Scene,
        name: &str,
        options: &RenderOptions,
    ) -> Result<(), Error> {
        let mut stats = FrameStats::default();
        let fresh = (methods::find(name)?.create)(&self.dev)?;
        let kept = std::mem::replace(&mut self.method, fresh);
        self.restoring(
            |r| r.render_hosted(scene, WARM_UP_SIZE, options, [0, 0], &mut stats, false),
            move |r| {
                let mut used = std::mem::replace(&mut r.method, kept);
                used.destroy(&r.dev);
            },
        )
    }
}
