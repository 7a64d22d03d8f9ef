//! Warnings, once a renderer, about the camera's depth range: a depth buffer too coarse at the
//! scene's far content (surfaces closer together in depth than its step show the one behind on
//! some pixels, in every method alike, so comparing methods with forward cannot see it), and a
//! far plane `f32` cannot place (docs/precision.md).

use crate::scene::{Camera, Projection};

/// The largest depth step, as a share of the far content's distance, left unsaid.
const QUIET_SHARE: f64 = 0.01;

/// Warns (once: `warned`) when the depth step of a `bits`-bit depth buffer at `content_far`
/// passes [`QUIET_SHARE`] of it.
pub(super) fn warn_of_coarse_depth(
    camera: &Camera,
    content_far: f64,
    bits: u32,
    warned: &mut bool,
) {
    if *warned {
        return;
    }
    let step = camera.depth_step_at(content_far, bits);
    if step.is_nan() || step <= QUIET_SHARE * content_far {
        return;
    }
    *warned = true;
    let (near, far) = camera.near_far();
    let what = match camera.projection {
        Projection::Perspective { .. } => format!("camera.near {near:e}"),
        Projection::Orthographic { .. } => {
            format!("the orthographic depth range ({near:e} to {far:e})")
        }
    };
    log::warn!(
        "{what} leaves the {bits}-bit depth buffer a step of {step:.3e} at the scene's farthest content \
         ({content_far:.3e} away): surfaces closer together in depth than that may show the \
         one behind, whatever the method; a near plane as far out (or, orthographic, a depth \
         range as tight) as the scene allows fixes it (docs/precision.md)"
    );
}

/// Warns (once: `warned`) when the camera's far plane lies so many near planes out that the
/// GPU's `f32` projection may clip nothing there: geometry past it is drawn and lit.
pub(super) fn warn_of_unclipped_far(camera: &Camera, warned: &mut bool) {
    let Projection::Perspective { near, far, .. } = camera.projection else {
        return;
    };
    if *warned || !camera.has_unclipped_far() {
        return;
    }
    *warned = true;
    log::warn!(
        "camera.far {far:e} is {:.1e} times camera.near {near:e}: past about 4e6 a 32-bit \
         float projection has no far plane to clip at, so geometry beyond camera.far is drawn \
         and lit; a larger near plane keeps it (docs/precision.md)",
        far / near
    );
}
