//! Drawing one frame into the bound framebuffer: [`Renderer::render`], the allocation-free
//! [`Renderer::render_reusing`] (through the renderer's multisampled target when MSAA is
//! asked for) and the frame itself: validation, setup, the method's draw, GPU timing and the
//! frame's figures.

use std::time::Instant;

use super::frame_report::DrawnFrame;
use super::light_high_water::LitWith;
use super::{FrameStats, Renderer};
use crate::gl::bound_framebuffer::TargetQueries;
use crate::gl::framebuffer::ColorFormat;
use crate::methods::{self, FrameContext};
use crate::options::{Clear, CountKind, RenderOptions, MAX_EXPOSURE_EV};
use crate::scene::{Projection, Scene, Short};
use crate::Error;

impl Renderer {
    /// Renders `scene` into the currently bound framebuffer with a `width × height` viewport
    /// whose lower-left corner is `options.origin` (for embedding: a game binds its own target
    /// or the default framebuffer first); only that rectangle is cleared and drawn. With
    /// `options.samples` > 1 the frame is drawn into the renderer's own multisampled target
    /// and resolved into that rectangle, in whatever colour format the bound framebuffer has
    /// (on ES 3.0 through a single-sampled copy where it is not the target's RGBA8 or sRGB
    /// RGBA8: GL resolves between identical formats only). The application's GL state
    /// (bindings, viewport, blend, depth, …) is given back as it was, and its scissor,
    /// stencil or blend equations do not change the frame (the README's
    /// "Sharing the context with a game"); another EGL context current is
    /// [`GlError::OtherContext`](crate::GlError::OtherContext), and a frame of no pixels (a
    /// minimised window, which a game skips) [`Error::EmptyViewport`].
    ///
    /// The returned stats own their texts (method, GL strings, reasons): in steady state they
    /// are all the renderer allocates for a frame. A game's per-frame loop calls
    /// [`Renderer::render_reusing`] instead, which allocates nothing, with
    /// [`RenderOptions::wait_for_gpu`] `false`: the default options wait for the GPU at the end
    /// of every frame (`glFinish`), as measurements want and a game does not.
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
    /// or not, the automatic grid's re-choices included (`tools/tests/soak.rs` counts them; see
    /// docs/performance.md). Keep one `FrameStats` and pass it every frame. After an error,
    /// `stats` holds no meaningful figures.
    pub fn render_reusing(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        stats: &mut FrameStats,
    ) -> Result<(), Error> {
        let origin = options.origin;
        self.hosted(|r| r.render_hosted(scene, (width, height), options, origin, stats, true))
    }

    /// [`Renderer::render_reusing`] with the frame's lower-left corner at `origin` in the bound
    /// framebuffer (the offscreen renders pass `[0, 0]`), inside a call that saved the
    /// application's GL state ([`Renderer::hosted`]). `applications`: the framebuffer is the
    /// application's, checked for what the frame needs of it (the offscreen renders bind their
    /// own).
    pub(super) fn render_hosted(
        &mut self,
        scene: &Scene,
        size: (u32, u32),
        options: &RenderOptions,
        origin: [u32; 2],
        stats: &mut FrameStats,
        applications: bool,
    ) -> Result<(), Error> {
        let (draw_calls, programs) = (self.dev.draw_calls(), self.programs.len());
        if self.warming_up {
            self.programs.count_for_next_frame();
        } else {
            self.programs.begin_frame();
        }
        let drawn = self.render_counted(scene, size, options, origin, stats, applications);
        if drawn.is_ok() && !self.warming_up && self.light_high_water.note(self.lights.len()) {
            self.fit_light_buffers();
        }
        if drawn.is_err() {
            // What the failed frame uploaded may not be there: the next one packs and uploads
            // its light data anew, whatever its method kept (each keys it on the generation).
            self.lights_generation += 1;
        }
        stats.draw_calls = self.dev.draw_calls() - draw_calls;
        stats.programs_built = self.programs.len() - programs;
        stats.memory.shader_programs = self.programs.len();
        drawn
    }

