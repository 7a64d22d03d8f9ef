//! An assigner's buffers stop growing after a warm-up on any number of workers: frames of
//! moving lights reuse every buffer however the work is split (bands of slices, chunks of
//! lights), however the split moves from frame to frame and whichever chunks' lights are in
//! view. The soak test checks the same rule for whole frames, but the 2-core CI host's
//! renderer keeps small scenes on one thread; here every assignment runs on a pool of 2, 4 or
//! 8 workers (as many of those as the host has cores for).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use manylight::cluster::assign::{AssignLimits, Assigner};
use manylight::cluster::grid::GridConfig;
use manylight::cluster::view_light::GpuLight;
use manylight_tools::workload::AssignWorkload;

/// The system allocator, counting the calls that allocate on the workers of the pool that
/// [`COUNTED_POOL`] names: those run every assignment. The test harness's threads (printing
/// one test's result while the next counts) and an earlier pool's workers (ending whenever the
/// system runs them) are not counted.
struct Counting;

/// The number [`pool_of`] gave the pool whose workers are counted; 0 while none is.
static COUNTED_POOL: AtomicUsize = AtomicUsize::new(0);
static CALLS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    /// This thread is printing a backtrace: what that allocates is not counted.
    static IN_TRACE: Cell<bool> = const { Cell::new(false) };
    /// The number of the pool this thread works in ([`pool_of`]); 0 outside any.
    static POOL: Cell<usize> = const { Cell::new(0) };
}
/// With `MANYLIGHT_ALLOC_TRACE` set (any value), every counted call prints its backtrace.
static TRACE: AtomicBool = AtomicBool::new(false);

