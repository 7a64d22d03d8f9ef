//! The clustered method's automatic grid ([`crate::cluster::auto_grid`]) wired to frames: when to
//! choose again, where the surface samples come from (a coarse ray cast of the scene, its
//! hierarchy built once per geometry), and the calibration fed by every rendered frame.

use glam::{DMat4, DVec3, DVec4};

use super::{FrameContext, FrameTiming};
use crate::cluster::assign::{AssignLimits, Assigner};
use crate::cluster::auto_grid::{
    self, ChoiceInputs, ChoiceSearch, FrameCost, GridChoice, GridCosts, SurfaceSamples,
};
use crate::cluster::grid::{ClusterGrid, GridConfig, GridProjection};
use crate::cluster::pack::GridEncoding;
use crate::gl::timer::RING as TIMER_RING;
use crate::scene::raycast::{KeptCaster, SceneRaycaster};

/// Rays of the surface sample, across and down (1 296 rays).
const SAMPLE_GRID: (u32, u32) = (48, 27);

/// Rays of the surface sample.
const SAMPLE_RAYS: u32 = SAMPLE_GRID.0 * SAMPLE_GRID.1;

/// Box and triangle tests the surface sample may make ([`SceneRaycaster::hit_within`]):
/// triangles that overlap one another make every ray test most of them, and a 1 MB model of
/// 915 k overlapping chords took 30 s a sample. Past it the rays cast so far are the sample.
const SAMPLE_WORK: u64 = 1 << 22;

/// Step between consecutive rays of the sample through its rays in reading order: prime, so
/// coprime with their count, and near its golden section, so each first part of the rays is
/// spread over the view.
const SAMPLE_STRIDE: u32 = 797;

/// A view or light set that changed is chosen for again after at most this many frames.
const RECHOOSE_AFTER_CHANGE: u32 = 30;

/// A static frame is chosen for again (with the costs calibrated since) this often.
const RECHOOSE_PERIOD: u32 = 240;

/// The first re-choice comes this many frames after the first, once the costs have been
/// calibrated on the device: seven frames, whose median outvotes the slow first frames of a
/// new grid (its buffers growing, its pool threads waking).
const FIRST_CALIBRATED_CHOICE: u32 = 8;

/// The scene's geometry by identity: each object's mesh, transform bits and whether its
/// material is double-sided (the caster hits a single-sided one's front only).
type GeometryKey = Vec<(usize, [u64; 16], bool)>;

/// What makes the current choice stale at once.
#[derive(Clone, Debug, PartialEq)]
struct Layout {
    size: (u32, u32),
    projection: GridProjection,
    near: u64,
    /// The user's grid settings (what the choice does not set).
    base: GridConfig,
    /// The assignment's per-cell cap and index budget (`MeasureOptions`): a choice made
    /// under tight ones lasted hundreds of frames after they were lifted.
    limits: (u32, usize),
}

/// A frame's slot in [`AutoGrid`]'s ring of recent evaluations.
fn ring_slot(serial: u64) -> usize {
    (serial % TIMER_RING as u64) as usize
}

/// The automatic grid's state across frames.
#[derive(Default)]
pub(crate) struct AutoGrid {
    costs: GridCosts,
    choice: Option<GridChoice>,
    layout: Option<Layout>,
    /// View matrix and light count at the last choice.
    view_at_choice: Option<(DMat4, usize)>,
    frames_since_choice: u32,
    choices: u32,
    samples: SurfaceSamples,
    /// Ray caster of the scene's geometry, with the identity of the meshes and transforms it
    /// was built from; kept without its meshes between samples, so those a game drops are
    /// freed at once (their GPU uploads too), not at the next choice.
    caster: Option<(GeometryKey, KeptCaster)>,
    /// The frame rendered and not yet observed.
    pending: Option<FrameCost>,
    /// The last observed frames' numbers and light evaluations, by number modulo the ring:
    /// what a GPU time read a few frames later is set against.
    recent_evals: [Option<(u64, f64)>; TIMER_RING],
    /// The current frame measured a candidate: its time holds the candidate's assignment (and
    /// on the first frame shader compiles), so it calibrates nothing.
    chose_this_frame: bool,
    /// The search over candidate footprints (one per frame while it runs).
    search: ChoiceSearch,
    /// The light count when the running search started.
    lights_at_search_start: usize,
    /// The choice a search finishes into before it is kept or swapped in (its buffers
    /// reused).
    scratch: GridChoice,
    /// The current choice was made with the priors, before any frame was measured.
    choice_from_priors: bool,
    /// A surface sample was cut short by its work bound, and a warning said so.
    sample_cut_said: bool,
    /// The sample's caster left meshes out (memory refused), and a warning said so.
    left_out_said: bool,
    /// Frames since the lights last outgrew a grid ([`AutoGrid::outgrown`]; `None`: never).
    frames_since_outgrown: Option<u32>,
}