    /// [`Renderer::render_hosted`] but for its draw calls' count.
    fn render_counted(
        &mut self,
        scene: &Scene,
        (width, height): (u32, u32),
        options: &RenderOptions,
        origin: [u32; 2],
        stats: &mut FrameStats,
        applications: bool,
    ) -> Result<(), Error> {
        // The frame's own errors first: they do not depend on what is bound.
        check_viewport(width, height)?;
        // The size before the origin: a frame of u32::MAX pixels is too large, whatever its
        // origin (it was named an origin past GL's window coordinates).
        self.check_viewport_limit(width, height)?;
        check_origin(origin, width, height)?;
        // Before MSAA's target is made: its refusal would hide the option's error.
        check_options(options)?;
        // Light counts are exact per pixel: never averaged over samples.
        let mut samples = if options.count == CountKind::None {
            options.samples.max(1)
        } else {
            1
        };
        // The framebuffer the frame goes to and what it is, asked once a frame: the
        // application's as the call found it bound, or the offscreen render's own.
        let target = match applications {
            true => {
                self.dev.draw_into_host_framebuffer();
                self.dev.host_framebuffer()
            }
            false => self.dev.bound_framebuffer(),
        };
        let queries = TargetQueries {
            fixed_point: applications && options.hdr && !self.warned_hdr_fixed_point,
            rgba8: samples > 1,
        };
        // An offscreen render's target is the renderer's own: only an MSAA resolve into it
        // asks what it is.
        let format = match applications || samples > 1 {
            true => self.dev.target_format(target, queries),
            false => Default::default(),
        };
        // A game's multisampled framebuffer (a window surface with EGL_SAMPLES) samples the
        // frame itself; a resolve could not blit into it.
        let destination_samples = if applications { format.samples } else { 0 };
        if destination_samples > 0 {
            samples = 1;
        }
        // An offscreen render has nothing to keep (its target is the renderer's own): it
        // ignores `clear`, as it ignores `origin`.
        self.frame_clear = if applications {
            options.clear
        } else {
            Clear::All
        };
        if self.frame_clear != Clear::All {
            let keep = |why: &str| Error::InvalidOption {
                field: "clear",
                reason: format!("nothing to keep: {why}; use Clear::All"),
            };
            if samples > 1 {
                return Err(keep(
                    "MSAA draws into the renderer's own multisampled target, which has none of \
                     the framebuffer's colour or depth (draw with samples 1, or into a \
                     framebuffer multisampled itself)",
                ));
            }
        }
        let games_depth_bits = if applications {
            self.warn_hdr_into_fixed_point(options, &format);
            self.check_bound_target((target, &format), (width, height), origin, samples <= 1)?
        } else {
            None
        };
        stats.depth_bits = match games_depth_bits {
            Some(bits) => bits,
            None => self.own_depth_bits(),
        };
        // A framebuffer that encodes sRGB itself is given linear values, not encoded twice.
        self.srgb_destination = applications && format.srgb;
        if self.srgb_destination && matches!(options.count, CountKind::Evals | CountKind::Reaching)
        {
            return Err(Error::InvalidOption {
                field: "count",
                reason: "exact light counts are bytes, which a framebuffer that encodes sRGB \
                         would change: draw them into an RGBA8 one (or use the heatmap)"
                    .into(),
            });
        }
        if self.srgb_destination && options.linear {
            return Err(Error::InvalidOption {
                field: "linear",
                reason: "a framebuffer that encodes sRGB stores every value encoded: draw \
                         linear values into an RGBA8 one"
                    .into(),
            });
        }
        self.own_msaa_frame = samples > 1;
        if samples <= 1 {
            // A game that turned MSAA off gets the target's memory back (tens of MB at 1080p).
            for mut m in self.msaa.take_all() {
                m.destroy(&self.dev);
            }
            self.render_frame(
                scene,
                (width, height),
                options,
                (target, origin),
                None,
                stats,
            )?;
            stats.samples = stats.samples.max(destination_samples as u32);
            self.complete_target = applications.then_some(target);
            return Ok(());
        }
        let destination = target;
        let same_format = format.rgba8;
        let format = if options.hdr {
            ColorFormat::Rgba16F
        } else {
            ColorFormat::Rgba8
        };
        let srgb = self.srgb_destination;
        let prepared = self.prepare_msaa(width, height, samples, format, srgb);
        // Creating the target binds (then leaves) framebuffers: the caller's comes back.
        self.dev.bind_framebuffer(destination);
        prepared?;
        let msaa = self.msaa.get().expect("created by prepare_msaa");
        msaa.bind(&self.dev);
        let own_target = Some(msaa.fbo());
        // Drawn at the target's corner, resolved to the origin.
        let resolve = Resolve {
            destination,
            origin,
            same_format,
        };
        let rendered = self.render_frame(
            scene,
            (width, height),
            options,
            (own_target, [0, 0]),
            Some(resolve),
            stats,
        );
        let msaa = self.msaa.get().expect("created by prepare_msaa");
        match rendered {
            Ok(()) => {
                stats.samples = msaa.samples_drawn();
                stats.memory.msaa_bytes = self.msaa.both().map(|m| m.gpu_bytes()).sum();
                self.complete_target = applications.then_some(target);
                Ok(())
            }
            // A failed frame is not resolved over the caller's picture.
            Err(e) => {
                self.dev.bind_framebuffer(destination);
                Err(e)
            }
        }
    }

