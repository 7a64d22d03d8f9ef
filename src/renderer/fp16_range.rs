//! What a device without fragment `highp` can place: its view-space positions are fp16
//! (largest 65 504), so the frame's visible geometry and the lights that reach it must lie
//! within that range of the eye, light-to-surface differences included. A frame past it is
//! refused naming the field to change; lights past it that reach nothing visible are left out
//! (exactly what they add).

use super::frame_setup::overwrite_lights;
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
/// reaches it (naming the light), and warns of radii fp16 caps where that shows. Returns how
/// far from the eye a light may lie when some lie farther (reaching nothing: they are to be
/// left out, see [`placeable`]); `None` when every light is placed.
pub(super) fn check(
    caps: &Caps,
    scene: &Scene,
    lights: &[GpuLight],
    reach: f64,
) -> Result<Option<f64>, Error> {
    if caps.fragment_has_highp() {
        return Ok(None);
    }
    if reach > MAX_FP16_VIEW_REACH {
        // Where `f32` cannot place the far plane, it clips nothing: the near plane is the cause.
        let remedy = if scene.camera.has_unclipped_far() {
            "a larger camera.near, which gives the projection a far plane to clip at"
        } else {
            "bring camera.far closer"
        };
        return Err(Error::Limit(format!(
            "camera.far: without fragment highp view-space positions are fp16, but the \
             visible scene reaches {reach:.3e} from the camera, past {MAX_FP16_VIEW_REACH}; \
             {remedy} (or scale the scene down)"
        )));
    }
    let farthest = MAX_FP16_SPAN - reach;
    if lights.iter().all(|l| placeable(l, farthest)) {
        warn_of_capped_radii(lights.iter(), reach);
        return Ok(None);
    }
    // The gathered lights are the scene's active ones in order: name the scene's index.
    let active = scene
        .lights
        .iter()
        .enumerate()
        .filter(|(_, l)| l.is_active());
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
    warn_of_capped_radii(lights.iter().filter(|l| placeable(l, farthest)), reach);
    Ok(Some(farthest))
}

/// Whether a light lies within `farthest` of the eye (as [`check`] returned it).
fn placeable(light: &GpuLight, farthest: f64) -> bool {
    (light.position.length() as f64) <= farthest
}

/// The lights a frame draws when [`check`] leaves some out: kept between frames and compared
/// as the gathered ones are, so that a still frame stays one.
#[derive(Default)]
pub(super) struct PlacedLights {
    lights: Vec<GpuLight>,
    leaving_out: bool,
}

impl PlacedLights {
    /// Gives back what a burst of lights grew the kept lights to.
    pub(super) fn fit_buffers(&mut self) {
        crate::cluster::headroom::fit(&mut self.lights);
    }

    /// Takes in this frame's gathered lights and what [`check`] returned for them. Returns
    /// whether the lights drawn may differ from the last frame's beyond the gathered ones'
    /// own changes.
    pub(super) fn update(&mut self, gathered: &[GpuLight], farthest: Option<f64>) -> bool {
        match farthest {
            None => std::mem::take(&mut self.leaving_out),
            Some(farthest) => {
                let placed = gathered.iter().filter(|l| placeable(l, farthest)).copied();
                let changed = overwrite_lights(&mut self.lights, placed);
                changed | !std::mem::replace(&mut self.leaving_out, true)
            }
        }
    }

    /// The lights the frame draws: `gathered`, or those of them it can place.
    pub(super) fn of<'a>(&'a self, gathered: &'a [GpuLight]) -> &'a [GpuLight] {
        if self.leaving_out {
            &self.lights
        } else {
            gathered
        }
    }
}

/// Largest value fp16 holds: a larger radius reads as this in a mediump shader.
const FP16_MAX: f64 = 65504.0;

/// Whether a light's radius was found past [`FP16_MAX`] where it changes the picture (said once
/// a process: a warning per frame would flood a game's log).
static WARNED_CAPPED_RADIUS: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// How far from a light the visible geometry may lie: its distance from the eye plus the reach.
fn farthest_lit(l: &GpuLight, reach: f64) -> f64 {
    (l.position.length() as f64 + reach).min(l.radius as f64)
}

/// How much darker the window of a light of radius `r` is `d` away when fp16 holds the radius
/// as [`FP16_MAX`] (0 for radii it holds).
fn capped_radius_error(r: f64, d: f64) -> f64 {
    if r <= FP16_MAX {
        0.0
    } else {
        window(d, r) - window(d, FP16_MAX)
    }
}

/// The light model's window `(1 − (d/r)⁴)²` (0 past the radius).
fn window(d: f64, r: f64) -> f64 {
    let q = d / r;
    if q >= 1.0 {
        0.0
    } else {
        (1.0 - q.powi(4)).powi(2)
    }
}

/// Warns (once) of a light whose radius fp16 caps at [`FP16_MAX`] while it reaches geometry
/// far enough that the capped window differs from the true one by more than 1/255.
fn warn_of_capped_radii<'a>(lights: impl Iterator<Item = &'a GpuLight>, reach: f64) {
    use std::sync::atomic::Ordering;
    if WARNED_CAPPED_RADIUS.load(Ordering::Relaxed) {
        return;
    }
    for l in lights {
        let (r, d) = (l.radius as f64, farthest_lit(l, reach));
        let error = capped_radius_error(r, d);
        if error > 1.0 / 255.0 {
            WARNED_CAPPED_RADIUS.store(true, Ordering::Relaxed);
            log::warn!(
                "without fragment highp a light radius is held in fp16: radius {r:.3e} acts as \
                 {FP16_MAX}, and this light's falloff {d:.0} away is {:.0}% too dark (keep \
                 radii under {FP16_MAX} or lights within a few thousand of what they light)",
                100.0 * error / window(d, r).max(f64::MIN_POSITIVE)
            );
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_capped_radius_matters_only_far_from_the_light() {
        // The red-team case: 59 000 from the plane, radius 10⁵: far too dark.
        assert!(capped_radius_error(1e5, 59000.0) > 0.5);
        // A lamp with a huge radius lighting a room a few hundred units across: exact enough.
        assert!(capped_radius_error(1e6, 500.0) < 1e-6);
        assert!(capped_radius_error(1e12, 3000.0) < 1.0 / 255.0);
        assert_eq!(capped_radius_error(6e4, 59000.0), 0.0);
    }
}
