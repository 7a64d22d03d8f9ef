//! The renderer: owns the GL device, the program cache, the uploaded scene and the current
//! shading method; renders a [`Scene`] and reports [`FrameStats`].

use std::time::Instant;

use glam::DMat4;
use serde::Serialize;

use crate::cluster::assign::AssignStats;
use crate::cluster::pack::GpuLight;
use crate::gl::framebuffer::{ColorFormat, OffscreenTarget};
use crate::gl::program::ProgramCache;
use crate::gl::{Caps, Device, EsVersion};
pub use crate::gpu_scene::GpuScene;
use crate::methods::{self, FrameContext, ShaderFeatures, ShadingMethod, Support};
pub use crate::metrics::counts::LightCounts;
use crate::metrics::spread::Spread;
pub use crate::options::{CountKind, RenderOptions, ToneMap};
use crate::scene::features::SceneFeatures;
use crate::scene::{Aabb, Projection, Scene};
use crate::Error;

/// What one frame did.
#[derive(Clone, Debug, Serialize)]
pub struct FrameStats {
    /// Shading method.
    pub method: String,
    /// Feature level (`2.0` / `3.0`).
    pub es: EsVersion,
    /// `GL_VERSION` of the context.
    pub gl_version: String,
    /// `GL_RENDERER`.
    pub renderer: String,
    /// Viewport width.
    pub width: u32,
    /// Viewport height.
    pub height: u32,
    /// Lights in the scene.
    pub lights: usize,
    /// Lights uploaded (radius and radiance > 0).
    pub active_lights: usize,
    /// Frame time in milliseconds: CPU work plus `glFinish` (median of the timed frames).
    pub frame_ms: f64,
    /// GPU time of the frame's GL work from a `GL_EXT_disjoint_timer_query` elapsed-time query
    /// (median of the timed frames); `None` without the extension, when the GPU reported a
    /// disjoint event, or when the frame does not wait for the GPU.
    pub gpu_ms: Option<f64>,
    /// Bytes uploaded for the frame.
    pub upload_bytes: usize,
    /// CPU light-assignment time in milliseconds (0 for forward).
    pub assign_ms: f64,
    /// Grid cells (0 for forward).
    pub clusters: u32,
    /// Cells holding at least one light.
    pub nonempty_clusters: u32,
    /// Mean lights per non-empty cell.
    pub avg_lights_per_nonempty: f64,
    /// Most lights any cell touched (before the per-cell cap).
    pub max_lights_per_cluster: u32,
    /// Light references dropped by the overflow policy (see `cluster::assign`), or lights
    /// forward left out beyond its loop cap (see `methods::forward_cap`).
    pub overflowed_lights: u64,
    /// Lights that reached the screen (touched at least one cell); all active lights for forward.
    pub visible_lights: usize,
    /// `float32` or `rgba8`.
    pub light_encoding: crate::cluster::pack::LightEncoding,
    /// The method's support status on this context (fallbacks say what degrades).
    pub support: Support,
    /// Triangles drawn.
    pub triangles: usize,
    /// GPU memory held by the method.
    pub method_gpu_bytes: usize,
    /// G-buffer memory (deferred only; 0 otherwise).
    pub gbuffer_bytes: usize,
    /// The method `auto` picked for this frame (`None` for the other methods).
    pub auto_choice: Option<String>,
    /// Why `auto` picked it.
    pub auto_reason: Option<String>,
    /// `LP_NUM_THREADS` when set (llvmpipe's thread count changes every timing).
    pub lp_num_threads: Option<String>,
    /// What the scene uses (and so what the shader variants were built with).
    pub scene_features: SceneFeatures,
    /// Cell footprint in pixels of the grid the frame used (tiled, clustered).
    pub grid_footprint_px: Option<f64>,
    /// Cells of that grid (0 without one).
    pub grid_cells: u32,
    /// Why the grid is what it is: the automatic choice's prediction and costs, or the fixed
    /// setting.
    pub grid_reason: Option<String>,
    /// Frame time over the timed frames of
    /// [`Renderer::render_offscreen`] (`timed_frames` > 0): p50, p95, p99, max.
    pub frame_ms_spread: Option<Spread>,
    /// CPU assignment time over the same frames.
    pub assign_ms_spread: Option<Spread>,
    /// Samples per pixel of the offscreen target (1: no MSAA).
    pub samples: u32,
    /// GPU memory of the multisampled target (0 without MSAA).
    pub msaa_bytes: usize,
    /// Bytes uploaded per frame over the timed frames of an animated sequence (lights that
    /// move change what is uploaded); `None` for a single frame.
    pub upload_bytes_spread: Option<Spread>,
}

