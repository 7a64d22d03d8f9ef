//! Shading methods and the method table.
//!
//! Every method implements [`ShadingMethod`]; [`METHODS`] lists them with their minimum ES
//! version, required extensions and a `supported(&Caps)` check. The CLI, the tests and the
//! capability matrix all iterate this one table.

pub mod auto;
#[cfg(test)]
mod auto_memory_tests;
pub mod capacity;
pub mod clustered;
pub mod culled;
pub mod culled_support;
pub mod deferred;
pub mod directional;
pub mod features;
pub mod forward;
pub mod forward_cap;
pub mod geometry;
mod grid_choice;
pub mod maps;
pub(crate) mod surface_variants;
pub mod tiled;
pub mod uniforms;
mod unseen_lights;

use crate::cluster::grid::{GridProjection, ViewVolume};
use crate::cluster::view_light::GpuLight;
use crate::gl::program::ProgramCache;
use crate::gl::{Caps, Device, EsVersion};
use crate::gpu_scene::GpuScene;
use crate::options::RenderOptions;
use crate::scene::Scene;
use crate::Error;

pub use features::ShaderFeatures;

/// Whether a method can run on a context.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(tag = "status", content = "reason", rename_all = "snake_case")]
pub enum Support {
    /// Runs as designed.
    #[default]
    Supported,
    /// Runs with a documented degradation (the reason says which).
    Fallback(String),
    /// Cannot run; the reason names what is missing.
    Unsupported(String),
}

/// What a frame's timing says, for a method's cost model ([`ShadingMethod::observe_frame`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTiming {
    /// The frame's number, counted by the renderer.
    pub serial: u64,
    /// Wall time of a frame that waited for the GPU (`None` when it did not).
    pub waited_ms: Option<f64>,
    /// GPU time of this frame, or of an earlier one read when it finished: that frame's
    /// number and milliseconds.
    pub gpu: Option<(u64, f64)>,
}

/// Everything a method needs for one frame.
pub struct FrameContext<'a> {
    /// The GL device.
    pub dev: &'a Device,
    /// Shared program cache.
    pub programs: &'a mut ProgramCache,
    /// The scene (objects, materials, ambient).
    pub scene: &'a Scene,
    /// Uploaded meshes and textures of the scene.
    pub gpu_scene: &'a GpuScene,
    /// World → view (`f64`).
    pub view: glam::DMat4,
    /// View → clip.
    pub projection: glam::Mat4,
    /// True for an orthographic camera.
    pub orthographic: bool,
    /// Active lights in view space (radius and radiance > 0).
    pub lights: &'a [GpuLight],
    /// Changes whenever `lights` may differ from the last frame's (the renderer compares them
    /// bit for bit as it gathers them): what a method built from lights of the same
    /// generation, with everything else it depends on unchanged, it may keep.
    pub lights_generation: u64,
    /// The framebuffer the frame is drawn into, bound (`None`: the default one).
    pub target: Option<glow::Framebuffer>,
    /// The frame's directional lights (shaded outside the light lists).
    pub directional: directional::DirectionalFrame,
    /// Scene-level shader features (spots present, output encoding, light encoding).
    pub features: ShaderFeatures,
    /// What the frame's lights, ambient and emission are multiplied by
    /// ([`ShaderFeatures::pre_exposure`]): `lights` and `directional` come so.
    pub pre_exposure: f32,
    /// Viewport size in pixels.
    pub viewport: (u32, u32),
    /// The viewport's lower-left corner in the bound framebuffer (the frame's pixel (0, 0)).
    pub origin: [u32; 2],
    /// Near plane distance.
    pub near: f64,
    /// The farthest view distance the GPU may draw: the far plane, widened by `f32`
    /// rounding ([`Camera::far_clip_range`](crate::scene::Camera::far_clip_range); may be
    /// infinite).
    pub far: f64,
    /// Farthest view depth the scene's geometry reaches, clipped to [near, far]: where a grid
    /// needs to end.
    pub content_far: f64,
    /// Caller's options.
    pub options: &'a RenderOptions,
    /// The frame's objects in draw order (buffers kept between frames: see
    /// [`geometry::DrawOrder`]).
    pub order: &'a mut geometry::DrawOrder,
    /// Draw only the transparent objects (deferred's forward fallback for them).
    pub transparent_only: bool,
    /// The frame is drawn into the renderer's own multisampled target (`RenderOptions::samples`
    /// above 1, not drawn straight into a framebuffer multisampled itself).
    pub own_msaa: bool,
    /// What the frame cleared before it was drawn (`RenderOptions::clear`; everything in an
    /// offscreen render, which ignores it).
    pub clear: crate::options::Clear,
    /// A frame of [`Renderer::warm_up`](crate::Renderer::warm_up): a pass with nothing to draw
    /// this time (a deferred proxy no light takes) still builds its program.
    pub warm_up: bool,
    /// The scene's objects are drawn with the shared surface variants
    /// (`surface_variants::shared`): it asks for more than `MAX_SURFACE_VARIANTS`, or the
    /// options for full variants.
    pub shared_surfaces: bool,
}

