//! What a frame reports: [`FrameStats`], its summary over timed frames, and the helpers that
//! refill its texts in place so a reused `FrameStats` costs no allocation per frame.

use serde::Serialize;

use crate::cluster::assign::AssignStats;
use crate::cluster::pack::LightEncoding;
use crate::gl::EsVersion;
use crate::methods::Support;
use crate::metrics::spread::Spread;
use crate::scene::features::SceneFeatures;

/// What one frame did, grouped by what the figures are about. Serialised flat (the `--stats`
/// JSON's field names, docs/cli.md).
#[derive(Clone, Debug, Serialize)]
pub struct FrameStats {
    /// Shading method.
    pub method: String,
    /// The method's support status on this context (fallbacks say what degrades; forward
    /// standing in for a default method the context cannot run is a fallback naming it).
    pub support: Support,
    /// The method `auto` picked for this frame (`None` for the other methods).
    pub auto_choice: Option<String>,
    /// Why `auto` picked it.
    pub auto_reason: Option<String>,
    /// The context the frame ran on.
    #[serde(flatten)]
    pub context: ContextStats,
    /// Viewport width.
    pub width: u32,
    /// Viewport height.
    pub height: u32,
    /// Samples per pixel the frame was drawn with (1: no MSAA): what the implementation gave
    /// for `RenderOptions::samples`, which GL rounds up to a count it has.
    pub samples: u32,
    /// Bits of the depth buffer the frame was drawn against: the game's framebuffer's, or the
    /// renderer's own target's (16 on an ES 2.0 context with neither `GL_OES_depth24` nor
    /// `GL_OES_packed_depth_stencil`, where surfaces close in depth may show through).
    pub depth_bits: u32,
    /// Triangles drawn.
    pub triangles: usize,
    /// Draw calls the frame made, in every pass (depth prepass, shading, deferred's lights and
    /// composite, transparent objects, MSAA's fill and resolve): each costs a GPU's driver
    /// CPU time, which a software rasterizer's frame time hides.
    pub draw_calls: u64,
    /// Shader programs the frame compiled and linked (variants met for the first time): each
    /// costs the driver milliseconds or more, a hitch in a game's frame.
    /// [`Renderer::warm_up`](super::Renderer::warm_up) builds them beforehand. With
    /// [`MeasureOptions::timed_frames`](crate::MeasureOptions::timed_frames): those every frame
    /// of the call built, its untimed first frame included.
    pub programs_built: usize,
    /// What the scene uses (and so what the shader variants were built with).
    pub scene_features: SceneFeatures,
    /// Frame, GPU and assignment times.
    #[serde(flatten)]
    pub time: TimeStats,
    /// The scene's lights and what became of them.
    #[serde(flatten)]
    pub lights: LightStats,
    /// The light assignment's figures (tiled, clustered; zeros for the other methods).
    #[serde(flatten)]
    pub assignment: AssignStats,
    /// The frame drew with its method's last light lists and uploads: nothing they are built
    /// from had changed (the lights in view space, and the grid, the limits and the light
    /// record layout for tiled and clustered; forward's and deferred's light records likewise,
    /// docs/architecture.md), so it neither assigned nor uploaded them (`assign_ms` 0, the
    /// assignment's figures the lists' own, and `upload_bytes` 0 unless an object moved and its
    /// split copies of huge triangles were made again).
    pub lists_reused: bool,
    /// The cell grid (tiled, clustered).
    #[serde(flatten)]
    pub grid: GridStats,
    /// Uploads and GPU memory.
    #[serde(flatten)]
    pub memory: MemoryStats,
}

/// The context a frame ran on.
#[derive(Clone, Debug, Default, Serialize)]
pub struct ContextStats {
    /// Feature level (`2.0` / `3.0`).
    pub es: EsVersion,
    /// `GL_VERSION` of the context.
    pub gl_version: String,
    /// `GL_RENDERER`.
    pub renderer: String,
    /// `LP_NUM_THREADS` when set (llvmpipe's thread count changes every timing).
    pub lp_num_threads: Option<String>,
}

/// Where a frame's time went.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct TimeStats {
    /// Frame time in milliseconds (median of the timed frames): CPU work plus `glFinish` with
    /// [`RenderOptions::wait_for_gpu`](crate::RenderOptions::wait_for_gpu), else the CPU's
    /// submission alone (a game's frame). Both this and `gpu_ms` include the resolve of the
    /// renderer's own MSAA target.
    pub frame_ms: f64,
    /// GPU time of the frame's GL work from a `GL_EXT_disjoint_timer_query` elapsed-time query
    /// (median of the timed frames). A frame that does not wait for the GPU (a game's) reports
    /// the newest earlier frame whose query has finished, read without stalling (a GPU runs a
    /// frame or two behind). `None` without the extension, when the GPU reported a disjoint
    /// event, and while no query has finished.
    pub gpu_ms: Option<f64>,
    /// CPU light-assignment time in milliseconds (0 for forward).
    pub assign_ms: f64,
    /// Frame time over the timed frames of
    /// [`Renderer::render_offscreen`](crate::Renderer::render_offscreen) (`timed_frames` > 0):
    /// p50, p95, p99, max.
    pub frame_ms_spread: Option<Spread>,
    /// CPU assignment time over the same frames.
    pub assign_ms_spread: Option<Spread>,
}