impl Default for FrameStats {
    /// Empty figures: what [`Renderer::render_reusing`] fills in (a game keeps one and passes
    /// it every frame).
    fn default() -> Self {
        FrameStats {
            method: String::new(),
            es: EsVersion::Es3,
            gl_version: String::new(),
            renderer: String::new(),
            width: 0,
            height: 0,
            lights: 0,
            active_lights: 0,
            frame_ms: 0.0,
            gpu_ms: None,
            upload_bytes: 0,
            assign_ms: 0.0,
            clusters: 0,
            nonempty_clusters: 0,
            avg_lights_per_nonempty: 0.0,
            max_lights_per_cluster: 0,
            overflowed_lights: 0,
            visible_lights: 0,
            light_encoding: crate::cluster::pack::LightEncoding::Float32,
            support: Support::Supported,
            triangles: 0,
            method_gpu_bytes: 0,
            gbuffer_bytes: 0,
            auto_choice: None,
            auto_reason: None,
            lp_num_threads: None,
            scene_features: SceneFeatures::default(),
            grid_footprint_px: None,
            grid_cells: 0,
            grid_reason: None,
            frame_ms_spread: None,
            assign_ms_spread: None,
            samples: 1,
            msaa_bytes: 0,
            upload_bytes_spread: None,
        }
    }
}

/// Copies `src` into `dst`, keeping `dst`'s buffer: no allocation unless `src` is longer than
/// any text `dst` held before (and then room for half as much again, so a reason a few digits
/// longer next frame fits).
fn copy_str(dst: &mut String, src: &str) {
    if dst.as_str() != src {
        dst.clear();
        if dst.capacity() < src.len() {
            dst.reserve(src.len() + src.len() / 2);
        }
        dst.push_str(src);
    }
}

/// [`copy_str`] for optional texts (`None` frees the buffer).
fn copy_opt_str(dst: &mut Option<String>, src: Option<&str>) {
    match (dst.as_mut(), src) {
        (Some(d), Some(s)) => copy_str(d, s),
        (None, Some(s)) => {
            let mut d = String::new();
            copy_str(&mut d, s);
            *dst = Some(d);
        }
        (_, None) => *dst = None,
    }
}

/// [`copy_str`] for a support status.
fn copy_support(dst: &mut Support, src: &Support) {
    match (&mut *dst, src) {
        (Support::Supported, Support::Supported) => {}
        (Support::Fallback(d), Support::Fallback(s))
        | (Support::Unsupported(d), Support::Unsupported(s)) => copy_str(d, s),
        _ => *dst = src.clone(),
    }
}

impl FrameStats {
    /// The last of `frames` with frame, assignment and GPU time replaced by their medians over
    /// all of them and the frame and assignment spreads filled in (nearest rank, so median and
    /// spread agree; GPU time only where every frame has it). `None` for no frames.
    pub fn summarize(mut frames: Vec<FrameStats>) -> Option<FrameStats> {
        let frame_spread = Spread::of(frames.iter().map(|s| s.frame_ms));
        let assign_spread = Spread::of(frames.iter().map(|s| s.assign_ms));
        let gpu_ms = frames
            .iter()
            .map(|s| s.gpu_ms)
            .collect::<Option<Vec<f64>>>()
            .and_then(Spread::of)
            .map(|s| s.p50);
        let mut last = frames.pop()?;
        last.frame_ms = frame_spread.map_or(last.frame_ms, |s| s.p50);
        last.assign_ms = assign_spread.map_or(last.assign_ms, |s| s.p50);
        last.gpu_ms = gpu_ms;
        last.frame_ms_spread = frame_spread;
        last.assign_ms_spread = assign_spread;
        Some(last)
    }
}

