//! Shrinking a scene's lights with their motions: `lights` alone cannot be cut while a track
//! moves the lights past the cut, or a track would pose whatever lights take their places.

use super::motion::LightTrack;
use super::{Light, Scene};

impl Scene {
    /// Keeps the lights for which `keep` is true, in order, each with its place in the track
    /// that moves it (a track is cut round the lights it loses; the lights after a gap keep
    /// their own variations), as [`Scene::remove_light`] does for one light, in one pass.
    pub fn retain_lights(&mut self, mut keep: impl FnMut(&Light) -> bool) {
        let kept: Vec<bool> = self.lights.iter().map(&mut keep).collect();
        // Each light's index once the lights before it that go are gone.
        let mut new_index = Vec::with_capacity(kept.len());
        let mut next = 0;
        for &k in &kept {
            new_index.push(next);
            next += usize::from(k);
        }
        let mut tracks = Vec::with_capacity(self.animation.len());
        for track in std::mem::take(&mut self.animation) {
            split_kept(track, &kept, &new_index, &mut tracks);
        }
        self.animation = tracks;
        let mut kept = kept.into_iter();
        self.lights.retain(|_| kept.next().unwrap_or(false));
    }

    /// Keeps the first `len` lights (all of them when there are fewer) and the parts of their
    /// tracks that move them.
    pub fn truncate_lights(&mut self, len: usize) {
        let mut index = 0;
        self.retain_lights(|_| {
            index += 1;
            index <= len
        });
    }
}

/// Pushes onto `out` the runs of `track` whose lights are kept, each as a track of its own
/// placed at the kept lights' new indices. A part of the track past the end of the lights
/// moves nothing and goes.
fn split_kept(track: LightTrack, kept: &[bool], new_index: &[usize], out: &mut Vec<LightTrack>) {
    let LightTrack {
        first,
        rest,
        motion,
        vary,
        variation_start,
    } = track;
    let mut run: Option<LightTrack> = None;
    for (k, light) in rest.into_iter().enumerate() {
        // A track placed (in code) past any index a light can have keeps nothing.
        let Some(i) = first.checked_add(k) else {
            break;
        };
        if kept.get(i).copied().unwrap_or(false) {
            run.get_or_insert_with(|| LightTrack {
                first: new_index[i],
                rest: Vec::new(),
                motion,
                vary,
                variation_start: variation_start.wrapping_add(k),
            })
            .rest
            .push(light);
        } else if let Some(done) = run.take() {
            out.push(done);
        }
    }
    out.extend(run);
}

#[cfg(test)]
mod tests {
    use crate::scene::builtin;

    /// Cutting the lights with their tracks poses every kept light exactly as before, at
    /// every time, and validates; `truncate_lights(0)` leaves no track.
    #[test]
    fn kept_lights_move_as_before() {
        let scene = builtin::build("courtyard", Some((64, 3))).unwrap();
        assert!(!scene.animation.is_empty(), "the built-in's lights move");
        let keep = |i: usize| i % 3 != 1 && !(20..30).contains(&i) && i < 60;
        let mut cut = scene.clone();
        let mut index = 0;
        cut.retain_lights(|_| {
            index += 1;
            keep(index - 1)
        });
        cut.validate().unwrap();
        let kept: Vec<usize> = (0..scene.lights.len()).filter(|&i| keep(i)).collect();
        assert_eq!(cut.lights.len(), kept.len());
        for t in [0.0, 0.7, 3.25] {
            let (mut all, mut some) = (scene.clone(), cut.clone());
            all.set_time(t);
            some.set_time(t);
            for (j, &i) in kept.iter().enumerate() {
                assert_eq!(some.lights[j], all.lights[i], "light {i} at t = {t}");
            }
        }
        let mut none = scene.clone();
        none.truncate_lights(0);
        none.validate().unwrap();
        assert!(none.lights.is_empty() && none.animation.is_empty());
        let mut three = scene;
        three.truncate_lights(3);
        three.validate().unwrap();
        assert_eq!(three.lights.len(), 3);
    }

    /// Tracks whose public indices were set in code near `usize::MAX` neither overflow nor
    /// pose a light they do not move: one placed past every light is dropped by the cuts, and
    /// variation numbers past the top wrap.
    #[test]
    fn tracks_placed_near_the_top_of_usize_neither_overflow_nor_wrap_onto_lights() {
        let mut scene = builtin::build("courtyard", Some((8, 3))).unwrap();
        let mut track = scene.animation[0].clone();
        track.first = usize::MAX - 1;
        track.variation_start = usize::MAX;
        track.vary = Some(5);
        track.rest.truncate(3);
        scene.animation.push(track);
        let before = scene.lights.clone();
        let mut posed = scene.clone();
        posed.set_time(0.0);
        assert_eq!(posed.lights, before, "the stray track posed a light");
        assert!(
            scene.validate().is_err(),
            "a track past the lights validates"
        );
        let mut kept = scene.clone();
        kept.retain_lights(|_| true);
        kept.validate().unwrap();
        assert_eq!(kept.lights, before);
        scene.remove_light(0).unwrap();
        let k = scene.animation.last().unwrap();
        assert_eq!(k.first, usize::MAX - 2);
        assert!(k.motion_of(2).validate("", false).is_ok());
    }
}