/// The scene's lights and what became of them.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct LightStats {
    /// Lights in the scene.
    #[serde(rename = "lights")]
    pub total: usize,
    /// Lights uploaded (radius and radiance > 0).
    #[serde(rename = "active_lights")]
    pub active: usize,
    /// Lights that reached the screen (touched at least one cell) with tiled and clustered;
    /// all active lights with forward and deferred, which do not cull by cell; none in a
    /// frame whose lights all lie outside the view (drawn ambient-only, whatever the method).
    #[serde(rename = "visible_lights")]
    pub visible: usize,
    /// Light references dropped by the overflow policy (docs/grid.md), or lights forward left
    /// out beyond its loop cap.
    #[serde(rename = "overflowed_lights")]
    pub overflowed: u64,
    /// `float32` or `rgba8`.
    #[serde(rename = "light_encoding")]
    pub encoding: LightEncoding,
}

/// The cell grid a tiled or clustered frame used.
#[derive(Clone, Debug, Default, Serialize)]
pub struct GridStats {
    /// Cell footprint in pixels (`None` without a grid).
    #[serde(rename = "grid_footprint_px")]
    pub footprint_px: Option<f64>,
    /// Cells (0 without a grid).
    #[serde(rename = "grid_cells")]
    pub cells: u32,
    /// Why the grid is what it is: the automatic choice's prediction and costs, or the fixed
    /// setting.
    #[serde(rename = "grid_reason")]
    pub reason: Option<String>,
}

/// What a frame uploaded and what GPU memory its method holds.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct MemoryStats {
    /// Bytes uploaded for the frame: the method's light data (records, grids, index lists) and
    /// the copies of huge triangles split near the eye (made again when the camera, the
    /// viewport or an object moved). A scene's meshes and images, uploaded the first time a
    /// frame shows them, are in `scene_upload_bytes` instead.
    pub upload_bytes: usize,
    /// Bytes uploaded per frame over the timed frames of an animated sequence (lights that
    /// move change what is uploaded): the command line's animated runs fill it; the library's
    /// frames leave it `None`.
    pub upload_bytes_spread: Option<Spread>,
    /// GPU bytes of the meshes and images the frame uploaded because no earlier frame had
    /// (mipmaps included, and mipmaps made for an image first sampled without): a scene's
    /// whole content on its first frame, then 0 unless the application made one anew (a mesh
    /// rebuilt every frame, a new `Arc` of the same data, shows here every frame) or an object
    /// first samples a texture (a material it changed to, a coordinate set no texture had
    /// read, uploaded with its mesh again).
    pub scene_upload_bytes: usize,
    /// GPU memory held by the method.
    pub method_gpu_bytes: usize,
    /// G-buffer memory (deferred only; 0 otherwise), of both sizes where frames draw two
    /// views of two sizes (a split screen: the other size's is kept for 8 calls).
    pub gbuffer_bytes: usize,
    /// GPU memory of the multisampled target (0 without MSAA), of both sizes where frames
    /// draw two views of two sizes.
    pub msaa_bytes: usize,
    /// GPU memory of the uploaded meshes and images (mipmaps included), this frame's scene's
    /// and those of earlier scenes the game still holds
    /// ([`Renderer::free_unused_uploads`](super::Renderer::free_unused_uploads) frees them).
    pub scene_gpu_bytes: usize,
    /// Shader programs (variants) the renderer holds after the frame, built for this frame
    /// or earlier ones ([`Renderer::free_unused_programs`](super::Renderer::free_unused_programs)
    /// frees those no recent frame drew with).
    pub shader_programs: usize,
}

impl Default for FrameStats {
    /// Empty figures: what [`Renderer::render_reusing`](super::Renderer::render_reusing) fills
    /// in (a game keeps one and passes it every frame).
    fn default() -> Self {
        FrameStats {
            method: String::new(),
            support: Support::default(),
            auto_choice: None,
            auto_reason: None,
            context: ContextStats::default(),
            width: 0,
            height: 0,
            samples: 1,
            depth_bits: 24,
            triangles: 0,
            draw_calls: 0,
            programs_built: 0,
            scene_features: SceneFeatures::default(),
            time: TimeStats::default(),
            lights: LightStats::default(),
            assignment: AssignStats::default(),
            lists_reused: false,
            grid: GridStats::default(),
            memory: MemoryStats::default(),
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
        let frame_spread = Spread::of(frames.iter().map(|s| s.time.frame_ms));
        let assign_spread = Spread::of(frames.iter().map(|s| s.time.assign_ms));
        let gpu_ms = frames
            .iter()
            .map(|s| s.time.gpu_ms)
            .collect::<Option<Vec<f64>>>()
            .and_then(Spread::of)
            .map(|s| s.p50);
        let mut last = frames.pop()?;
        let time = &mut last.time;
        time.frame_ms = frame_spread.map_or(time.frame_ms, |s| s.p50);
        time.assign_ms = assign_spread.map_or(time.assign_ms, |s| s.p50);
        time.gpu_ms = gpu_ms;
        time.frame_ms_spread = frame_spread;
        time.assign_ms_spread = assign_spread;
        Some(last)
    }
}
