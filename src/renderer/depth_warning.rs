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
        "camera.far {far:e} is {} times camera.near {near:e}: past about 4e6 a 32-bit \
         float projection has no far plane to clip at, so geometry beyond camera.far is drawn \
         and lit; a larger near plane keeps it (docs/precision.md)",
        quotient(far, near)
    );
}

/// `a / b` (both positive and finite) in scientific notation, also where it passes `f64`'s
/// range (`1e308 / 1e-300`: `1.0e608`, not `inf`).
fn quotient(a: f64, b: f64) -> String {
    let q = a / b;
    if q.is_finite() {
        return format!("{q:.1e}");
    }
    let exponent = a.log10() - b.log10();
    let (mut whole, mut mantissa) = (exponent.floor(), 10f64.powf(exponent.fract()));
    // 9.96 would print as 10.0.
    if mantissa >= 9.95 {
        (whole, mantissa) = (whole + 1.0, 1.0);
    }
    format!("{mantissa:.1}e{whole}")
}

#[cfg(test)]
mod tests {
    use super::quotient;

    #[test]
    fn a_quotient_past_f64_is_written_as_one() {
        assert_eq!(quotient(4e7, 2.0), "2.0e7");
        assert_eq!(quotient(1e308, 1e-300), "1.0e608");
        assert_eq!(quotient(f64::MAX, 1e-300), "1.8e608");
        assert_eq!(quotient(9.99e300, 1e-300), "1.0e601");
    }
}