impl AutoGrid {
    /// The grid settings for this frame: the current choice, or a new one when it is stale.
    ///
    /// A grid is needed at once on the first frame, when the viewport, projection, near
    /// plane or settings change, and when the lights outgrew the grid
    /// ([`AutoGrid::outgrown`]): those choices measure every candidate in this frame (up to
    /// thirteen assignments; the search's stops usually end it sooner). The others (the view
    /// or the lights moved, the period passed, the costs got calibrated) only refine a grid
    /// that works: they measure one candidate per frame, so no frame pays for many
    /// assignments, and switch when the last is measured.
    ///
    /// The candidates are assigned with `assigner`, the frame's own: its buffers then
    /// already fit whichever candidate is adopted, so a switch to a finer grid does not grow
    /// them (and no second set of buffers is kept). Its last assignment is a candidate's until
    /// the frame assigns.
    pub(crate) fn config(
        &mut self,
        ctx: &FrameContext,
        projection: GridProjection,
        limits: &AssignLimits,
        encoding: GridEncoding,
        assigner: &mut Assigner,
    ) -> &GridChoice {
        let layout = Layout {
            size: ctx.viewport,
            projection,
            near: ctx.near.to_bits(),
            base: ctx.options.grid.clone(),
            limits: (limits.cell_cap, limits.max_indices),
        };
        let inputs = ChoiceInputs {
            size: ctx.viewport,
            projection,
            near: ctx.near,
            far: ctx.content_far,
            camera_far: ctx.far,
            base: ctx.options.grid.clone(),
            lights: ctx.lights,
            limits: *limits,
            encoding,
        };
        self.frames_since_choice += 1;
        if let Some(n) = &mut self.frames_since_outgrown {
            *n = n.saturating_add(1);
        }
        let urgent = self.choice.is_none() || self.layout.as_ref() != Some(&layout);
        if urgent {
            self.sample(ctx);
            self.search.start(&inputs, &self.samples);
            while !self
                .search
                .step(&inputs, &self.samples, &self.costs, assigner)
            {}
            self.conclude(&inputs, layout, ctx);
            self.chose_this_frame = true;
            return self.choice.as_ref().expect("chosen above");
        }
        let moved = self
            .view_at_choice
            .is_none_or(|(view, n)| view != ctx.view || changed_much(n, ctx.lights.len()));
        let due = (moved && self.frames_since_choice >= RECHOOSE_AFTER_CHANGE)
            || (self.choices == 1 && self.frames_since_choice >= FIRST_CALIBRATED_CHOICE)
            || self.frames_since_choice >= RECHOOSE_PERIOD;
        // A search whose candidates would be measured with a light set changed by more than a
        // quarter since its start compares unlike frames: it starts again.
        let stale_search = self.search.in_progress()
            && changed_much(self.lights_at_search_start, ctx.lights.len());
        self.chose_this_frame = self.search.in_progress() || due;
        if (!self.search.in_progress() && due) || stale_search {
            self.sample(ctx);
            self.search.start(&inputs, &self.samples);
            self.lights_at_search_start = ctx.lights.len();
        }
        if self.chose_this_frame
            && self
                .search
                .step(&inputs, &self.samples, &self.costs, assigner)
        {
            self.conclude(&inputs, layout, ctx);
        }
        self.choice.as_ref().expect("chosen on the first frame")
    }