/// Renders scenes with one shading method at a time.
pub struct Renderer {
    dev: Device,
    programs: ProgramCache,
    gpu_scene: GpuScene,
    method: Box<dyn ShadingMethod>,
    support: Support,
    target: Option<OffscreenTarget>,
    /// The multisampled target `render_offscreen` draws into with `RenderOptions::samples`.
    msaa: Option<crate::gl::multisample::MultisampleTarget>,
    /// The GPU timer: `None` until first needed, then `Some(None)` where the context has no
    /// timer queries.
    timer: Option<Option<crate::gl::timer::GpuTimer>>,
    /// What the default method's support would warn about: said at the first frame, unless
    /// the caller picks a method first (whose own support is then what is said).
    pending_warning: Option<String>,
    /// GL objects already freed (by `destroy`; dropping then does nothing more).
    freed: bool,
    /// The frame's active lights in view space (kept: a frame fills it without allocating).
    lights: Vec<GpuLight>,
    /// The frame's objects in draw order (kept likewise).
    draw_order: methods::geometry::DrawOrder,
    /// `LP_NUM_THREADS` when the renderer was made (llvmpipe reads it when the context is
    /// made; reading it every frame would allocate).
    lp_num_threads: Option<String>,
}

impl Renderer {
    /// Creates a renderer on a current GL context, restricted to feature level `es`. The
    /// context must stay current (and alive) for the renderer's whole life.
    pub fn new(gl: glow::Context, es: EsVersion) -> Result<Renderer, Error> {
        Renderer::restricted(gl, es, &crate::gl::Restrictions::default())
    }

    /// [`Renderer::new`] playing a weaker device than the driver (see
    /// [`crate::gl::Restrictions`]): for example one without fragment highp, where only
    /// methods that need no highp run (the default method falls back to forward).
    pub fn restricted(
        gl: glow::Context,
        es: EsVersion,
        restrictions: &crate::gl::Restrictions,
    ) -> Result<Renderer, Error> {
        let dev = Device::restricted(gl, es, restrictions)?;
        let mut desc = methods::find(methods::DEFAULT_METHOD)?;
        let mut support = (desc.supported)(dev.caps());
        let mut pending_warning = None;
        if let Support::Unsupported(reason) = &support {
            pending_warning = Some(format!(
                "the default method `{}` is unsupported here ({reason}); rendering with `forward`",
                desc.name
            ));
            desc = methods::find("forward")?;
            support = (desc.supported)(dev.caps());
        }
        if let Support::Fallback(reason) = &support {
            let note = format!("method `{}` runs with a fallback: {reason}", desc.name);
            pending_warning = Some(match pending_warning {
                Some(first) => format!("{first}; {note}"),
                None => note,
            });
        }
        let method = (desc.create)(&dev)?;
        Ok(Renderer {
            dev,
            programs: ProgramCache::new(),
            gpu_scene: GpuScene::default(),
            method,
            support,
            target: None,
            msaa: None,
            timer: None,
            pending_warning,
            freed: false,
            lights: Vec::new(),
            draw_order: methods::geometry::DrawOrder::default(),
            lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
        })
    }

    /// The probed capabilities.
    pub fn caps(&self) -> &Caps {
        self.dev.caps()
    }

    /// Whether the fragment stage evaluates `mediump` as fp16 (measured with a tiny render).
    pub fn mediump_is_fp16(&self) -> Result<bool, Error> {
        Ok(crate::gl::precision_probe::mediump_is_fp16(&self.dev)?)
    }

    /// GL objects the renderer holds now.
    pub fn live_gl_objects(&self) -> crate::gl::device::LiveObjects {
        self.dev.live_objects()
    }

    /// Every shader variant built so far: shader, feature bits and assembled source size.
    pub fn program_report(&self) -> Vec<crate::gl::program::ProgramInfo> {
        self.programs.report()
    }

