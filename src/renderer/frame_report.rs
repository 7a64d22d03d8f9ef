//! A drawn frame's figures written into its [`FrameStats`], reusing the texts it holds (a
//! reused `FrameStats` costs no allocation per frame).

use super::stats::{copy_opt_str, copy_str, copy_support};
use super::stats::{LightStats, MemoryStats, TimeStats};
use super::FrameStats;
use crate::gl::Caps;
use crate::methods::{MethodStats, ShaderFeatures, Support};
use crate::scene::features::SceneFeatures;
use crate::scene::Scene;

/// What a frame drew and with what, gathered where it was drawn.
pub(super) struct DrawnFrame<'a> {
    /// The method whose shaders drew the colours (forward for a reaching-count pass).
    pub method_name: &'a str,
    pub support: &'a Support,
    pub caps: &'a Caps,
    pub lp_num_threads: Option<&'a str>,
    pub size: (u32, u32),
    pub scene: &'a Scene,
    pub scene_features: SceneFeatures,
    pub features: ShaderFeatures,
    /// Lights after gathering (active ones), and whether any reached the view.
    pub active_lights: usize,
    pub lit: bool,
    pub frame_ms: f64,
    pub gpu_ms: Option<f64>,
    pub method: &'a MethodStats<'a>,
    /// Bytes the split copies of long triangles uploaded.
    pub split_bytes: usize,
    pub scene_upload_bytes: usize,
    pub scene_gpu_bytes: usize,
}

impl FrameStats {
    /// Writes `frame`'s figures; the caller adds the method's GPU memory, the draw calls and
    /// the programs, and the MSAA figures where it drew through its own target.
    pub(super) fn record(&mut self, frame: &DrawnFrame<'_>) {
        let m = frame.method;
        let assignment = m.assign.unwrap_or_default();
        let grid = m.grid.as_ref();
        copy_str(&mut self.method, frame.method_name);
        copy_support(&mut self.support, frame.support);
        copy_opt_str(&mut self.auto_choice, m.auto_choice.map(|(c, _)| c));
        copy_opt_str(&mut self.auto_reason, m.auto_choice.map(|(_, r)| r));
        let context = &mut self.context;
        context.es = frame.caps.es;
        copy_str(&mut context.gl_version, &frame.caps.gl_version);
        copy_str(&mut context.renderer, &frame.caps.renderer);
        copy_opt_str(&mut context.lp_num_threads, frame.lp_num_threads);
        (self.width, self.height) = frame.size;
        self.samples = 1;
        let objects = frame.scene.objects.iter();
        self.triangles = objects.map(|o| o.mesh.triangle_count()).sum();
        self.scene_features = frame.scene_features;
        self.time = TimeStats {
            frame_ms: frame.frame_ms,
            gpu_ms: frame.gpu_ms,
            assign_ms: m.assign_ms.unwrap_or(0.0),
            frame_ms_spread: None,
            assign_ms_spread: None,
        };
        self.lights = LightStats {
            total: frame.scene.lights.len(),
            active: frame.active_lights,
            visible: match m.assign {
                _ if !frame.lit => 0,
                Some(a) => a.visible_lights,
                None => frame.active_lights,
            },
            overflowed: assignment.overflowed_lights + m.dropped_lights,
            encoding: frame.features.light_encoding(),
        };
        self.assignment = assignment;
        self.lists_reused = m.lists_reused;
        self.grid.footprint_px = grid.map(|g| g.footprint_px);
        self.grid.cells = grid.map_or(0, |g| g.cells);
        copy_opt_str(&mut self.grid.reason, grid.map(|g| g.reason));
        self.memory = MemoryStats {
            upload_bytes: m.upload_bytes + frame.split_bytes,
            upload_bytes_spread: None,
            scene_upload_bytes: frame.scene_upload_bytes,
            method_gpu_bytes: 0,
            gbuffer_bytes: m.gbuffer_bytes,
            msaa_bytes: 0,
            scene_gpu_bytes: frame.scene_gpu_bytes,
            shader_programs: 0,
        };
    }
}