    /// Whether the current grid no longer lists the frame's lights, so that the frame must
    /// choose again at once: its assignment dropped `dropped` light references (`u64::MAX`:
    /// could not list them), where the grid's own measurement when it was chosen dropped none.
    /// The lights changed under it (a few small lights became many large ones), and waiting
    /// for the re-choice after a change would fail or darken every frame until then. The next
    /// [`AutoGrid::config`] then chooses at once, as for a new viewport, measuring every
    /// candidate with this frame's lights: the grid it takes drops what its measurement says,
    /// so it is not outgrown in turn. A grid chosen although it overflowed (every candidate
    /// did), or without a measurement of its own, is kept until its re-choice is due. Lights
    /// moving about the edge of what a grid lists would make every frame such a search: one
    /// that drops references chooses again at most once in [`RECHOOSE_AFTER_CHANGE`] frames
    /// (one that cannot list them, and so would fail, always).
    pub(crate) fn outgrown(&mut self, dropped: u64) -> bool {
        let Some(choice) = &self.choice else {
            return false;
        };
        let chosen = choice.config.footprint_px;
        let fitted = choice
            .candidates
            .iter()
            .find(|c| c.footprint_px == chosen)
            .is_some_and(|c| c.overflowed_lights == 0);
        let lately = self
            .frames_since_outgrown
            .is_some_and(|n| n < RECHOOSE_AFTER_CHANGE);
        let outgrown = dropped > 0 && fitted && (dropped == u64::MAX || !lately);
        if outgrown {
            self.layout = None;
            self.frames_since_outgrown = Some(0);
        }
        outgrown
    }

    /// Whether this frame's [`AutoGrid::config`] measured candidates, with the assigner it was
    /// given (whose last assignment is then a candidate's).
    pub(crate) fn measured_candidates(&self) -> bool {
        self.chose_this_frame
    }

    /// Ends the search: its choice replaces the current grid unless the hysteresis keeps it.
    /// Written through kept buffers (the scratch choice, the current one's reason and
    /// candidates), so a re-choice allocates nothing once they have grown.
    fn conclude(&mut self, inputs: &ChoiceInputs, layout: Layout, ctx: &FrameContext) {
        use std::fmt::Write as _;
        let new = &mut self.scratch;
        self.search
            .finish_into(inputs, &self.samples, &self.costs, new);
        let same_layout = self.layout.as_ref() == Some(&layout);
        // A grid chosen with the priors was not chosen with this device's figures: the first
        // calibrated choice replaces it without the hysteresis (once, so no flip-flop).
        let replaces_priors = first_calibrated(&mut self.choice_from_priors, self.costs.frames > 0);
        match &mut self.choice {
            Some(current)
                if same_layout
                    && !replaces_priors
                    && !auto_grid::should_switch(&current.config, new) =>
            {
                // The grid stays; the reason says it was measured again.
                current.reason.clear();
                if current.config.footprint_px != new.config.footprint_px {
                    let _ = write!(
                        current.reason,
                        "kept {} px (predicted within {:.0} % of the best): ",
                        current.config.footprint_px,
                        auto_grid::HYSTERESIS * 100.0,
                    );
                }
                current.reason.push_str(&new.reason);
                current.candidates.clear();
                current.candidates.extend_from_slice(&new.candidates);
            }
            Some(current) => std::mem::swap(current, new),
            None => {
                // With the scratch's room, so that swapping the two later allocates nothing.
                let mut first = new.clone();
                first.keep_room(new.candidates.capacity());
                self.choice = Some(first);
            }
        }
        let cut = self.samples.rays < SAMPLE_RAYS as usize;
        if let (Some(choice), true) = (&mut self.choice, cut) {
            let _ = write!(
                choice.reason,
                "; surface sample cut to {} of {SAMPLE_RAYS} rays (overlapping triangles)",
                self.samples.rays,
            );
        }
        if self.layout.as_ref() != Some(&layout) {
            self.layout = Some(layout);
        }
        self.view_at_choice = Some((ctx.view, ctx.lights.len()));
        self.frames_since_choice = 0;
        self.choices += 1;
    }

    /// Why the current grid is what it is.
    pub(crate) fn reason(&self) -> &str {
        self.choice.as_ref().map_or("", |c| c.reason.as_str())
    }

    /// Records what this frame's CPU side cost; the shading time follows in
    /// [`AutoGrid::observe`].
    pub(crate) fn record(&mut self, grid: &ClusterGrid, counts: &[u32], cost: FrameCost) {
        if self.chose_this_frame {
            self.pending = None;
            return;
        }
        let evals = self.samples.evals_per_pixel(grid, counts) * self.samples.covered_pixels();
        self.pending = Some(FrameCost { evals, ..cost });
    }