    /// The current method's name.
    pub fn method(&self) -> &'static str {
        self.method.name()
    }

    /// Switches method. Unsupported methods are an error naming what is missing; a fallback
    /// is returned as `Some(reason)` (also logged as a warning). The previous method's GPU
    /// resources are freed.
    pub fn set_method(&mut self, name: &str) -> Result<Option<String>, Error> {
        // An explicit choice replaces what the default method would have warned about.
        let unannounced = self.pending_warning.take().is_some();
        let desc = methods::find(name)?;
        let support = (desc.supported)(self.dev.caps());
        if let Support::Unsupported(reason) = &support {
            let caps = self.dev.caps();
            let runnable: Vec<&str> = methods::METHODS
                .iter()
                .filter(|m| !matches!((m.supported)(caps), Support::Unsupported(_)))
                .map(|m| m.name)
                .collect();
            return Err(Error::UnsupportedMethod {
                method: name.to_string(),
                reason: reason.clone(),
                runnable: runnable.join(", "),
            });
        }
        let switching = desc.name != self.method.name();
        if switching {
            let new = (desc.create)(&self.dev)?;
            let mut old = std::mem::replace(&mut self.method, new);
            old.destroy(&self.dev);
        }
        self.support = support.clone();
        Ok(match support {
            Support::Fallback(reason) => {
                // Announced once, when the method is taken up (here or at the first frame).
                if switching || unannounced {
                    log::warn!("method `{name}` runs with a fallback: {reason}");
                }
                Some(reason)
            }
            _ => None,
        })
    }

    /// Renders `scene` into the currently bound framebuffer with a `width × height` viewport
    /// (for embedding: a game binds its own target or the default framebuffer first). With
    /// `options.samples` > 1 the frame is drawn into the renderer's own multisampled target
    /// and resolved into the bound framebuffer, which must then be RGBA8 of that size.
    ///
    /// The returned stats own their texts (method, GL strings, reasons): in steady state they
    /// are all the renderer allocates for a frame. A game's per-frame loop calls
    /// [`Renderer::render_reusing`] instead, which allocates nothing.
    pub fn render(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
    ) -> Result<FrameStats, Error> {
        let mut stats = FrameStats::default();
        self.render_reusing(scene, width, height, options, &mut stats)?;
        Ok(stats)
    }

    /// [`Renderer::render`], writing the frame's figures into `stats` and reusing its
    /// strings. In steady state (the same method and scene shape for a few frames: shaders
    /// built, buffers grown) the renderer makes no heap allocation for a frame, lights moving
    /// or not (`tests/soak.rs` counts them; what still allocates, the automatic grid's
    /// periodic re-choice, is listed in docs/performance.md). Keep one `FrameStats` and pass it every frame. After an error,
    /// `stats` holds no meaningful figures.
    pub fn render_reusing(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        stats: &mut FrameStats,
    ) -> Result<(), Error> {
        // Light counts are exact per pixel: never averaged over samples.
        let samples = if options.count == CountKind::None {
            options.samples.max(1)
        } else {
            1
        };
        if samples <= 1 {
            return self.render_frame(scene, width, height, options, stats);
        }
        if width == 0 || height == 0 {
            return Err(Error::Limit(format!("viewport {width}×{height} is empty")));
        }
        let destination = self.dev.bound_framebuffer();
        let format = if options.hdr {
            ColorFormat::Rgba16F
        } else {
            ColorFormat::Rgba8
        };
        let prepared = self.prepare_msaa(width, height, samples, format);
        // Creating the target binds (then leaves) framebuffers: the caller's comes back.
        self.dev.bind_framebuffer(destination);
        prepared?;
        let msaa = self.msaa.as_ref().expect("created by prepare_msaa");
        msaa.bind(&self.dev);
        let rendered = self.render_frame(scene, width, height, options, stats);
        let msaa = self.msaa.as_ref().expect("created by prepare_msaa");
        match rendered {
            Ok(()) => {
                msaa.resolve(&self.dev, destination)?;
                stats.samples = samples;
                stats.msaa_bytes = msaa.gpu_bytes();
                Ok(())
            }
            // A failed frame is not resolved over the caller's picture.
            Err(e) => {
                self.dev.bind_framebuffer(destination);
                Err(e)
            }
        }
    }

    /// One frame into the bound framebuffer (see [`Renderer::render_reusing`]).
    fn render_frame(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        stats: &mut FrameStats,
    ) -> Result<(), Error> {
        let start = Instant::now();
        let method_name = self.method.name();
        if let Some(warning) = self.pending_warning.take() {
            log::warn!("{warning}");
        }
        scene.validate()?;
        // 2^15 stays finite in fp16, where a device without fragment highp holds it.
        if !(options.exposure_ev.is_finite() && options.exposure_ev.abs() <= 15.0) {
            return Err(Error::Scene(crate::scene::SceneError::invalid(
                "exposure_ev",
                format!("must be within ±15 stops, got {}", options.exposure_ev),
            )));
        }
        if width == 0 || height == 0 {
            return Err(Error::Limit(format!("viewport {width}×{height} is empty")));
        }
        self.gpu_scene
            .upload(&self.dev, scene, options.full_variants)?;
        let view: DMat4 = scene.camera.view_matrix();
        let projection = scene
            .camera
            .projection_matrix(width as f64 / height as f64)
            .as_mat4();
        self.lights.clear();
        self.lights
            .extend(scene.lights.iter().filter(|l| l.is_active()).map(|l| {
                let mut g = GpuLight::from_light(l, &view);
                if let Some(cutoff) = options.light_cutoff {
                    g.cull_radius = crate::scene::shading::cutoff_distance(
                        g.radiance.max_element() as f64,
                        g.radius as f64,
                        cutoff as f64,
                    ) as f32;
                }
                g
            }));
        let scene_features = SceneFeatures::of(scene);
        let features = ShaderFeatures::default()
            .with(
                ShaderFeatures::SPOT,
                scene_features.spot_lights || options.full_variants,
            )
            .with(ShaderFeatures::OUTPUT_LINEAR, options.linear)
            .with(
                ShaderFeatures::TONEMAP_REINHARD,
                options.tone_map == ToneMap::Reinhard,
            )
            .with(
                ShaderFeatures::TONEMAP_ACES,
                options.tone_map == ToneMap::Aces,
            )
            .with(
                ShaderFeatures::TONEMAP_NEUTRAL,
                options.tone_map == ToneMap::Neutral,
            )
            .with(ShaderFeatures::OUTPUT_HDR, options.hdr)
            .with(
                ShaderFeatures::REFERENCE_PRECISION,
                options.reference_precision,
            )
            .with(
                ShaderFeatures::FP16_LIGHTS,
                !self.dev.caps().fragment_has_highp(),
            )
            .with(
                ShaderFeatures::COUNT_EVALS,
                matches!(options.count, CountKind::Evals | CountKind::Heatmap),
            )
            .with(
                ShaderFeatures::COUNT_HEATMAP,
                options.count == CountKind::Heatmap,
            )
            .with(
                ShaderFeatures::COUNT_REACHING,
                options.count == CountKind::Reaching,
            )
            .with(
                ShaderFeatures::LIGHTS_RGBA8,
                options.force_rgba8_lights || !self.dev.caps().float_textures,
            );
        let (near, far) = scene.camera.near_far();
        let content_far = content_far(self.gpu_scene.scene_bounds(scene), &view, near, far);
        self.dev.viewport(0, 0, width as i32, height as i32);
        self.dev.clear(options.clear_color);
        let mut ctx = FrameContext {
            dev: &self.dev,
            programs: &mut self.programs,
            scene,
            gpu_scene: &self.gpu_scene,
            view,
            projection,
            orthographic: matches!(scene.camera.projection, Projection::Orthographic { .. }),
            lights: &self.lights,
            features,
            viewport: (width, height),
            near,
            far,
            content_far,
            options,
            order: &mut self.draw_order,
            transparent_only: false,
        };
        // GPU time only where the frame waits anyway: reading the query result stalls.
        let timer = if options.wait_for_gpu {
            if self.timer.is_none() {
                self.timer = Some(crate::gl::timer::GpuTimer::new(&self.dev)?);
            }
            self.timer.as_ref().and_then(Option::as_ref)
        } else {
            None
        };
        if let Some(t) = timer {
            t.begin(&self.dev);
        }
        // No lights: no assignment, no uploads, the light loop compiled out — whatever the
        // method (a scene pays only for what it has).
        let rendered = if self.lights.is_empty() {
            methods::geometry::draw_ambient_only(&mut ctx)
        } else {
            self.method.render(&mut ctx)
        };
        // The query ends on the error path too: one left active makes the next frame's
        // `glBeginQuery` fail.
        let gpu_ms = timer.and_then(|t| t.end(&self.dev));
        let method_stats = rendered?;
        if options.wait_for_gpu {
            self.dev.finish();
        }
        self.dev.check("frame")?;
        let frame_ms = start.elapsed().as_secs_f64() * 1e3;
        let caps = self.dev.caps();
        let assign = method_stats.assign.unwrap_or(AssignStats::default());
        let grid = method_stats.grid.as_ref();
        copy_str(&mut stats.method, method_name);
        stats.es = caps.es;
        copy_str(&mut stats.gl_version, &caps.gl_version);
        copy_str(&mut stats.renderer, &caps.renderer);
        stats.width = width;
        stats.height = height;
        stats.lights = scene.lights.len();
        stats.active_lights = self.lights.len();
        stats.frame_ms = frame_ms;
        stats.gpu_ms = gpu_ms;
        stats.upload_bytes = method_stats.upload_bytes;
        stats.assign_ms = method_stats.assign_ms.unwrap_or(0.0);
        stats.clusters = assign.clusters;
        stats.nonempty_clusters = assign.nonempty_clusters;
        stats.avg_lights_per_nonempty = assign.avg_lights_per_nonempty;
        stats.max_lights_per_cluster = assign.max_lights_per_cluster;
        stats.overflowed_lights = assign.overflowed_lights + method_stats.dropped_lights;
        stats.visible_lights = method_stats
            .assign
            .map_or(self.lights.len(), |a| a.visible_lights);
        stats.light_encoding = features.light_encoding();
        copy_support(&mut stats.support, &self.support);
        stats.triangles = scene.objects.iter().map(|o| o.mesh.triangle_count()).sum();
        stats.gbuffer_bytes = method_stats.gbuffer_bytes;
        copy_opt_str(
            &mut stats.auto_choice,
            method_stats.auto_choice.map(|(c, _)| c),
        );
        copy_opt_str(
            &mut stats.auto_reason,
            method_stats.auto_choice.map(|(_, r)| r),
        );
        copy_opt_str(&mut stats.lp_num_threads, self.lp_num_threads.as_deref());
        stats.scene_features = scene_features;
        stats.grid_footprint_px = grid.map(|g| g.footprint_px);
        stats.grid_cells = grid.map_or(0, |g| g.cells);
        copy_opt_str(&mut stats.grid_reason, grid.map(|g| g.reason));
        stats.samples = 1;
        stats.msaa_bytes = 0;
        stats.upload_bytes_spread = None;
        stats.frame_ms_spread = None;
        stats.assign_ms_spread = None;
        // Only colour frames that waited for the GPU (or were timed on it) say what shading
        // costs: count passes run other shaders.
        if options.count == CountKind::None {
            let waited = options.wait_for_gpu.then_some(frame_ms);
            self.method.observe_frame(waited, gpu_ms);
        }
        stats.method_gpu_bytes = self.method.gpu_bytes();
        Ok(())
    }

    /// Renders into an internal `width × height` target and reads it back (top row first).
    /// With `options.timed_frames > 0`, renders one warm-up frame and reports the median of
    /// the timed ones.
    pub fn render_offscreen(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
    ) -> Result<(image::RgbaImage, FrameStats), Error> {
        let stats = self.render_into_target(scene, width, height, options, ColorFormat::Rgba8)?;
        let image = self
            .target
            .as_ref()
            .expect("rendered")
            .read_rgba8(&self.dev)?;
        self.dev.bind_default_framebuffer();
        Ok((image, stats))
    }

    /// Renders linear, unclamped radiance into an RGBA16F target and reads it back as f32,
    /// top row first: NaN and Inf stay visible (an 8-bit target shows them as black or white).
    /// Errors when the context cannot render to half floats.
    pub fn render_offscreen_hdr(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
    ) -> Result<(Vec<[f32; 4]>, FrameStats), Error> {
        let options = RenderOptions {
            hdr: true,
            ..options.clone()
        };
        let stats =
            self.render_into_target(scene, width, height, &options, ColorFormat::Rgba16F)?;
        let pixels = self
            .target
            .as_ref()
            .expect("rendered")
            .read_rgba_f32(&self.dev)?;
        self.dev.bind_default_framebuffer();
        Ok((pixels, stats))
    }

    fn render_into_target(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        format: ColorFormat,
    ) -> Result<FrameStats, Error> {
        let current = self.target.as_ref().map(|t| (t.size(), t.format()));
        if current != Some(((width, height), format)) {
            if let Some(mut t) = self.target.take() {
                t.destroy(&self.dev);
            }
            self.target = Some(OffscreenTarget::with_format(
                &self.dev, width, height, format,
            )?);
        }
        self.target.as_ref().expect("created above").bind(&self.dev);
        let mut stats = self.render(scene, width, height, options)?;
        if options.timed_frames > 0 {
            // The warm-up frame compiled shaders and uploaded meshes; report the timed ones.
            let mut frames = Vec::new();
            for _ in 0..options.timed_frames {
                frames.push(self.render(scene, width, height, options)?);
            }
            stats = FrameStats::summarize(frames).expect("at least one timed frame");
        }
        Ok(stats)
    }

    /// Checks that MSAA can run here with the current method and output, and (re)creates the
    /// multisampled target for this size.
    fn prepare_msaa(
        &mut self,
        width: u32,
        height: u32,
        samples: u32,
        format: ColorFormat,
    ) -> Result<(), Error> {
        let refuse = |reason: String| {
            Err(Error::Limit(format!(
                "RenderOptions::samples = {samples} (MSAA): {reason}"
            )))
        };
        if let Some(reason) = crate::gl::multisample::unsupported_reason(&self.dev, samples) {
            return refuse(reason);
        }
        if !methods::find(self.method.name())?.multisample {
            let able: Vec<&str> = methods::METHODS
                .iter()
                .filter(|m| m.multisample)
                .map(|m| m.name)
                .collect();
            return refuse(format!(
                "{} shading does not support it; methods that do: {}",
                self.method.name(),
                able.join(", ")
            ));
        }
        if format != ColorFormat::Rgba8 {
            return refuse("only 8-bit output is multisampled, not HDR".into());
        }
        let shape = ((width, height), samples);
        if self.msaa.as_ref().map(|m| m.shape()) != Some(shape) {
            if let Some(mut m) = self.msaa.take() {
                m.destroy(&self.dev);
            }
            self.msaa = Some(crate::gl::multisample::MultisampleTarget::new(
                &self.dev, width, height, samples,
            )?);
        }
        Ok(())
    }

    /// Per-pixel light counts of the opaque visible surfaces instead of colour: `Evals`, the
    /// lights the current method evaluates at each pixel (its loop length, or for deferred its
    /// proxy volumes covering the pixel), or `Reaching`, the lights whose sphere (and cone)
    /// contains the pixel's surface point, the lower bound of any culling (always evaluated
    /// by a plain-forward pass). Counts are exact (24 bits in an RGBA8 target).
    pub fn render_light_counts(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        kind: CountKind,
    ) -> Result<(LightCounts, FrameStats), Error> {
        let options = RenderOptions {
            count: kind,
            clear_color: [0.0; 4],
            timed_frames: 0,
            ..options.clone()
        };
        let (image, stats) = if kind == CountKind::Reaching {
            // A plain-forward pass whatever the method: swap one in for this frame.
            let forward = (methods::find("forward")?.create)(&self.dev)?;
            let current = std::mem::replace(&mut self.method, forward);
            let result = self.render_offscreen(scene, width, height, &options);
            let mut forward = std::mem::replace(&mut self.method, current);
            forward.destroy(&self.dev);
            result?
        } else {
            self.render_offscreen(scene, width, height, &options)?
        };
        Ok((LightCounts::decode(&image), stats))
    }

    /// The cell grid and light lists of the last tiled or clustered frame (for tests and
    /// tools that check what the shader read); `None` for other methods.
    pub fn last_light_lists(&self) -> Option<methods::LightLists<'_>> {
        self.method.light_lists()
    }

    /// Frees every GL object the renderer made, while its context is still current.
    /// Dropping the renderer does the same (so an early return on an error frees everything
    /// quietly); `destroy` only makes the moment explicit.
    pub fn destroy(mut self) {
        self.free_gl();
    }

    fn free_gl(&mut self) {
        if self.freed {
            return;
        }
        self.freed = true;
        if let Some(Some(t)) = self.timer.take() {
            t.destroy(&self.dev);
        }
        self.method.destroy(&self.dev);
        self.programs.destroy(&self.dev);
        self.gpu_scene.destroy(&self.dev);
        if let Some(mut t) = self.target.take() {
            t.destroy(&self.dev);
        }
        if let Some(mut t) = self.msaa.take() {
            t.destroy(&self.dev);
        }
    }
}

impl Drop for Renderer {
    /// The context must still be current, as [`Renderer::new`] requires for the renderer's
    /// whole life.
    fn drop(&mut self) {
        self.free_gl();
    }
}

/// Farthest view depth of the scene's geometry, clipped to `[near, far]` (never below a little
/// past the near plane): where a cluster grid should end. Lights beyond it still reach the
/// last slice, which extends to infinity.
fn content_far(bounds: Option<Aabb>, view: &DMat4, near: f64, far: f64) -> f64 {
    // View space looks down −Z: the deepest point has the smallest z.
    let deepest = bounds.map_or(far, |b| -b.transformed(view).min.z);
    let floor = if near > 0.0 { near * 2.0 } else { 1e-3 };
    let d = deepest.min(far).max(floor);
    if d.is_finite() {
        d
    } else {
        floor.max(1.0)
    }
}