impl FrameContext<'_> {
    /// The view from the near plane to the farthest geometry: a light whose sphere lies wholly
    /// outside it lights no pixel of the frame.
    pub fn view_volume(&self) -> ViewVolume {
        let projection = GridProjection::from_matrix(&self.projection.as_dmat4());
        ViewVolume::new(projection, self.near, self.content_far)
    }

    /// How many of the frame's lights reach into [`FrameContext::view_volume`], counted up to
    /// `at_most` (the count stops there, so a frame of many lights in view pays little).
    pub fn lights_in_view(&self, at_most: usize) -> usize {
        let volume = self.view_volume();
        let reaches = |l: &&GpuLight| !volume.excludes(l.position.as_dvec3(), f64::from(l.radius));
        self.lights.iter().filter(reaches).take(at_most).count()
    }
}

/// Which grid a tiled or clustered frame used, and why.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct GridReport<'a> {
    /// Cell footprint in pixels.
    pub footprint_px: f64,
    /// Cells of the grid.
    pub cells: u32,
    /// Why: the automatic choice's prediction, or the fixed setting (the method's own text,
    /// borrowed: a frame makes no string).
    pub reason: &'a str,
}

/// What a method reports about its frame. Its texts are borrowed from the method, so a
/// frame's report allocates nothing; the renderer copies them into the reused
/// [`crate::FrameStats`].
#[derive(Clone, Debug, Default)]
pub struct MethodStats<'a> {
    /// Bytes uploaded to the GPU this frame (light data, grids, index lists).
    pub upload_bytes: usize,
    /// CPU light-assignment time (culling methods).
    pub assign_ms: Option<f64>,
    /// Assignment figures (culling methods).
    pub assign: Option<crate::cluster::assign::AssignStats>,
    /// The frame drew with the method's last lists and uploads (see `FrameStats`).
    pub lists_reused: bool,
    /// G-buffer memory (deferred).
    pub gbuffer_bytes: usize,
    /// The grid the frame used (tiled, clustered).
    pub grid: Option<GridReport<'a>>,
    /// What `auto` picked, and why.
    pub auto_choice: Option<(&'static str, &'a str)>,
    /// Lights left out of the whole frame (forward beyond its loop cap).
    pub dropped_lights: u64,
}

/// A cell grid and the light lists assigned to it.
pub type LightLists<'a> = (
    &'a crate::cluster::grid::ClusterGrid,
    &'a crate::cluster::assign::Assignment,
);