    /// Takes the frame's time in and calibrates the costs: the wall time less the CPU work
    /// when the frame waited for the GPU, else the GPU timer's, which for a frame that did
    /// not wait arrives a few frames later and is set against that frame's evaluations. The
    /// wall time wins where both exist: it bounds the GPU's work from above, while some timers
    /// (llvmpipe's) undercount a frame that samples textures in the fragment loop.
    pub(crate) fn observe(&mut self, timing: FrameTiming) {
        let serial = timing.serial;
        if let Some(mut cost) = self.pending.take() {
            let own_gpu = timing.gpu.filter(|&(s, _)| s == serial).map(|(_, ms)| ms);
            // Without either (a frame that did not wait, its GPU time not read yet or never,
            // on a device without timer queries) the shading is not measured, but the CPU's
            // assignment and uploads are.
            cost.shade_ms = timing
                .waited_ms
                .map(|ms| ms - cost.assign_ms - cost.upload_ms)
                .or(own_gpu)
                .unwrap_or(f64::NAN);
            self.costs.observe(&cost);
            self.recent_evals[ring_slot(serial)] = Some((serial, cost.evals));
        }
        if timing.waited_ms.is_some() {
            return;
        }
        let Some((earlier, ms)) = timing.gpu.filter(|&(s, _)| s != serial) else {
            return;
        };
        if let Some((s, evals)) = self.recent_evals[ring_slot(earlier)] {
            if s == earlier {
                self.costs.observe_shading(ms, evals);
            }
        }
    }

    /// Casts the frame's sample rays into `self.samples` (its buffer reused): the surface
    /// points where fragments will be.
    fn sample(&mut self, ctx: &FrameContext) {
        let scene = ctx.scene;
        let identity = |o: &crate::scene::Object| {
            (
                std::sync::Arc::as_ptr(&o.mesh) as usize,
                o.transform.to_cols_array().map(f64::to_bits),
                scene
                    .materials
                    .get(o.material)
                    .is_some_and(|m| m.double_sided),
            )
        };
        // The caster is rebuilt only when the geometry or a surface's sides changed (compared
        // without collecting a key, which would allocate every re-choice).
        let same_geometry = self.caster.as_ref().is_some_and(|(key, _)| {
            key.len() == scene.objects.len()
                && key
                    .iter()
                    .zip(&scene.objects)
                    .all(|(k, o)| *k == identity(o))
        });
        let woken = match self.caster.take() {
            Some((key, kept)) if same_geometry => kept.wake().map(|c| (key, c)).map_err(Some),
            kept => Err(kept.map(|(_, kept)| kept)),
        };
        let (key, caster) = woken.unwrap_or_else(|previous| {
            let key: GeometryKey = scene.objects.iter().map(identity).collect();
            // Moved objects keep their meshes' hierarchies: only the top level is rebuilt.
            (key, SceneRaycaster::rebuilt(previous, scene))
        });
        let left_out = caster.left_out_triangles();
        if left_out > 0 && !self.left_out_said {
            self.left_out_said = true;
            log::warn!(
                "the automatic grid's surface sample leaves out {left_out} triangles, whose \
                 ray-casting hierarchy this process cannot allocate now: the grid is chosen \
                 from the other surfaces (a fixed `--grid` needs no sample)"
            );
        }
        self.cast_samples(ctx, &caster);
        self.caster = Some((key, caster.keep()));
    }

    /// The sample rays of [`AutoGrid::sample`], cast with `caster`.
    fn cast_samples(&mut self, ctx: &FrameContext, caster: &SceneRaycaster) {
        let scene = ctx.scene;
        let (w, h) = ctx.viewport;
        let aspect = w as f64 / h as f64;
        let view = ctx.view;
        let inv = (scene.camera.projection_matrix(aspect) * view).inverse();
        let unproject = |x: f64, y: f64, z: f64| {
            let p = inv * DVec4::new(x, y, z, 1.0);
            p.truncate() / p.w
        };
        let (nx, ny) = SAMPLE_GRID;
        let samples = &mut self.samples;
        samples.points.clear();
        samples.rays = 0;
        samples.pixels = w as f64 * h as f64;
        let mut work = SAMPLE_WORK;
        for k in 0..SAMPLE_RAYS {
            let (i, j) = sample_ray(k);
            let ndc_x = -1.0 + 2.0 * (i as f64 + 0.5) / nx as f64;
            let ndc_y = -1.0 + 2.0 * (j as f64 + 0.5) / ny as f64;
            let origin = unproject(ndc_x, ndc_y, -1.0);
            // A point between the planes gives the ray's line even for an infinite far.
            let dir: DVec3 = (unproject(ndc_x, ndc_y, 0.0) - origin).normalize();
            if dir.is_finite() {
                let Some(hit) = caster.hit_within(origin, dir, &mut work) else {
                    break;
                };
                if let Some(hit) = hit {
                    let depth = -(view * hit.position.extend(1.0)).z;
                    let x = (ndc_x + 1.0) * 0.5 * w as f64;
                    let y = (ndc_y + 1.0) * 0.5 * h as f64;
                    samples.points.push([x, y, depth]);
                }
            }
            samples.rays += 1;
        }
        if samples.rays < SAMPLE_RAYS as usize && !self.sample_cut_said {
            self.sample_cut_said = true;
            log::warn!(
                "the automatic grid's surface sample stopped after {} of its {SAMPLE_RAYS} rays: the \
                 scene's triangles overlap so much that each ray tests most of them; the grid \
                 is chosen from those rays (a fixed `--grid` needs no sample)",
                samples.rays
            );
        }
    }
}