    /// What `clear_color` is cleared with: an sRGB destination encodes the clear value as it
    /// does a fragment's, so it is decoded first (it is given as stored).
    fn clear_value(&self, options: &RenderOptions) -> [f32; 4] {
        let color = options.clear_color;
        if !self.srgb_destination {
            return color;
        }
        let decode =
            |c: f32| crate::scene::shading::srgb_to_linear(c.clamp(0.0, 1.0) as f64) as f32;
        [
            decode(color[0]),
            decode(color[1]),
            decode(color[2]),
            color[3],
        ]
    }

    /// One frame into the bound framebuffer `target` at `origin` (see
    /// [`Renderer::render_reusing`]); with `resolve`, into the bound MSAA target, filled and
    /// resolved inside the frame's timing.
    fn render_frame(
        &mut self,
        scene: &Scene,
        (width, height): (u32, u32),
        options: &RenderOptions,
        (target, origin): (Option<glow::Framebuffer>, [u32; 2]),
        resolve: Option<Resolve>,
        stats: &mut FrameStats,
    ) -> Result<(), Error> {
        let start = Instant::now();
        // Reaching counts are a plain-forward pass's, whatever the method (`CountKind`).
        let reaching_pass = options.count == CountKind::Reaching && self.method.name() != "forward";
        if reaching_pass && self.reaching_pass.is_none() {
            self.reaching_pass = Some((methods::find("forward")?.create)(&self.dev)?);
        }
        // Freed as a method's light resources are: it held its light texture for good.
        if reaching_pass {
            self.reaching_idle = 0;
        } else if self.reaching_pass.is_some() && methods::idle_for_long(&mut self.reaching_idle) {
            if let Some(mut pass) = self.reaching_pass.take() {
                pass.destroy(&self.dev);
            }
        }
        let method_name = if reaching_pass {
            "forward"
        } else {
            self.method.name()
        };
        let setup = self.set_up_frame(scene, (width, height), options, stats.depth_bits)?;
        let features = setup.features;
        let frame_lights = self.placed.of(&self.lights);
        let clear = self.frame_clear;
        let colour = (clear == Clear::All).then(|| self.clear_value(options));
        // MSAA frames clear everything (`Clear::All`, checked above).
        if let (Some(msaa), Some(colour)) =
            (self.msaa.get_mut().filter(|_| resolve.is_some()), colour)
        {
            msaa.fill(&self.dev, &mut self.programs, colour)?;
        }
        let frame_rect = [origin[0], origin[1], width, height].map(|v| v as i32);
        self.dev
            .viewport(frame_rect[0], frame_rect[1], frame_rect[2], frame_rect[3]);
        self.dev
            .clear_rect_of(frame_rect, colour, clear != Clear::Nothing);
        let mut ctx = FrameContext {
            dev: &self.dev,
            programs: &mut self.programs,
            scene,
            gpu_scene: &self.gpu_scene,
            view: setup.view,
            projection: setup.projection,
            orthographic: matches!(scene.camera.projection, Projection::Orthographic { .. }),
            lights: frame_lights,
            lights_generation: self.lights_generation,
            target,
            directional: setup.directional,
            features,
            pre_exposure: setup.pre_exposure,
            viewport: (width, height),
            origin,
            near: setup.near,
            far: setup.far,
            content_far: setup.content_far,
            options,
            order: &mut self.draw_order,
            transparent_only: false,
            own_msaa: self.own_msaa_frame,
            clear,
            warm_up: self.warming_up,
            shared_surfaces: setup.shared_surfaces,
        };
        // The frame's errors so far are its own: the timer's calls (creating the queries too)
        // would drain them as theirs.
        if options.gpu_timer {
            self.dev.check("the frame's uploads")?;
        }
        if options.gpu_timer && self.timer.is_none() {
            self.timer = Some(crate::gl::timer::GpuTimer::new(&self.dev));
        }
        let timer = (self.timer.as_ref().and_then(Option::as_ref)).filter(|_| options.gpu_timer);
        if ctx.scene.materials.iter().any(|m| m.depth_bias != 0.0) {
            self.dev.prepare_depth_bias();
        }
        self.frame_serial += 1;
        let serial = self.frame_serial;
        if let Some(t) = timer {
            // A frame that waits reads its own query: earlier frames' left in flight are
            // taken first, so one is free for it.
            if options.wait_for_gpu {
                t.poll(&self.dev);
            }
            t.begin(&self.dev, serial, options.wait_for_gpu);
        }
        // No lights, or none that reaches the view: no assignment, no uploads, the light loop
        // compiled out — whatever the method (a scene pays only for what it has in view).
        let method = match &mut self.reaching_pass {
            Some(pass) if reaching_pass => pass,
            _ => &mut self.method,
        };
        // A warm-up draws the lit variants whatever its camera sees (and the unlit ones in a
        // frame of their own).
        let lit = if self.warming_up {
            !ctx.lights.is_empty()
        } else {
            ctx.lights_in_view(1) > 0
        };
        self.light_high_water.lit_with = lit.then_some(if reaching_pass {
            LitWith::ReachingPass
        } else {
            LitWith::Method
        });
        let rendered = if !lit {
            method.skip_frame(&self.dev);
            methods::forward::draw_ambient_only(&mut ctx)
        } else {
            method.render(&mut ctx)
        };
        // MSAA's resolve is the frame's too: timed with it, waited for with it.
        let rendered = match (rendered, resolve, self.msaa.get_mut()) {
            (Ok(stats), Some(to), Some(msaa)) => msaa
                .resolve(
                    &self.dev,
                    &mut self.programs,
                    to.destination,
                    to.origin,
                    to.same_format,
                )
                .map(|()| stats)
                .map_err(Error::from),
            (other, ..) => other,
        };
        // Likewise the draws' errors, before the query ends (on the error path too: one left
        // active makes the next frame's `glBeginQuery` fail).
        let rendered = match (rendered, timer) {
            (Ok(stats), Some(_)) => (self.dev.check("the frame's draws"))
                .map(|()| stats)
                .map_err(Error::from),
            // A failed frame's pending errors are its own, not the query's.
            (Err(e), Some(_)) => {
                self.dev.drain_errors();
                Err(e)
            }
            (other, None) => other,
        };
        // A frame that waits reads its own query; one that does not reads the newest that has
        // finished, without stalling.
        let wait = options.wait_for_gpu;
        let gpu = match timer {
            Some(t) if wait => {
                let own = t.end(&self.dev, true);
                t.poll(&self.dev); // frees queries earlier frames left in flight
                own.map(|ms| (serial, ms))
            }
            Some(t) => {
                t.end(&self.dev, false);
                t.poll(&self.dev)
            }
            None => None,
        };
        let gpu_ms = gpu.map(|(_, ms)| ms);
        let method_stats = rendered?;
        if options.wait_for_gpu {
            self.dev.finish();
        }
        if timer.is_none() {
            // With the timer, checked before its query ended (and the timer's own calls by it).
            self.dev.check("the frame's draws")?;
        }
        let frame_ms = start.elapsed().as_secs_f64() * 1e3;
        stats.record(&DrawnFrame {
            method_name,
            support: &self.support,
            caps: self.dev.caps(),
            lp_num_threads: self.lp_num_threads.as_deref(),
            size: (width, height),
            scene,
            scene_features: setup.scene_features,
            features,
            active_lights: frame_lights.len(),
            lit,
            frame_ms,
            gpu_ms,
            method: &method_stats,
            split_bytes: setup.split_bytes,
            scene_upload_bytes: setup.scene_upload_bytes,
            scene_gpu_bytes: self.gpu_scene.gpu_bytes(),
        });
        // Only colour frames that waited for the GPU (or were timed on it) say what shading
        // costs: count passes run other shaders.
        if options.count == CountKind::None {
            self.method.observe_frame(methods::FrameTiming {
                serial,
                waited_ms: options.wait_for_gpu.then_some(frame_ms),
                gpu,
            });
        }
        stats.memory.method_gpu_bytes =
            self.method.gpu_bytes() + self.reaching_pass.as_ref().map_or(0, |p| p.gpu_bytes());
        Ok(())
    }

