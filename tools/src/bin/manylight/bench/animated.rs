//! The animated workload of `manylight bench`: lights and camera moving, each method's frame
//! times and its last frame against forward's.

use manylight::methods::Support;
use manylight::scene::{self, Scene};
use manylight::{EsVersion, RenderOptions, Renderer};
use manylight_tools::animated::AnimatedRow;

/// Frames per second of animation time in the animated workload.
const ANIMATED_FPS: f64 = 30.0;

/// The animated workload: the scene's lights moving (the lively default where the scene has
/// no motion of its own) and the camera panning ±8° about its target every 4 s.
pub(super) struct AnimatedWorkload {
    /// Posed by each method's run in turn, never copied: a copy would double the lights'
    /// memory, which the light count's memory check does not allow for.
    scene: Scene,
    /// The camera the pan swings about.
    start: scene::Camera,
    pub(super) name: String,
    size: (u32, u32),
    frames: u32,
}

impl AnimatedWorkload {
    pub(super) fn new(
        mut scene: Scene,
        name: String,
        size: (u32, u32),
        frames: u32,
    ) -> AnimatedWorkload {
        if !scene.is_animated() {
            if let Some(bounds) = scene.bounds() {
                let motion = scene::builtin::lively_motion(&name, &bounds);
                scene.animate_lights(0..scene.lights.len(), motion, 1);
            }
        }
        AnimatedWorkload {
            start: scene.camera,
            scene,
            name,
            size,
            frames,
        }
    }

    /// One method's row; `None` where it cannot run here.
    pub(super) fn run(
        &mut self,
        renderer: &mut Renderer,
        method: &str,
        es: EsVersion,
    ) -> Result<Option<AnimatedRow>, Box<dyn std::error::Error>> {
        let desc = manylight::methods::find(method)?;
        if matches!((desc.supported)(renderer.caps()), Support::Unsupported(_)) {
            return Ok(None);
        }
        // Every frame poses the scene (its time and the camera) before it is drawn.
        let scene = &mut self.scene;
        let start = self.start;
        let mut pose = move |s: &mut Scene, t: f64| {
            s.set_time(t);
            let swing = 8f64.to_radians() * (std::f64::consts::TAU * t / 4.0).sin();
            let turn = glam::DQuat::from_rotation_y(swing);
            s.camera.position = start.target + turn * (start.position - start.target);
        };
        let timeline = crate::sequence::Timeline {
            start_s: 0.0,
            fps: ANIMATED_FPS,
            frames: self.frames,
        };
        renderer.set_method_named(method)?;
        let options = RenderOptions::default();
        let rendered = match crate::sequence::render(
            renderer,
            scene,
            self.size,
            &options,
            &timeline,
            &mut pose,
            crate::sequence::Keep::Last,
        ) {
            Ok(r) => r,
            // Past a method's limits (forward's loop bound, say): skipped, as in the sweep.
            Err(e) if matches!(e.downcast_ref(), Some(manylight::Error::Limit(_))) => {
                log::warn!("{} animated {method}: skipped: {e}", self.name);
                return Ok(None);
            }
            Err(e) => return Err(e),
        };
        let stats = rendered.stats;
        // The last frame against plain forward at the same time (scene already posed there).
        let error = if method == "forward" {
            None
        } else {
            renderer.set_method_named("forward")?;
            let (w, h) = self.size;
            let (reference, _) = renderer.render_offscreen(scene, w, h, &options)?;
            let last = rendered.last.as_ref().unwrap_or(&rendered.first);
            Some(manylight::metrics::diff(&reference, last).max_abs)
        };
        let (Some(frame_ms), Some(assign_ms), Some(upload_bytes)) = (
            stats.time.frame_ms_spread,
            stats.time.assign_ms_spread,
            stats.memory.upload_bytes_spread,
        ) else {
            return Ok(None);
        };
        Ok(Some(AnimatedRow {
            scene: self.name.clone(),
            method: method.to_string(),
            es: format!("{}.0", es.major()),
            lights: scene.lights.len(),
            width: self.size.0,
            height: self.size.1,
            frames: frame_ms.frames,
            fps: ANIMATED_FPS,
            p99_over_p50: AnimatedRow::tail_ratio(&frame_ms),
            frame_ms,
            assign_ms,
            upload_bytes,
            max_abs_err_vs_forward: error,
        }))
    }
}
