//! What a frame reports: [`FrameStats`], its summary over timed frames, and the helpers that
//! refill its texts in place so a reused `FrameStats` costs no allocation per frame.

use serde::Serialize;

use crate::gl::EsVersion;
use crate::methods::Support;
use crate::metrics::spread::Spread;
use crate::scene::features::SceneFeatures;

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
    /// Runs of consecutive cells the assignment found (0 for forward): with the indices and
    /// cells, what the assignment's time grows with.
    pub assign_runs: usize,
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
    /// [`Renderer::render_offscreen`](super::Renderer::render_offscreen) (`timed_frames` > 0):
    /// p50, p95, p99, max.
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
    /// Empty figures: what [`Renderer::render_reusing`](super::Renderer::render_reusing) fills
    /// in (a game keeps one and passes it every frame).
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
            assign_runs: 0,
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
pub(super) fn copy_str(dst: &mut String, src: &str) {
    if dst.as_str() != src {
        dst.clear();
        if dst.capacity() < src.len() {
            dst.reserve(src.len() + src.len() / 2);
        }
        dst.push_str(src);
    }
}

/// [`copy_str`] for optional texts (`None` frees the buffer).
pub(super) fn copy_opt_str(dst: &mut Option<String>, src: Option<&str>) {
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
pub(super) fn copy_support(dst: &mut Support, src: &Support) {
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
