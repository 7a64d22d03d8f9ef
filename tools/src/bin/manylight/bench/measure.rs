//! One configuration of `manylight bench` timed, counted and compared against forward's
//! reference and the CPU reference.

use manylight::methods::Support;
use manylight::metrics::cpu_reference::{self, Encoding, ReferenceSet};
use manylight::renderer::{CountKind, LightCounts};
use manylight::scene::raycast::SceneRaycaster;
use manylight::scene::Scene;
use manylight::{RenderOptions, Renderer};
use manylight_tools::report::BenchRow;

use super::plan::{adaptive_frames, frames_for, Frames};

/// Everything one configuration is measured against.
pub(super) struct Baseline {
    pub(super) reference: image::RgbaImage,
    pub(super) bound: LightCounts,
    pub(super) cpu: ReferenceSet,
}

/// Forward's reference picture, its reaching counts and the CPU reference samples; `Ok(Err)`
/// with the reason where forward cannot draw every light here (no reference to compare with).
pub(super) fn baseline(
    renderer: &mut Renderer,
    scene: &Scene,
    caster: &SceneRaycaster,
    (w, h): (u32, u32),
    cpu_samples: usize,
) -> Result<Result<Baseline, String>, Box<dyn std::error::Error>> {
    renderer.set_method_named("forward")?;
    let reference_opts = RenderOptions {
        measure: manylight::MeasureOptions {
            reference_precision: true,
            ..Default::default()
        },
        ..RenderOptions::default()
    };
    // The counts first: where they are refused, a reference would not be over every light.
    let bound = renderer.render_light_counts(scene, w, h, &reference_opts, CountKind::Reaching);
    let (bound, _) = match bound {
        Ok(counted) => counted,
        // More lights than forward's loop holds here: no reference over all of them.
        Err(manylight::Error::Limit(e)) => return Ok(Err(e)),
        Err(e) => return Err(e.into()),
    };
    let (reference, _) = renderer.render_offscreen(scene, w, h, &reference_opts)?;
    let subpixel = cpu_reference::snapping_reach(renderer.caps().subpixel_bits);
    let cpu = cpu_reference::reference_samples_with(
        caster,
        scene,
        w,
        h,
        cpu_samples,
        Encoding::Srgb,
        subpixel,
    );
    Ok(Ok(Baseline {
        reference,
        bound,
        cpu,
    }))
}

/// One configuration's row, with its image and light counts (kept for the pictures).
pub(super) struct Measured {
    pub(super) row: BenchRow,
    pub(super) image: image::RgbaImage,
    pub(super) evals: LightCounts,
}

/// What every configuration of one (scene, light count, ES version) shares.
pub(super) struct Measure<'a> {
    pub(super) scene: &'a Scene,
    pub(super) name: &'a str,
    pub(super) base: &'a Baseline,
    pub(super) size: (u32, u32),
    pub(super) frames: Frames,
}

impl Measure<'_> {
    /// Times, counts and compares one configuration; `None` when the method cannot run here.
    pub(super) fn run(
        &self,
        renderer: &mut Renderer,
        method: &str,
        knob: &str,
        adjust: impl Fn(&mut RenderOptions),
    ) -> Result<Option<Measured>, Box<dyn std::error::Error>> {
        let desc = manylight::methods::find(method)?;
        if matches!((desc.supported)(renderer.caps()), Support::Unsupported(_)) {
            return Ok(None);
        }
        renderer.set_method_named(method)?;
        let mut opts = RenderOptions::default();
        adjust(&mut opts);
        let (w, h) = self.size;
        let rendered = match self.frames {
            Frames::Fixed(n) => Ok(n),
            // An untimed frame says how slow the configuration is: the first, or the second
            // where the first built shaders.
            Frames::Adaptive => {
                let mut untimed = || renderer.render_offscreen(self.scene, w, h, &opts);
                untimed().and_then(|(_, first)| match adaptive_frames(&first) {
                    Some(n) => Ok(n),
                    None => untimed().map(|(_, second)| frames_for(second.time.frame_ms)),
                })
            }
        }
        .and_then(|frames| {
            opts.measure.timed_frames = frames;
            renderer.render_offscreen(self.scene, w, h, &opts)
        });
        let (image, stats) = match rendered {
            Ok(r) => r,
            // A configuration past a method's limits (forward's loop bound, MSAA where the
            // context has none) is skipped.
            Err(e @ (manylight::Error::Limit(_) | manylight::Error::Msaa { .. })) => {
                log::warn!("{} {method} {knob}: skipped: {e}", self.name);
                return Ok(None);
            }
            Err(e) => return Err(e.into()),
        };
        let evals = renderer.render_light_counts(self.scene, w, h, &opts, CountKind::Evals);
        let (evals, _) = match evals {
            Ok(counted) => counted,
            // Counts this configuration cannot give exactly: skipped, as a render past a limit.
            Err(e @ manylight::Error::Limit(_)) => {
                log::warn!("{} {method} {knob}: skipped: {e}", self.name);
                return Ok(None);
            }
            Err(e) => return Err(e.into()),
        };
        let d = manylight::metrics::diff(&self.base.reference, &image);
        let cpu = cpu_reference::compare(&image, &self.base.cpu);
        let bound = self.base.bound.total();
        let row = BenchRow {
            scene: self.name.to_string(),
            method: method.to_string(),
            es: format!("{}.0", stats.context.es.major()),
            lights: self.scene.lights.len(),
            width: w,
            height: h,
            knob: knob.to_string(),
            frame_ms: stats.time.frame_ms,
            timed_frames: opts.measure.timed_frames,
            auto_choice: stats.auto_choice.clone(),
            gpu_ms: stats.time.gpu_ms,
            assign_ms: stats.time.assign_ms,
            upload_bytes: stats.memory.upload_bytes,
            draw_calls: stats.draw_calls,
            light_evals: evals.total(),
            evals_per_pixel: evals.mean(),
            max_evals: evals.max(),
            lower_bound_evals: bound,
            lower_bound_per_pixel: self.base.bound.mean(),
            evals_ratio: (bound > 0).then(|| evals.total() as f64 / bound as f64),
            max_abs_err: d.max_abs,
            rmse: d.rmse,
            psnr_db: d.psnr_db.is_finite().then_some(d.psnr_db),
            over_1: d.over_1,
            over_2: d.over_2,
            cpu_max_abs_err: (cpu.samples > 0).then_some(cpu.max_abs),
            cpu_samples: cpu.samples,
            overflowed_lights: stats.lights.overflowed,
            grid_footprint_px: stats.grid.footprint_px,
            grid_cells: stats.grid.cells,
            grid_reason: stats.grid.reason.clone(),
            renderer: stats.context.renderer.clone(),
            lp_num_threads: stats.context.lp_num_threads.clone(),
        };
        Ok(Some(Measured { row, image, evals }))
    }
}