    /// Checks that MSAA can run here with the current method and output, and (re)creates the
    /// multisampled target for this size.
    fn prepare_msaa(
        &mut self,
        width: u32,
        height: u32,
        samples: u32,
        format: ColorFormat,
        srgb: bool,
    ) -> Result<(), Error> {
        let refuse = |reason: String| Err(Error::Msaa { samples, reason });
        // First: HDR output is refused on every context and method, whatever else says no.
        if format != ColorFormat::Rgba8 {
            return refuse("only 8-bit output is multisampled, not HDR".into());
        }
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
        let shape = ((width, height), samples);
        // ES 2.0's target has no sRGB form: it keeps the frame's linear values in RGBA8.
        let srgb = srgb && self.dev.es() == crate::gl::EsVersion::Es3;
        let dev = &self.dev;
        self.msaa.fit(
            |m| m.shape() == shape && m.is_srgb() == srgb,
            |m| m.shape().0 != shape.0,
            || {
                crate::gl::multisample::MultisampleTarget::with_encoding(
                    dev, width, height, samples, srgb,
                )
            },
            |mut m| m.destroy(dev),
        )?;
        Ok(())
    }
}

/// Where a frame drawn into the renderer's MSAA target is resolved to.
#[derive(Clone, Copy)]
struct Resolve {
    /// The caller's framebuffer (`None`: the default one).
    destination: Option<glow::Framebuffer>,
    /// The frame's lower-left corner in it.
    origin: [u32; 2],
    /// Its colour is the target's format, so a blit can resolve into it directly.
    same_format: bool,
}

