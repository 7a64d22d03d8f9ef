//! The CPU buffers a burst of lights grew (light records, assignment, packed texels) given
//! back once frames have needed a quarter of them at most for `SHRINK_AFTER` frames in a row,
//! as the GPU stores are (`gl::shrink`): an explosion's sparks do not hold megabytes for good.

use crate::gl::shrink::SmallFrames;

/// The most lights frames have drawn since the buffers last fitted them.
#[derive(Default)]
pub(super) struct LightHighWater {
    most: usize,
    small: SmallFrames,
    /// Whether the last frame lit its surfaces with the renderer's method, or with the
    /// reaching-count pass (neither: no light in view): that one's buffers hold its lights.
    pub lit_with: Option<LitWith>,
}

/// What drew a lit frame.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum LitWith {
    Method,
    ReachingPass,
}

impl LightHighWater {
    /// Counts a drawn frame of `lights`: true when the buffers should fit the frames again.
    pub fn note(&mut self, lights: usize) -> bool {
        self.most = self.most.max(lights);
        if self.most == 0 || !self.small.note(lights, self.most) {
            return false;
        }
        self.most = lights;
        self.small.reset();
        true
    }
}

impl super::Renderer {
    /// Gives back what a burst of lights grew the CPU buffers to (see the module).
    pub(super) fn fit_light_buffers(&mut self) {
        let lit_with = self.light_high_water.lit_with;
        self.method.fit_buffers(lit_with == Some(LitWith::Method));
        if let Some(pass) = &mut self.reaching_pass {
            pass.fit_buffers(lit_with == Some(LitWith::ReachingPass));
        }
        crate::cluster::headroom::fit(&mut self.lights);
        self.placed.fit_buffers();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::shrink::SHRINK_AFTER;

    #[test]
    fn buffers_fit_after_a_quarter_for_shrink_after_frames_and_not_before() {
        let mut water = LightHighWater::default();
        assert!(!water.note(0), "no light yet: nothing to give back");
        assert!(!water.note(1000));
        // Half of the peak: not small.
        assert!((0..2 * SHRINK_AFTER).all(|_| !water.note(500)));
        // A quarter: small, and given back at the SHRINK_AFTER-th such frame.
        assert!((1..SHRINK_AFTER).all(|_| !water.note(250)));
        assert!(water.note(250));
        // The peak is now 250: frames of 250 are not small, nor is one back at 1000.
        assert!((0..2 * SHRINK_AFTER).all(|_| !water.note(250)));
        assert!(!water.note(1000));
        // Interrupted by a larger frame, the count starts again.
        assert!((1..SHRINK_AFTER).all(|_| !water.note(10)));
        assert!(!water.note(600));
        assert!((1..SHRINK_AFTER).all(|_| !water.note(10)));
        assert!(water.note(10));
    }
}
