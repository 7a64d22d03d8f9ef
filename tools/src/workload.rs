//! The light-assignment workload of the benchmarks: the default scene's view at 1280×720 with
//! N seeded random lights, converted to view space once, so only `assign` is timed.

use std::time::Instant;

use manylight::cluster::assign::{AssignLimits, Assigner, Assignment};
use manylight::cluster::grid::{ClusterGrid, GridConfig, GridMeasure, GridProjection};
use manylight::cluster::view_light::GpuLight;
use manylight::scene::{self, SceneError};

/// Untimed assignments before [`AssignWorkload::time`] measures: a cold core (clock, caches,
/// branch predictors) is markedly slower than a warm one.
pub const WARM_UP: std::time::Duration = std::time::Duration::from_millis(100);

/// Rounds in which [`AssignWorkload::timing_on_pools`] alternates its pools.
pub const POOL_ROUNDS: usize = 5;

/// Viewport of the benchmark view.
pub const BENCH_SIZE: (u32, u32) = (1280, 720);

/// A prepared assignment problem.
pub struct AssignWorkload {
    /// The default clustered grid for the view.
    pub grid: ClusterGrid,
    /// Lights in view space.
    pub lights: Vec<GpuLight>,
    /// Camera far plane.
    pub far: f64,
}

/// Most timed runs [`AssignWorkload::time`] makes (their times are kept for the median).
pub const MAX_RUNS: usize = 1 << 20;

impl AssignWorkload {
    /// The default scene's camera with `count` random lights (seed `seed`).
    ///
    /// # Panics
    ///
    /// Where [`AssignWorkload::try_default_view`] fails (a benchmark helper).
    pub fn default_view(count: usize, seed: u64) -> AssignWorkload {
        Self::try_default_view(count, seed).expect("the default scene builds")
    }

    /// [`AssignWorkload::default_view`], or the error naming `lights` where `count` is past
    /// [`manylight::scene::input::MAX_LIGHTS`] or its lights cannot be allocated.
    pub fn try_default_view(count: usize, seed: u64) -> Result<AssignWorkload, SceneError> {
        // The grid this workload has always timed (64-pixel cells, never narrower than 1/64
        // of the depth range), so figures compare across versions.
        Self::try_view_with(count, seed, BENCH_SIZE, |near, far| GridConfig {
            measure: GridMeasure {
                min_cell_size: Some((far - near) / 64.0),
                ..GridMeasure::default()
            },
            ..GridConfig::fixed(64.0)
        })
    }

    /// The grid the automatic choice picks for the default scene at 640×360 with 1 024 lights
    /// (11-pixel cells from a first split at 4 m, ~140 000 cells): the fine-grid case, where
    /// each light covers hundreds of cells.
    pub fn fine_grid(count: usize, seed: u64) -> AssignWorkload {
        Self::view_with(count, seed, (640, 360), |_, _| GridConfig {
            first_split: Some(4.0),
            ..GridConfig::fixed(11.0)
        })
    }

    /// A fixed grid of `px`-pixel cells (no first split) at `size`, as the renderer's `--grid
    /// PX` makes, over the camera's near and far planes: near the renderer's own assignment
    /// (whose depth range may give it fewer slices: 820 800 cells against this grid's 950 400
    /// at 1280×720 on 16-px cells), in a loop.
    pub fn renderer_grid(count: usize, seed: u64, size: (u32, u32), px: f64) -> AssignWorkload {
        Self::view_with(count, seed, size, |_, _| GridConfig::fixed(px))
    }

    /// The default scene's camera with `count` random lights at `size` with the grid that
    /// `config` makes of the camera's near and far planes.
    ///
    /// # Panics
    ///
    /// Where [`AssignWorkload::try_view_with`] fails (a benchmark helper).
    pub fn view_with(
        count: usize,
        seed: u64,
        size: (u32, u32),
        config: impl FnOnce(f64, f64) -> GridConfig,
    ) -> AssignWorkload {
        Self::try_view_with(count, seed, size, config).expect("the default scene builds")
    }

    /// [`AssignWorkload::view_with`], or the error naming `lights` where the scene or its
    /// view-space lights cannot be built.
    pub fn try_view_with(
        count: usize,
        seed: u64,
        (w, h): (u32, u32),
        config: impl FnOnce(f64, f64) -> GridConfig,
    ) -> Result<AssignWorkload, SceneError> {
        let scene = scene::builtin::build(scene::builtin::DEFAULT, Some((count, seed)))?;
        let view = scene.camera.view_matrix();
        let projection = scene.camera.projection_matrix(w as f64 / h as f64);
        let (near, far) = scene.camera.near_far();
        let grid = ClusterGrid::new(
            w,
            h,
            GridProjection::from_matrix(&projection),
            near,
            far,
            &config(near, far),
        );
        let mut lights = Vec::new();
        lights.try_reserve_exact(count).map_err(|_| {
            let bytes = count as u64 * std::mem::size_of::<GpuLight>() as u64;
            SceneError::invalid(
                "lights",
                format!("{count} lights take {bytes} bytes in view space, which this process cannot allocate now"),
            )
        })?;
        lights.extend(scene.lights.iter().map(|l| GpuLight::from_light(l, &view)));
        Ok(AssignWorkload { grid, lights, far })
    }