/// A shading method: owns its GPU resources, renders a frame into the bound framebuffer.
pub trait ShadingMethod {
    /// Name as in the table.
    fn name(&self) -> &'static str;
    /// Renders one frame (the framebuffer is bound and cleared by the renderer). In steady
    /// state (buffers grown, shaders built) a frame should allocate nothing on the heap:
    /// keep per-frame buffers in the method and texts in its own strings.
    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats<'_>, Error>;
    /// GPU memory the method holds, in bytes.
    fn gpu_bytes(&self) -> usize;
    /// The grid and light lists of the last frame, for methods that build them.
    fn light_lists(&self) -> Option<LightLists<'_>> {
        None
    }
    /// The frame's time after it was submitted (wall time including the GPU's work when the
    /// frame waited for it; GPU time from a timer query, this frame's or an earlier one's):
    /// methods that calibrate a cost model take it in.
    fn observe_frame(&mut self, _timing: FrameTiming) {}
    /// A frame with no lights, drawn without the method (ambient only): a method that keeps
    /// resources for a number of frames counts it, and frees its large ones after
    /// [`IDLE_FRAMES_KEPT`] in a row.
    fn skip_frame(&mut self, _dev: &Device) {}
    /// Frames have needed a quarter of the lights the CPU buffers were grown for at most, long
    /// enough: they give back what a burst of lights grew them to, keeping the last frame's
    /// contents and room for them where it drew with the method (`in_use`); where it drew
    /// none (no light in view) they are emptied, and the next lit frame makes them anew.
    fn fit_buffers(&mut self, _in_use: bool) {}
    /// Frees the method's GPU resources.
    fn destroy(&mut self, dev: &Device);
}

/// Frames without lights after which a method frees what it holds for lights (deferred's
/// G-buffer and instances, the culled methods' texture ring): two seconds at 60 frames a
/// second, so a light that blinks does not allocate every time; a sun-only stretch of a day
/// cycle gets the memory back. The next lit frame makes them again. Deferred counts frames
/// with nothing opaque to draw likewise, and `auto` the frames each of its methods sat out.
pub const IDLE_FRAMES_KEPT: u32 = 120;

/// Counts an idle frame of a row (`idle` is set to 0 by a frame that used the resources):
/// true from the one that reaches [`IDLE_FRAMES_KEPT`] on, so what was made again after being
/// freed, and is not used, is freed again.
pub(crate) fn idle_for_long(idle: &mut u32) -> bool {
    *idle = idle.saturating_add(1);
    *idle >= IDLE_FRAMES_KEPT
}

/// A row of the method table.
pub struct MethodDesc {
    /// CLI name.
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Lowest ES version it runs on.
    pub min_es: EsVersion,
    /// Extensions it needs beyond `min_es` core (none may be listed when it has fallbacks).
    pub required_extensions: &'static [&'static str],
    /// Whether it runs on a context, and how.
    pub supported: fn(&Caps) -> Support,
    /// Whether it can draw into a multisampled target (MSAA, `RenderOptions::samples`).
    pub multisample: bool,
    /// Builds the method (only called when `supported` is not `Unsupported`).
    pub create: fn(&Device) -> Result<Box<dyn ShadingMethod>, Error>,
}

/// The method table.
pub static METHODS: &[MethodDesc] = &[
    forward::DESC,
    tiled::DESC,
    clustered::DESC,
    deferred::DESC,
    auto::DESC,
];

/// The default method.
pub const DEFAULT_METHOD: &str = "clustered";

/// Finds a method by name.
pub fn find(name: &str) -> Result<&'static MethodDesc, Error> {
    METHODS
        .iter()
        .find(|m| m.name == name)
        .ok_or_else(|| Error::UnknownMethod {
            name: name.to_string(),
            available: METHODS
                .iter()
                .map(|m| m.name)
                .collect::<Vec<_>>()
                .join(", "),
        })
}

#[cfg(test)]
mod idle_tests {
    use super::*;

    #[test]
    fn idle_frames_free_from_the_kept_count_on() {
        let mut idle = 0;
        let freed: Vec<bool> = (0..IDLE_FRAMES_KEPT + 2)
            .map(|_| idle_for_long(&mut idle))
            .collect();
        let first = IDLE_FRAMES_KEPT as usize - 1;
        assert!(freed[..first].iter().all(|&f| !f));
        // Made again and left unused past the count: freed again, not kept for good.
        assert!(freed[first..].iter().all(|&f| f), "{freed:?}");
    }
}