/// Column and row of the sample's `k`th ray: an order whose every first part is spread over
/// the whole view, so the rays cast when the work runs out are a fair sample still.
fn sample_ray(k: u32) -> (u32, u32) {
    let ray = k * SAMPLE_STRIDE % SAMPLE_RAYS;
    (ray % SAMPLE_GRID.0, ray / SAMPLE_GRID.0)
}

/// Whether a choice concluded now is the first made with calibrated figures (`calibrated`)
/// after one made with the priors alone, and so replaces the current grid without the
/// hysteresis; `chosen_with_priors` tracks whether the current choice was made with the
/// priors. While nothing calibrates, every choice keeps the hysteresis.
fn first_calibrated(chosen_with_priors: &mut bool, calibrated: bool) -> bool {
    let first = *chosen_with_priors && calibrated;
    *chosen_with_priors = !calibrated;
    first
}

/// A light count changed by more than a quarter.
fn changed_much(then: usize, now: usize) -> bool {
    now * 4 > then * 5 || now * 5 < then * 4
}

/// Writes the reason a fixed grid reports into `out`.
pub(crate) fn write_fixed_reason(out: &mut String, config: &GridConfig) {
    use std::fmt::Write as _;
    let _ = write!(
        out,
        "fixed: footprint_px = {} (GridConfig)",
        config.footprint_px
    );
}

#[cfg(test)]
mod tests {
    use super::{first_calibrated, sample_ray, AutoGrid, FrameCost, FrameTiming, SAMPLE_GRID};

    /// The sample's order takes each ray once, and its first 5 % (a sample cut short) already
    /// reach most rows and columns and every quarter of the view.
    #[test]
    fn the_samples_rays_take_each_once_and_spread_from_the_first() {
        let (nx, ny) = SAMPLE_GRID;
        let rays = nx * ny;
        let order: Vec<(u32, u32)> = (0..rays).map(sample_ray).collect();
        let distinct: std::collections::HashSet<_> = order.iter().collect();
        assert_eq!(distinct.len(), rays as usize);
        let first = &order[..(rays / 20) as usize];
        let rows: std::collections::HashSet<_> = first.iter().map(|r| r.1).collect();
        let columns: std::collections::HashSet<_> = first.iter().map(|r| r.0).collect();
        assert!(
            rows.len() * 4 >= ny as usize * 3,
            "{} of {ny} rows",
            rows.len()
        );
        assert!(
            columns.len() * 2 >= nx as usize,
            "{} of {nx} columns",
            columns.len()
        );
        for quarter in 0..4 {
            let (right, top) = (quarter % 2 == 1, quarter / 2 == 1);
            let n = first
                .iter()
                .filter(|&&(i, j)| (i >= nx / 2) == right && (j >= ny / 2) == top)
                .count();
            assert!(
                n * 8 >= first.len(),
                "{n} of {} in quarter {quarter}",
                first.len()
            );
        }
    }

    fn rendered(auto: &mut AutoGrid, evals: f64) {
        auto.pending = Some(FrameCost {
            evals,
            assign_ms: 0.5,
            assign_work: 1e4,
            ..FrameCost::default()
        });
    }

