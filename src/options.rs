//! Per-call rendering options: what a caller asks of a frame. Below the shading methods and
//! the renderer, which both read them.

use serde::Serialize;

use crate::cluster::grid::GridConfig;
use crate::cluster::tiles::TILE_PX;
// Defined beside its CPU twin in the scene layer, which may not import options.
pub use crate::scene::shading::ToneMap;

/// Most frames one call times ([`MeasureOptions::timed_frames`], `render --frames`): each
/// timed frame's figures are kept until the percentiles are taken, so a count near 2³² would
/// grow memory for as long as it ran (65 536 frames are 18 minutes at 60 frames a second).
pub const MAX_TIMED_FRAMES: u32 = 1 << 16;

/// Largest [`RenderOptions::exposure_ev`] either way, in stops: 2¹⁵ is what fp16 holds, on
/// devices without fragment highp.
pub const MAX_EXPOSURE_EV: f32 = 15.0;

/// What a frame clears of its rectangle before drawing ([`RenderOptions::clear`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub enum Clear {
    /// Colour (to [`RenderOptions::clear_color`]) and depth: the frame alone.
    #[default]
    All,
    /// Depth only: the frame draws over the colour already there (a sky drawn first), which
    /// shows wherever no object is.
    Depth,
    /// Nothing: the frame draws over the colour and is depth-tested against the depth already
    /// there (the application's own opaque geometry, drawn first, hides what is behind it).
    Nothing,
}

/// Per-call rendering options.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Write linear values (clamped to [0, 1], no sRGB encoding; exposure and tone map still
    /// apply when set, and are off by default) so pixels can be checked against the light model.
    /// Refused into a framebuffer that encodes sRGB itself, which would encode them.
    pub linear: bool,
    /// Background colour (linear if `linear`, else as stored). Its alpha is what pixels that
    /// show nothing get; a transparent surface in front adds its opacity (`a + a_bg·(1 − a)`)
    /// and blends its colour over the background's, so over a transparent black background
    /// the image's colour is premultiplied by its alpha.
    pub clear_color: [f32; 4],
    /// Cluster grid of the clustered method.
    pub grid: GridConfig,
    /// Tile size in pixels of the tiled method.
    pub tile_px: f64,
    /// Wait for the GPU (`glFinish`) at the end of [`Renderer::render`](crate::Renderer::render) so `frame_ms` is the
    /// frame's time (the renderer's own MSAA resolve included). Offscreen
    /// rendering and benchmarks want this, and it is the default; a game presenting to a
    /// window sets it to `false` and `frame_ms` is then the CPU submission time only.
    pub wait_for_gpu: bool,
    /// Time the frame's GL work on the GPU with `GL_EXT_disjoint_timer_query` where the
    /// context has it (`FrameStats::time::gpu_ms`; the automatic grid's shading cost when the
    /// frame does not wait). Reading the extension's disjoint flag clears it: an application
    /// that times its own work with the extension sets this to `false`, or it may miss a
    /// disjoint event. A frame inside the application's own elapsed-time query goes untimed.
    pub gpu_timer: bool,
    /// Write linear, unclamped radiance (for float targets; see
    /// [`Renderer::render_offscreen_hdr`](crate::Renderer::render_offscreen_hdr)). A
    /// fixed-point framebuffer clamps it to [0, 1], which a renderer warns of once.
    pub hdr: bool,
    /// What the frame writes: colour, or per-pixel light counts (see
    /// [`Renderer::render_light_counts`](crate::Renderer::render_light_counts), which sets this).
    pub count: CountKind,
    /// Light cut-off in linear radiance: each light is culled (assigned to cells, or given a
    /// proxy volume) only out to where its contribution falls below this, instead of to its
    /// radius, trading error for time (tiled, clustered, deferred; forward loops over every
    /// light regardless). `None`: cull at the radius, exactly.
    pub light_cutoff: Option<f32>,
    /// Lights at which [`CountKind::Heatmap`]'s colour map tops out (1 or more).
    pub heat_scale: f32,
    /// The tone map applied to the exposed radiance before it is clamped and encoded (not in
    /// HDR output). [`ToneMap::None`], the default, keeps images the light model's own.
    pub tone_map: ToneMap,
    /// Exposure in stops: radiance is multiplied by 2^`exposure_ev` before the tone map.
    /// Within ±[`MAX_EXPOSURE_EV`]. Not in HDR output, which is the light model's radiance.
    pub exposure_ev: f32,
    /// Samples per pixel: 1 (the default) or 0 for none, up to `GL_MAX_SAMPLES` for MSAA (GL
    /// rounds a count the implementation lacks up: `FrameStats::samples` says what it drew).
    /// The frame is drawn into the renderer's multisampled target and resolved into the
    /// framebuffer that was bound, whose depth buffer it leaves as it was (ES 3.0, and ES 2.0
    /// with `GL_EXT_multisampled_render_to_texture`; forward, tiled, clustered and auto; not
    /// deferred, not HDR output; light counts are never multisampled). A bound framebuffer
    /// that is multisampled itself is drawn into directly. The target is kept while frames
    /// use it and freed at the first frame that does not (a game that draws some views with
    /// MSAA and some without keeps a renderer for each).
    pub samples: u32,
    /// What [`Renderer::render`](crate::Renderer::render) clears of its rectangle before it
    /// draws: everything (the default), or only depth, or nothing, so the frame draws over
    /// what the application drew first (a sky; its own opaque geometry, which then hides what
    /// lies behind it); its colour and alpha then stay wherever no surface is drawn, in place
    /// of `clear_color`. For a single-sampled frame in the application's framebuffer (or one
    /// multisampled itself): the renderer's own MSAA target has nothing to keep and refuses
    /// it, and an offscreen render ignores it, as it ignores `origin`.
    pub clear: Clear,
    /// Where the frame's lower-left corner lies in the bound framebuffer, in pixels:
    /// [`Renderer::render`](crate::Renderer::render) draws into the `width × height` rectangle
    /// from there and leaves the rest of the framebuffer as it was (split screen, a view beside
    /// an editor's panel). `[0, 0]` by default. The offscreen renders ignore it: their image is
    /// the frame.
    pub origin: [u32; 2],
    /// Most threads the CPU light assignment (tiled, clustered) takes from rayon's pool, the
    /// calling thread included: 1 keeps it on the calling thread and never enters rayon (for a
    /// game whose own rayon jobs fill the pool: an assignment waits for a worker of the pool
    /// it shares, README "Embedding"). At most 8 are used whatever this says; the pool's
    /// size, and a measure of whether more threads pay, decide below that. 0 is refused.
    pub max_assign_threads: usize,
    /// Knobs for measuring and testing the renderer (timed frames, forced encodings, caps that
    /// exercise the overflow policy); a game leaves them at their defaults.
    pub measure: MeasureOptions,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            linear: false,
            clear_color: [0.0, 0.0, 0.0, 1.0],
            grid: GridConfig::default(),
            tile_px: TILE_PX,
            wait_for_gpu: true,
            gpu_timer: true,
            hdr: false,
            count: CountKind::None,
            light_cutoff: None,
            heat_scale: 64.0,
            tone_map: ToneMap::None,
            exposure_ev: 0.0,
            samples: 1,
            clear: Clear::All,
            origin: [0, 0],
            max_assign_threads: crate::cluster::assign::MAX_ASSIGN_THREADS,
            measure: MeasureOptions::default(),
        }
    }
}