fn count(bytes: usize) {
    let counted = COUNTED_POOL.load(Ordering::Relaxed);
    if counted != 0
        && POOL.try_with(Cell::get) == Ok(counted)
        && !IN_TRACE.try_with(Cell::get).unwrap_or(true)
    {
        CALLS.fetch_add(1, Ordering::Relaxed);
        if TRACE.load(Ordering::Relaxed) {
            IN_TRACE.with(|t| t.set(true));
            eprintln!(
                "allocation of {bytes} bytes:\n{}",
                std::backtrace::Backtrace::force_capture()
            );
            IN_TRACE.with(|t| t.set(false));
        }
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count(layout.size());
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count(new_size);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Held by each test for its whole run: the counter is global, so one test counts at a time.
fn serial() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let guard = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    TRACE.store(
        std::env::var_os("MANYLIGHT_ALLOC_TRACE").is_some(),
        Ordering::Relaxed,
    );
    guard
}

/// Frames before counting (as the soak test's warm-up), and frames counted.
const WARM_UP: usize = 40;
const MEASURED: usize = 100;

/// Moves every light of `start` for `frame`: each on its own orbit in view x and depth, so
/// the lights' work moves between slices (the bands' borders follow it) and in and out of view
/// (a chunk's share of the runs changes). Every orbit repeats within the warm-up: the whole
/// assignment's peak is in it, and only where the work is split differs afterwards.
fn move_lights(lights: &mut [GpuLight], start: &[GpuLight], frame: usize) {
    for (i, (light, from)) in lights.iter_mut().zip(start).enumerate() {
        let turns = (1 + i % 3) as f32 * frame as f32 / WARM_UP as f32;
        let phase = std::f32::consts::TAU * turns + i as f32;
        let depth = -from.position.z;
        light.position.x = from.position.x + 0.3 * depth * phase.sin();
        light.position.z = -depth * (1.0 + 0.6 * phase.cos());
    }
}

/// Allocations in the counted frames of `workload`'s lights, posed for each frame by `pose`
/// (in place: nothing allocated), assigned by one assigner on `pool`, every assignment on the
/// pool.
fn allocations(
    workload: &AssignWorkload,
    pool: &rayon::ThreadPool,
    pose: impl Fn(&mut [GpuLight], usize) + Sync,
) -> usize {
    // Inside the pool: an entry from outside would queue a job in rayon's global queue,
    // which allocates a block now and then (the soak test tells those apart).
    pool.install(|| {
        let mut assigner = Assigner::new();
        let limits = limits();
        let mut lights = workload.lights.clone();
        let mut before = 0;
        for frame in 0..WARM_UP + MEASURED {
            pose(&mut lights, frame);
            if frame == WARM_UP {
                let number = POOL.with(Cell::get);
                // 0 would count nothing, and every test would pass.
                assert_ne!(number, 0, "the pool's workers are not numbered (pool_of)");
                before = CALLS.load(Ordering::Relaxed);
                COUNTED_POOL.store(number, Ordering::Relaxed);
            }
            let a = assigner.assign(&workload.grid, &lights, workload.far, &limits);
            assert!(a.stats.threads > 1, "frame {frame} ran on one thread");
        }
        COUNTED_POOL.store(0, Ordering::Relaxed);
        CALLS.load(Ordering::Relaxed) - before
    })
}

/// Every light listed (no cap), and every assignment on the pool.
fn limits() -> AssignLimits {
    AssignLimits {
        cell_cap: u32::MAX,
        parallel_threshold: 0,
        ..AssignLimits::default()
    }
}

/// A pool of `threads` workers, every worker started (a worker starting allocates on its own
/// thread, whenever the system runs it): made before any counting and kept to the end. Its
/// workers know it by a number of its own ([`POOL`]).
fn pool_of(threads: usize) -> rayon::ThreadPool {
    static MADE: AtomicUsize = AtomicUsize::new(0);
    let number = MADE.fetch_add(1, Ordering::Relaxed) + 1;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(move |_| POOL.with(|p| p.set(number)))
        .build()
        .expect("a thread pool");
    pool.broadcast(|_| ());
    pool
}

#[test]
fn moving_lights_on_two_to_eight_workers_allocate_nothing_after_a_warm_up() {
    let _serial = serial();
    let fixed = |px: f64| move |_: f64, _: f64| GridConfig::fixed(px);
    let workloads = [
        // More cells than lights: bands of slices.
        (
            "bands, 128 lights",
            AssignWorkload::view_with(128, 3, (256, 144), fixed(16.0)),
        ),
        (
            "bands, 2 048 lights",
            AssignWorkload::view_with(2048, 3, (640, 360), fixed(16.0)),
        ),
        // More lights than cells: chunks of lights.
        (
            "chunks, 512 lights",
            AssignWorkload::view_with(512, 3, (48, 27), fixed(32.0)),
        ),
    ];
    // Made once and kept to the end: a worker starting allocates on its own thread, whenever
    // the system runs it.
    // No more workers than cores (but two): on fewer cores the workers preempt one another, so
    // each band's measured time, and the split that follows it, is noise, which no device
    // running a pool of its own size sees.
    let cores = std::thread::available_parallelism().map_or(2, |n| n.get());
    let pools: Vec<rayon::ThreadPool> = [2, 4, 8]
        .into_iter()
        .filter(|&threads| threads <= cores.max(2))
        .map(pool_of)
        .collect();
    let mut failures = Vec::new();
    for (name, workload) in &workloads {
        for pool in &pools {
            let threads = pool.current_num_threads();
            let n = allocations(workload, pool, |lights, frame| {
                move_lights(lights, &workload.lights, frame);
            });
            eprintln!("{name}, {threads} workers: {n} allocations in {MEASURED} frames");
            if n > 0 {
                failures.push(format!("{name}, {threads} workers: {n} allocations"));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Lights that take turns in view: the first half by index during the warm-up, the second
/// half after it, each half's away from the camera behind it. The whole list stays at its
/// warm-up size, but the chunks that hold the second half reach their own peaks only after the
/// warm-up; what each chunk keeps room for must follow the whole, not its own history.
#[test]
fn chunks_whose_lights_come_into_view_after_a_warm_up_allocate_nothing() {
    let _serial = serial();
    let workload = AssignWorkload::view_with(512, 3, (48, 27), |_, _| GridConfig::fixed(32.0));
    let behind = |light: &GpuLight| GpuLight {
        position: glam::Vec3::new(light.position.x, light.position.y, 1.0e3),
        ..*light
    };
    let half = workload.lights.len() / 2;
    // Both sets made before counting: index 0 for the warm-up, 1 after it.
    let sets = [false, true].map(|later| {
        (workload.lights.iter().enumerate())
            .map(|(i, l)| if (i < half) == later { behind(l) } else { *l })
            .collect::<Vec<GpuLight>>()
    });
    let n = allocations(&workload, &pool_of(2), |lights, frame| {
        lights.copy_from_slice(&sets[usize::from(frame >= WARM_UP)]);
    });
    // The test means something: both halves list lights, and the whole list after the
    // warm-up stays within a quarter more than its warm-up size (the least room that any of
    // the assigner's buffers keeps past its peak).
    let listed = sets.map(|lights| {
        let mut assigner = Assigner::new();
        (assigner.assign(&workload.grid, &lights, workload.far, &limits()))
            .indices
            .len()
    });
    assert!(
        listed.iter().all(|&l| l > 100) && listed[1] <= listed[0] + listed[0] / 4,
        "{listed:?}"
    );
    assert_eq!(n, 0, "{n} allocations after the warm-up (lists {listed:?})");
}