/// Refuses an empty frame (the same error whichever call was given it).
pub(super) fn check_viewport(width: u32, height: u32) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(Error::EmptyViewport { width, height });
    }
    Ok(())
}

/// Refuses a frame rectangle past GL's `i32` window coordinates, naming the field.
fn check_origin(origin: [u32; 2], width: u32, height: u32) -> Result<(), Error> {
    for (axis, start, size) in [("x", origin[0], width), ("y", origin[1], height)] {
        if u64::from(start) + u64::from(size) > i32::MAX as u64 {
            let reason = format!(
                "{axis} {start} plus the frame's {size} pixels passes GL's largest window \
                 coordinate, {}",
                i32::MAX
            );
            return Err(Error::InvalidOption {
                field: "origin",
                reason,
            });
        }
    }
    Ok(())
}

/// Refuses render options the frame cannot be made from, naming the field.
fn check_options(options: &RenderOptions) -> Result<(), Error> {
    let invalid = |field, reason| Err(Error::InvalidOption { field, reason });
    let positive = |v: f64| v.is_finite() && v > 0.0;
    if let Some(cutoff) = options.light_cutoff {
        if !(cutoff.is_finite() && cutoff >= 0.0) {
            let why = format!("must be a finite radiance from 0 up, got {}", Short(cutoff));
            return invalid("light_cutoff", why);
        }
    }
    if !options.clear_color.iter().all(|c| c.is_finite()) {
        let why = format!("must be finite, got {:?}", options.clear_color);
        return invalid("clear_color", why);
    }
    // A NaN tile size, like a NaN grid setting, never equals itself: the tiles would be
    // rebuilt every frame.
    if !positive(options.tile_px) {
        let why = format!(
            "must be a finite number above 0, got {}",
            Short(options.tile_px)
        );
        return invalid("tile_px", why);
    }
    let heat = options.heat_scale;
    if !(heat.is_finite() && heat >= 1.0) {
        return invalid(
            "heat_scale",
            format!("must be a finite count from 1 up, got {}", Short(heat)),
        );
    }
    if !(options.exposure_ev.is_finite() && options.exposure_ev.abs() <= MAX_EXPOSURE_EV) {
        let why = format!(
            "must be within ±{MAX_EXPOSURE_EV} stops, got {}",
            Short(options.exposure_ev)
        );
        return invalid("exposure_ev", why);
    }
    // Non-finite grid settings: a NaN never equals itself, so the grid would be rebuilt and
    // re-chosen every frame.
    for (field, value) in [
        ("grid.footprint_px", options.grid.footprint_px),
        ("grid.slice_depth", options.grid.slice_depth),
    ] {
        if !positive(value) {
            return invalid(
                field,
                format!("must be a finite number above 0, got {}", Short(value)),
            );
        }
    }
    for (field, value) in [
        ("grid.first_split", options.grid.first_split),
        (
            "grid.measure.min_cell_size",
            options.grid.measure.min_cell_size,
        ),
    ] {
        if let Some(v) = value.filter(|v| !v.is_finite()) {
            return invalid(field, format!("must be finite (or None), got {}", Short(v)));
        }
    }
    if options.max_assign_threads == 0 {
        let why = "must be at least 1 (1: the calling thread alone)".to_string();
        return invalid("max_assign_threads", why);
    }
    if options.measure.timed_frames > crate::options::MAX_TIMED_FRAMES {
        let why = format!(
            "must be at most {}, got {}",
            crate::options::MAX_TIMED_FRAMES,
            options.measure.timed_frames
        );
        return invalid("measure.timed_frames", why);
    }
    let cascades = options.grid.cascades;
    if cascades > crate::cluster::grid::MAX_CASCADES {
        let why = format!(
            "must be at most {} (0 counts as 1), got {cascades}",
            crate::cluster::grid::MAX_CASCADES
        );
        return invalid("grid.cascades", why);
    }
    let budget = options.grid.assign_budget();
    if !(budget.is_finite() && budget >= 0.0) {
        let why = format!(
            "must be a finite share of the frame from 0 up, got {}",
            Short(budget)
        );
        return invalid("grid.assign_budget", why);
    }
    Ok(())
}
