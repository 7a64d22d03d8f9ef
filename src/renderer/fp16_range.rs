//! What a device without fragment `highp` can place: its view-space positions are fp16
//! (largest 65 504), so the frame's visible geometry and the lights that reach it must lie
//! within that range of the eye, light-to-surface differences included. A frame past it is
//! refused naming the field to change; lights past it that reach nothing visible are left out
//! (exactly what they add).

use crate::cluster::view_light::GpuLight;
use crate::gl::Caps;
use crate::scene::{Projection, Scene};
use crate::Error;

/// Farthest from the eye visible geometry may be without fragment `highp`.
pub const MAX_FP16_VIEW_REACH: f64 = 32768.0;

/// Largest light-to-eye plus surface-to-eye distance: fp16's 65 504 with a margin.
const MAX_FP16_SPAN: f64 = 60000.0;

/// How far from the eye visible geometry reaches: the frustum's corners at `content_far`
/// (the deepest geometry, already clipped to the far plane).
pub(super) fn view_reach(scene: &Scene, aspect: f64, content_far: f64) -> f64 {
    match scene.camera.projection {
        Projection::Perspective { fov_y_deg, .. } => {
            let t = (fov_y_deg.to_radians() * 0.5).tan();
            content_far * (1.0 + t * t * (1.0 + aspect * aspect)).sqrt()
        }
        Projection::Orthographic { height, .. } => {
            let h = height * 0.5;
            (content_far * content_far + h * h * (1.0 + aspect * aspect)).sqrt()
        }
    }
}

/// Without fragment `highp`: refuses a frame whose visible geometry reaches past
/// [`MAX_FP16_VIEW_REACH`] (naming `camera.far`) or with a light too far to place that
/// reaches it (naming the light); drops the lights too far to place that reach nothing.
pub(super) fn check(
    caps: &Caps,
    scene: &Scene,
    lights: &mut Vec<GpuLight>,
    reach: f64,
) -> Result<(), Error> {
    if caps.fragment_has_highp() {
        return Ok(());
    }
    if reach > MAX_FP16_VIEW_REACH {
        return Err(Error::Limit(format!(
            "camera.far: without fragment highp view-space positions are fp16, but the \
             visible scene reaches {reach:.3e} from the camera, past {MAX_FP16_VIEW_REACH}; \
             bring camera.far closer (or scale the scene down)"
        )));
    }
    let farthest = MAX_FP16_SPAN - reach;
    let placeable = |l: &GpuLight| (l.position.length() as f64) <= farthest;
    if lights.iter().all(placeable) {
        return Ok(());
    }
    // The gathered lights are the scene's active ones in order: name the scene's index.
    let active = scene.lights.iter().enumerate().filter(|(_, l)| l.is_active());
    for ((i, _), l) in active.zip(lights.iter()) {
        let distance = l.position.length() as f64;
        if distance > farthest && distance - (l.radius as f64) < reach {
            return Err(Error::Limit(format!(
                "lights[{i}]: without fragment highp view-space positions are fp16, but this \
                 light is {distance:.3e} from the camera (past {farthest:.0} with the scene \
                 {reach:.0} deep) and reaches what is in view; bring it closer or scale the \
                 scene down"
            )));
        }
    }
    lights.retain(placeable);
    Ok(())
}
