//! Offscreen renders read back to the CPU: 8-bit colour ([`Renderer::render_offscreen`], with
//! warm-up and timed frames), linear HDR ([`Renderer::render_offscreen_hdr`]) and per-pixel
//! light counts ([`Renderer::render_light_counts`]), all into the renderer's own target.

use super::{FrameStats, Renderer};
use crate::gl::framebuffer::{ColorFormat, OffscreenTarget};
use crate::metrics::counts::LightCounts;
use crate::options::{CountKind, RenderOptions};
use crate::scene::Scene;
use crate::Error;

impl Renderer {
    /// Renders into an internal `width × height` target and reads it back (top row first):
    /// 8-bit sRGB-encoded colour (linear with `options.linear`), alpha 1 on opaque surfaces and
    /// the clear colour's where nothing was drawn;
    /// the application's framebuffer binding and other GL state are as they were. With
    /// `options.measure.timed_frames > 0`, renders one warm-up frame and reports the median of
    /// the timed ones (each assigning its light lists anew, as `timed_frames` says).
    pub fn render_offscreen(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
    ) -> Result<(image::RgbaImage, FrameStats), Error> {
        self.hosted(|r| {
            let stats = r.render_into_target(scene, width, height, options, ColorFormat::Rgba8)?;
            let image = r.target.as_ref().expect("rendered").read_rgba8(&r.dev)?;
            Ok((image, stats))
        })
    }

    /// Renders linear, unclamped radiance into an RGBA16F target and reads it back as f32,
    /// top row first (`width × height` pixels, row by row): NaN and Inf stay visible (an 8-bit
    /// target shows them as black or white). Exposure and tone map are not applied: the values
    /// are the light model's radiance. Errors when the context cannot render to half floats
    /// ([`Caps::hdr_output`](crate::Caps::hdr_output) says so beforehand).
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
        self.hosted(|r| {
            let stats =
                r.render_into_target(scene, width, height, &options, ColorFormat::Rgba16F)?;
            let pixels = r.target.as_ref().expect("rendered").read_rgba_f32(&r.dev)?;
            Ok((pixels, stats))
        })
    }

    fn render_into_target(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        format: ColorFormat,
    ) -> Result<FrameStats, Error> {
        // As `render` says it, before the target is made.
        super::frame::check_viewport(width, height)?;
        self.check_viewport_limit(width, height)?;
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
        // Inside the caller's `hosted`: the application's state is saved already.
        let frame = |r: &mut Renderer| {
            let mut stats = FrameStats::default();
            r.render_hosted(scene, (width, height), options, [0, 0], &mut stats, false)
                .map(|()| stats)
        };
        let mut stats = frame(self)?;
        if options.measure.timed_frames > 0 {
            // The warm-up frame compiled shaders and uploaded meshes; report the timed ones,
            // but the programs the whole call built.
            let mut built = stats.programs_built;
            let mut frames = Vec::new();
            self.timing_frames = true;
            let timed = self.restoring(
                |r| {
                    (0..options.measure.timed_frames).try_for_each(|_| {
                        let timed = frame(r)?;
                        built += timed.programs_built;
                        frames.push(timed);
                        Ok::<(), Error>(())
                    })
                },
                |r| r.timing_frames = false,
            );
            timed?;
            stats = FrameStats::summarize(frames).expect("at least one timed frame");
            stats.programs_built = built;
        }
        Ok(stats)
    }

    /// Per-pixel light counts of the opaque visible surfaces instead of colour: `Evals`, the
    /// lights the current method evaluates at each pixel (its loop length, or for deferred its
    /// proxy volumes covering the pixel), or `Reaching`, the lights whose sphere (and cone)
    /// contains the pixel's surface point, the lower bound of any culling (always evaluated
    /// by a plain-forward pass). Counts are exact (24 bits in an RGBA8 target); where they
    /// cannot be ([`Error::Limit`]): forward's past its loop bound, deferred's past 8 192 lights
    /// without `GL_EXT_float_blend` (a half-float accumulation). `None` and
    /// `Heatmap` are colour, not counts: [`Error::InvalidOption`] naming `kind`.
    pub fn render_light_counts(
        &mut self,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RenderOptions,
        kind: CountKind,
    ) -> Result<(LightCounts, FrameStats), Error> {
        if !matches!(kind, CountKind::Evals | CountKind::Reaching) {
            return Err(Error::InvalidOption {
                field: "kind",
                reason: format!("must be Evals or Reaching (counts), got {kind:?}"),
            });
        }
        let mut options = RenderOptions {
            count: kind,
            clear_color: [0.0; 4],
            ..options.clone()
        };
        options.measure.timed_frames = 0;
        let (image, stats) = self.hosted(|r| r.render_offscreen(scene, width, height, &options))?;
        Ok((LightCounts::try_decode(&image)?, stats))
    }
}