/// What the benchmarks and tests turn to measure the renderer: each default is what a game
/// wants.
#[derive(Clone, Copy, Debug, Default)]
pub struct MeasureOptions {
    /// Frames timed after one warm-up frame by [`Renderer::render_offscreen`](crate::Renderer::render_offscreen); the median is
    /// reported. 0 times the single (cold) frame. At most [`MAX_TIMED_FRAMES`] (the frames'
    /// figures are kept for the percentiles): more is refused naming `timed_frames`. Each timed
    /// frame assigns and uploads its light lists as a frame of moving lights does, where
    /// frames of a still scene would reuse the last ones ([`FrameStats::lists_reused`](crate::FrameStats::lists_reused)).
    pub timed_frames: u32,
    /// Pack lights as RGBA8 even where float textures exist (to measure the packing error).
    pub force_rgba8_lights: bool,
    /// Most lights per cell (tiled/clustered); ES 2.0 never exceeds 4 095 (its shader's loop
    /// bound). `None`: no cap beyond the encoding's. With `auto`, a frame that overflows it
    /// is drawn by forward where forward holds every light (at most 8 192).
    pub cell_cap: Option<u32>,
    /// Most indices in a frame's light lists (tiled/clustered); `None`: what the index texture
    /// holds. Lower values exercise the overflow policy.
    pub max_indices: Option<usize>,
    /// Evaluate the light model's mediump tier at highp as well (the `reference_precision`
    /// variant): the reference image error is measured against. Off, colour factors run at
    /// mediump as a mobile build wants (see `glsl/light_model.glsl`).
    pub reference_precision: bool,
    /// Compile every variant with spot code, and every object's with the shared surface
    /// variant a scene of too many material variants takes (texture, specular, emission,
    /// occlusion and metallic-roughness maps, texture transforms and vertex colours, with
    /// neutral values where the object lacks them) — to measure what leaving features out
    /// saves, and to test that it changes nothing in the image.
    pub full_variants: bool,
}

/// Per-pixel light counts instead of colour.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CountKind {
    /// Colour (a normal frame).
    #[default]
    None,
    /// Lights the method evaluates per pixel (its loop length, or its proxy volumes there).
    Evals,
    /// Lights whose sphere (and cone) reaches the pixel's surface point: the lower bound of
    /// any culling, evaluated by a plain-forward pass whatever the method.
    Reaching,
    /// `Evals` drawn through a colour map (viridis, 0 to [`RenderOptions::heat_scale`]
    /// lights) into whatever target is bound, for looking at: the viewer's heatmap.
    Heatmap,
}