    /// A frame that does not wait calibrates the shading from its GPU time read frames later,
    /// set against that frame's evaluations, not the current one's.
    #[test]
    fn a_gpu_time_read_later_calibrates_against_its_own_frame() {
        let mut auto = AutoGrid::default();
        let prior = auto.costs.shade_ns;
        let timing = |serial, gpu| FrameTiming {
            serial,
            waited_ms: None,
            gpu,
        };
        // Frames 1 and 2: no GPU time yet; only the assignment is measured.
        rendered(&mut auto, 2e6);
        auto.observe(timing(1, None));
        rendered(&mut auto, 4e6);
        auto.observe(timing(2, None));
        assert_eq!(auto.costs.shade_ns, prior);
        assert_eq!(auto.costs.assign_ns, 50.0);
        // Frame 3 reads frame 1's: 10 ms over 2e6 evaluations is 5 ns each.
        rendered(&mut auto, 8e6);
        auto.observe(timing(3, Some((1, 10.0))));
        assert_eq!(auto.costs.shade_ns, 5.0);
        // A time of a frame the ring no longer holds (or never observed) is dropped.
        rendered(&mut auto, 8e6);
        auto.observe(timing(9, Some((5, 80.0))));
        assert_eq!(auto.costs.shade_ns, 5.0);
        // A frame's own GPU time counts for that frame.
        rendered(&mut auto, 1e6);
        auto.observe(timing(10, Some((10, 7.0))));
        assert!(
            (auto.costs.shade_ns - 6.0).abs() < 1e-9,
            "median of 5 and 7"
        );
    }

    /// A grid whose lists dropped nothing when it was chosen, and now drop references, is
    /// chosen again at once (the next `config` is urgent); one chosen although it overflowed,
    /// or never measured, is kept: choosing again would only find it again, each frame.
    #[test]
    fn only_a_grid_that_fitted_when_chosen_is_outgrown() {
        use crate::cluster::auto_grid::{Candidate, GridChoice};
        use crate::cluster::grid::GridConfig;
        let with = |overflowed_lights: u64| {
            let mut auto = AutoGrid::default();
            let candidate = |footprint_px, overflowed_lights| Candidate {
                footprint_px,
                cells: 1,
                indices: 1,
                evals_per_pixel: 1.0,
                bytes: 1,
                predicted_ms: 1.0,
                assign_ms: 0.1,
                over_budget: false,
                overflowed_lights,
                dropped_per_pixel: 0.0,
            };
            auto.choice = Some(GridChoice {
                config: GridConfig::fixed(16.0),
                reason: String::new(),
                candidates: vec![candidate(32.0, 0), candidate(16.0, overflowed_lights)],
            });
            auto.layout = Some(super::Layout {
                size: (1, 1),
                projection: crate::cluster::grid::GridProjection::from_matrix(
                    &glam::DMat4::IDENTITY,
                ),
                near: 0,
                base: GridConfig::default(),
                limits: (0, 0),
            });
            auto
        };
        let mut fitted = with(0);
        assert!(!fitted.outgrown(0), "nothing dropped");
        assert!(fitted.layout.is_some());
        assert!(fitted.outgrown(7));
        assert!(fitted.layout.is_none(), "the next choice is urgent");
        // Once in 30 frames for dropped references; always where none could be listed.
        assert!(!fitted.outgrown(7), "again at once");
        assert!(fitted.outgrown(u64::MAX));
        fitted.frames_since_outgrown = Some(super::RECHOOSE_AFTER_CHANGE);
        assert!(fitted.outgrown(7));
        assert!(with(0).outgrown(u64::MAX), "unlisted");
        let mut overflowed = with(5);
        assert!(!overflowed.outgrown(9));
        assert!(overflowed.layout.is_some());
        let mut unmeasured = with(0);
        unmeasured.choice.as_mut().unwrap().candidates.pop();
        assert!(!unmeasured.outgrown(9));
        assert!(!AutoGrid::default().outgrown(9), "no choice yet");
    }

    /// The hysteresis is skipped once, for the first calibrated choice after the priors' one,
    /// and never while no frame calibrates (a game that does not wait for the GPU on a device
    /// without timers would otherwise switch grids at every near-equal re-choice).
    #[test]
    fn only_the_first_calibrated_choice_skips_the_hysteresis() {
        let mut with_priors = false;
        // The first choice (priors), then choices that never calibrate.
        assert!(!first_calibrated(&mut with_priors, false));
        for _ in 0..5 {
            assert!(!first_calibrated(&mut with_priors, false));
        }
        // Calibrated at last: once, then the hysteresis again.
        assert!(first_calibrated(&mut with_priors, true));
        for _ in 0..5 {
            assert!(!first_calibrated(&mut with_priors, true));
        }
    }
}