    /// One assignment with `assigner`'s buffers (as a renderer does every frame).
    pub fn assign_with<'a>(&self, assigner: &'a mut Assigner) -> &'a Assignment {
        assigner.assign(
            &self.grid,
            &self.lights,
            self.far,
            &AssignLimits {
                cell_cap: u32::MAX,
                ..AssignLimits::default()
            },
        )
    }

    /// One assignment with fresh buffers.
    pub fn assign(&self) -> Assignment {
        let mut assigner = Assigner::new();
        self.assign_with(&mut assigner);
        assigner.into_assignment()
    }

    /// Median wall time in milliseconds over `runs` assignments (1 to [`MAX_RUNS`]; outside,
    /// the nearest), after [`WARM_UP`] of untimed ones (at least one, which sizes the reused
    /// buffers as a renderer's first frame does), and the number of indices produced.
    pub fn time(&self, runs: usize) -> (f64, usize) {
        let timing = self.timing(runs);
        (timing.median_ms, timing.indices)
    }

    /// [`AssignWorkload::time`], with the threads the median run took.
    pub fn timing(&self, runs: usize) -> AssignTiming {
        let runs = runs.clamp(1, MAX_RUNS);
        let mut times = Vec::with_capacity(runs);
        let indices = self.warm_and_time(&mut Assigner::new(), WARM_UP, runs, &mut times);
        median_of(&mut times, indices)
    }

    /// [`AssignWorkload::timing`] on each of `pools` (rayon pools: one of one thread and one
    /// of two, say), alternating: in each of [`POOL_ROUNDS`] rounds every pool in turn warms
    /// up (a fifth of [`WARM_UP`], at least one assignment) and times its share of the `runs`,
    /// each run timed on one of the pool's threads. So a host whose speed drifts (a shared VM,
    /// a phone's clocks) drifts under every pool alike, and their ratio is one run's. Each pool
    /// keeps its own [`Assigner`] (buffers, thread choice, bands' split).
    ///
    /// The pools are driven from a thread of no pool: a worker of another pool (the command
    /// line's thread is one of the global pool) waits for `install` by looking for work in
    /// its own pool, spinning a core away from the pool being timed.
    pub fn timing_on_pools(&self, pools: &[rayon::ThreadPool], runs: usize) -> Vec<AssignTiming> {
        std::thread::scope(|scope| {
            scope
                .spawn(|| self.alternate_pools(pools, runs))
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        })
    }

    /// [`AssignWorkload::timing_on_pools`] on the calling thread.
    fn alternate_pools(&self, pools: &[rayon::ThreadPool], runs: usize) -> Vec<AssignTiming> {
        let runs = runs.clamp(1, MAX_RUNS);
        let rounds = POOL_ROUNDS.min(runs);
        let mut assigners: Vec<Assigner> = pools.iter().map(|_| Assigner::new()).collect();
        let mut indices = vec![0; pools.len()];
        let mut times: Vec<Vec<(f64, usize)>> = vec![Vec::with_capacity(runs); pools.len()];
        let warm_up = WARM_UP / POOL_ROUNDS as u32;
        for round in 0..rounds {
            let share = runs * (round + 1) / rounds - runs * round / rounds;
            for (p, pool) in pools.iter().enumerate() {
                let (assigner, samples) = (&mut assigners[p], &mut times[p]);
                indices[p] = pool.install(|| self.warm_and_time(assigner, warm_up, share, samples));
            }
        }
        times
            .iter_mut()
            .zip(indices)
            .map(|(samples, indices)| median_of(samples, indices))
            .collect()
    }

    /// One assignment, then more untimed ones for `warm_up`, then `runs` timed ones into
    /// `samples` (wall time in milliseconds, threads taken); the first one's indices.
    fn warm_and_time(
        &self,
        assigner: &mut Assigner,
        warm_up: std::time::Duration,
        runs: usize,
        samples: &mut Vec<(f64, usize)>,
    ) -> usize {
        let indices = self.assign_with(assigner).indices.len();
        let start = Instant::now();
        while start.elapsed() < warm_up {
            std::hint::black_box(self.assign_with(assigner));
        }
        samples.extend((0..runs).map(|_| self.timed_run(assigner)));
        indices
    }

    /// One assignment's wall time in milliseconds, and the threads it took.
    fn timed_run(&self, assigner: &mut Assigner) -> (f64, usize) {
        let t = Instant::now();
        let threads = std::hint::black_box(self.assign_with(assigner))
            .stats
            .threads;
        (t.elapsed().as_secs_f64() * 1e3, threads)
    }
}

/// The median of `times` (wall time in milliseconds, threads), with `indices`.
fn median_of(times: &mut [(f64, usize)], indices: usize) -> AssignTiming {
    times.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (median_ms, threads) = times[times.len() / 2];
    AssignTiming {
        median_ms,
        indices,
        threads,
    }
}

/// What [`AssignWorkload::timing`] measured.
#[derive(Clone, Copy, Debug)]
pub struct AssignTiming {
    /// Median wall time of the timed runs, in milliseconds.
    pub median_ms: f64,
    /// Indices listed.
    pub indices: usize,
    /// Threads the median run took (the assignment picks them from the previous run's time).
    pub threads: usize,
}
