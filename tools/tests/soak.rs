//! Memory over many frames, with lights moving every frame, for every method:
//!
//! * the renderer's live heap bytes (counted by this test binary's allocator) and its live GL
//!   objects do not grow after a warm-up;
//! * in steady state a frame allocates nothing: [`Renderer::render_reusing`] into a framebuffer
//!   the test binds itself (a game's path) makes no heap allocation of its own over the
//!   measured frames, on ES 3.0 and ES 2.0 contexts; [`Renderer::render`] makes exactly the
//!   allocations of the strings in the `FrameStats` it returns besides. Rayon's global job
//!   queue allocates a block every 63 entries into its pool from outside, and whether an
//!   assignment enters the pool depends on the host's speed: those blocks, told apart by their
//!   backtrace, are allowed at that rate in every case and nothing else is. `Scene::validate`,
//!   which every frame runs, is counted with the frame; a scene using every part it checks
//!   (maps, transforms, suns, motions) is validated without an allocation too.
//!
//! * a warm-up copies none of the scene's lights: its peak heap is a fresh method's frame's,
//!   where a copy of the lights and their motion added 201 bytes a light.
//!
//! `cargo bench --bench soak` runs the long version (2 000 frames a method, resident memory
//! sampled; docs/performance.md has its figures). To find an allocation that crept into the
//! frame, run `MANYLIGHT_ALLOC_TRACE=TEXT cargo test --test soak -- --nocapture` (TEXT: part of
//! the cases' names, as printed, e.g. `ES 3.0 courtyard 64`, or `all`): every allocation in
//! those cases' `render_reusing` frames prints its backtrace.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicIsize, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use common::Gpu;
use glam::DVec3;
use manylight::cluster::grid::GridConfig;
use manylight::gl::framebuffer::OffscreenTarget;
use manylight::gl::{Device, HeadlessContext, Restrictions};
use manylight::methods::{Support, METHODS};
use manylight::scene::meshbuild::MeshBuilder;
use manylight::scene::Scene;
use manylight::{scene, EsVersion, FrameStats, RenderOptions, Renderer};

/// The system allocator, keeping a count of the bytes live and of the calls that allocate.
struct Counting;

/// Bytes allocated and not yet freed.
static LIVE: AtomicIsize = AtomicIsize::new(0);
/// The most `LIVE` has been since a test last set it.
static PEAK: AtomicIsize = AtomicIsize::new(0);

/// Adds `bytes` to [`LIVE`], keeping [`PEAK`].
fn grow_live(bytes: isize) {
    let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(live, Ordering::Relaxed);
}
/// `alloc`, `alloc_zeroed` and `realloc` calls of the frames: on the thread that renders them
/// and on rayon's workers (not on the test harness's threads, which print results and start
/// other tests meanwhile).
static CALLS: AtomicUsize = AtomicUsize::new(0);
/// While set, every counted call prints its backtrace.
static TRACING: AtomicBool = AtomicBool::new(false);
/// While set (the counted frames), a call large enough to be a block of rayon's global job
/// queue is told apart by its backtrace: such blocks go to [`INJECTOR_BLOCKS`], not `CALLS`.
static MEASURING: AtomicBool = AtomicBool::new(false);
/// Blocks of rayon's global job queue allocated in the counted frames (see
/// [`RAYON_INJECTOR_BLOCK`]).
static INJECTOR_BLOCKS: AtomicUsize = AtomicUsize::new(0);
/// Bytes below which a call is not looked at as a job-queue block: crossbeam's block of 63
/// jobs is 190 pointers (1 520 bytes on a 64-bit target, 760 on a 32-bit one), and the frames'
/// own few calls, their stats' strings, are far smaller. A call past this that is not such a
/// block is counted like any other; the bound only spares the others a backtrace.
const INJECTOR_BLOCK_MIN_BYTES: usize = 128 * std::mem::size_of::<usize>();

thread_local! {
    /// This thread is printing a backtrace: what that allocates is neither counted nor traced.
    static IN_TRACE: Cell<bool> = const { Cell::new(false) };
    /// This thread renders the counted frames.
    static RENDERS: Cell<bool> = const { Cell::new(false) };
}

fn count_call(bytes: usize) {
    if IN_TRACE.try_with(Cell::get).unwrap_or(true) {
        return;
    }
    let renders = RENDERS.try_with(Cell::get).unwrap_or(false);
    if !renders && rayon::current_thread_index().is_none() {
        return;
    }
    if bytes >= INJECTOR_BLOCK_MIN_BYTES && MEASURING.load(Ordering::Relaxed) {
        IN_TRACE.with(|t| t.set(true));
        let trace = std::backtrace::Backtrace::force_capture().to_string();
        IN_TRACE.with(|t| t.set(false));
        if trace.contains("crossbeam_deque") && trace.contains("Injector") {
            INJECTOR_BLOCKS.fetch_add(1, Ordering::Relaxed);
            return;
        }
    }
    CALLS.fetch_add(1, Ordering::Relaxed);
    if TRACING.load(Ordering::Relaxed) {
        IN_TRACE.with(|t| t.set(true));
        let trace = std::backtrace::Backtrace::force_capture();
        eprintln!(
            "allocation on thread {:?}:\n{trace}",
            std::thread::current().name()
        );
        IN_TRACE.with(|t| t.set(false));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_call(layout.size());
        grow_live(layout.size() as isize);
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count_call(layout.size());
        grow_live(layout.size() as isize);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as isize, Ordering::Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_call(new_size);
        grow_live(new_size as isize - layout.size() as isize);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The counters are global: the tests of this file run one at a time.
static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// `scene` with each object's mesh replaced by its bounding box: the same objects, materials,
/// bounds, lights and camera, so the same draws, sorting and grid, with 12 triangles an object.
/// What a frame allocates does not depend on the triangles, and the courtyard's 6 000 (the
/// bubbles' 13 000) through every pass were most of a software GPU's time here.
fn with_boxes(mut scene: Scene) -> Scene {
    for object in &mut scene.objects {
        let bounds = object.mesh.bounds().expect("a built-in mesh has vertices");
        let mut boxed = MeshBuilder::new();
        boxed.cuboid(bounds.min.as_vec3(), bounds.max.as_vec3());
        object.mesh = Arc::new(boxed.build().expect("a box"));
    }
    scene
}

/// Moves every light in place along its own small orbit (nothing is allocated).
fn move_lights(scene: &mut Scene, start: &[DVec3], frame: usize) {
    let t = frame as f64 / 30.0;
    for (i, (light, origin)) in scene.lights.iter_mut().zip(start).enumerate() {
        let a = t * (1.0 + (i % 5) as f64) + i as f64;
        light.position = *origin + DVec3::new(a.cos(), 0.2 * a.sin(), a.sin());
    }
}

/// Sways the camera around `eye`, a whole sway every 38 frames (the grid's depth range, and so
/// the grid, changes every frame).
fn move_camera(scene: &mut Scene, eye: DVec3, frame: usize) {
    let a = frame as f64 / 6.0;
    scene.camera.position = eye + DVec3::new(0.6 * a.sin(), 0.2 * a.cos(), 0.4 * a.cos());
}

#[test]
fn live_heap_and_gl_objects_stay_flat_over_frames_of_moving_lights() {
    let _serial = serial();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut scene = with_boxes(scene::builtin::build("courtyard", Some((64, 5))).unwrap());
    let start: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
    let options = RenderOptions::default();
    let (warm_up, measured) = (40, 120);
    for method in METHODS.iter().map(|m| m.name) {
        gpu.r().set_method_named(method).unwrap();
        let mut at_warm_up = None;
        for frame in 0..warm_up + measured {
            move_lights(&mut scene, &start, frame);
            gpu.r()
                .render_offscreen(&scene, 32, 18, &options)
                .unwrap_or_else(|e| panic!("{method} frame {frame}: {e}"));
            if frame + 1 == warm_up {
                at_warm_up = Some((LIVE.load(Ordering::Relaxed), gpu.r().live_gl_objects()));
            }
        }
        let (heap_before, gl_before) = at_warm_up.unwrap();
        let heap_after = LIVE.load(Ordering::Relaxed);
        let gl_after = gpu.r().live_gl_objects();
        eprintln!(
            "{method}: live heap {:+} bytes over {measured} frames, GL objects {gl_after:?}",
            heap_after - heap_before
        );
        assert_eq!(gl_before, gl_after, "{method}: GL objects grew");
        // Buffers may still settle (a grid re-chosen, a list longer than before); a leak of
        // even 1 KiB a frame would pass 100 KiB here.
        assert!(
            heap_after - heap_before < 100 * 1024,
            "{method}: live heap grew by {} bytes over {measured} frames",
            heap_after - heap_before
        );
    }
}

/// Frames before counting: shaders built, buffers grown, the automatic grid chosen and
/// calibrated, a whole sway of the moving camera seen.
const WARM_UP: usize = 40;
/// Frames counted with [`Renderer::render`], after the warm-up.
const MEASURED_RENDER: usize = 10;
/// Frames counted with [`Renderer::render_reusing`], after those: more than anything the
/// renderer does periodically but the automatic grid's re-choices (the case below). With a still
/// camera they end (frame 90) before its periodic re-choice (240 frames after its calibrated
/// choice at frame 5).
const MEASURED: usize = 40;
/// The same for the case with a moving camera and the automatic grid: three re-choices (every 30
/// frames once the view moves), which allocate nothing either.
const MEASURED_THROUGH_RECHOICES: usize = 100;

/// Allocations `Renderer::render` makes for the `FrameStats` it returns: one per non-empty
/// string in it.
fn owned_strings(s: &FrameStats) -> usize {
    let reason = match &s.support {
        Support::Supported => None,
        Support::Fallback(r) | Support::Unsupported(r) => Some(r),
    };
    [&s.method, &s.context.gl_version, &s.context.renderer]
        .into_iter()
        .chain(reason)
        .chain(s.auto_choice.as_ref())
        .chain(s.auto_reason.as_ref())
        .chain(s.context.lp_num_threads.as_ref())
        .chain(s.grid.reason.as_ref())
        .filter(|s| !s.is_empty())
        .count()
}

/// One workload of [`allocations_per_frame`].
struct Case {
    scene: &'static str,
    lights: usize,
    /// Whether frames wait for the GPU (a game's do not; the timer query and the automatic
    /// grid's calibration run only when they do).
    wait_for_gpu: bool,
    /// Whether the camera moves too (with a fixed grid then, unless `auto_grid`).
    camera_moves: bool,
    /// With a moving camera, keep the automatic grid: it re-chooses every 30 frames then, so
    /// the counted frames include re-choices.
    auto_grid: bool,
    /// The methods (none named: all).
    methods: &'static [&'static str],
    /// Samples per pixel (MSAA above 1).
    samples: u32,
    /// Viewport (and the application's target).
    size: (u32, u32),
    /// Most lights a cell keeps (`MeasureOptions::cell_cap`): the overflow policy's path.
    cell_cap: Option<u32>,
    /// Frames counted with `render_reusing`.
    measured: usize,
    /// Each frame draws a second view, half the size, with the same renderer (a split screen).
    second_view: bool,
}

/// A case with still camera, waiting for the GPU, every method, nothing allowed. 64 lights:
/// enough that `auto` picks clustered, few enough to keep a software GPU's frames short. What a
/// frame allocates does not depend on its size, so the frame is small: 16×9, within one tile
/// (forward and tiled over 64 lights at every pixel are most of a software GPU's time here).
const CASE: Case = Case {
    scene: "courtyard",
    lights: 64,
    wait_for_gpu: true,
    camera_moves: false,
    auto_grid: false,
    methods: &[],
    samples: 1,
    size: (16, 9),
    cell_cap: None,
    measured: MEASURED,
    second_view: false,
};

/// Jobs rayon's global job queue (crossbeam's `Injector`) holds per block: every this many
/// entries into the pool from outside it, it allocates a block. Whether an assignment enters
/// the pool depends on the host (its time on the previous frame, which a slow or busy CPU makes
/// long with few lights), so every case allows these blocks, at most one per this many entries.
const RAYON_INJECTOR_BLOCK: usize = 63;

/// Entries into rayon's pool a frame can make: its assignment, and a candidate grid's of the
/// automatic grid's re-choice.
const POOL_ENTRIES_PER_FRAME: usize = 2;

/// The workloads of both ES versions.
fn common_cases() -> Vec<Case> {
    vec![
        CASE,
        Case {
            wait_for_gpu: false,
            ..CASE
        },
        // `auto` picks forward.
        Case { lights: 16, ..CASE },
        // Ambient only.
        Case { lights: 0, ..CASE },
        // Transparent objects, drawn back to front (deferred draws them with forward).
        Case {
            scene: "bubbles",
            lights: 64,
            ..CASE
        },
        Case {
            wait_for_gpu: false,
            camera_moves: true,
            ..CASE
        },
        Case {
            scene: "bubbles",
            lights: 64,
            wait_for_gpu: false,
            camera_moves: true,
            ..CASE
        },
        // The automatic grid with a moving camera: a re-choice every 30 frames, each
        // measuring one candidate per frame, three of them in the counted frames.
        //
        // 128 lights: with 64 the search can measure a grid finer than any of the warm-up,
        // whose per-cell arrays then grow (docs/performance.md, "Allocations per frame").
        Case {
            lights: 128,
            camera_moves: true,
            auto_grid: true,
            methods: &["clustered", "auto"],
            measured: MEASURED_THROUGH_RECHOICES,
            // The size the light count above was chosen at: the candidate grids depend on it.
            size: (48, 27),
            ..CASE
        },
        // Cells holding more lights than the cap: the overflow policy trims them.
        Case {
            wait_for_gpu: false,
            cell_cap: Some(4),
            methods: &["tiled", "clustered"],
            ..CASE
        },
        // Enough lights for the assignment to run on all cores on any host: one entry into
        // rayon's pool a frame (see RAYON_INJECTOR_BLOCK). The count decides that, not the
        // size, and a software GPU's fragments loop over thousands of lights: 4×2 pixels.
        Case {
            lights: 5000,
            wait_for_gpu: false,
            methods: &["clustered"],
            size: (4, 2),
            ..CASE
        },
    ]
}

/// Renders every method through `Renderer::render_reusing` and `Renderer::render` into a
/// framebuffer the test made and bound (as a game does), lights moving every frame, and counts
/// allocation calls per method after the warm-up. Returns the rows that allocated.
fn allocations_per_frame(
    es: EsVersion,
    restrictions: &Restrictions,
    cases: &[Case],
) -> Vec<String> {
    RENDERS.with(|r| r.set(true));
    let ctx = HeadlessContext::new(es).unwrap_or_else(|e| {
        panic!(
            "no headless {es} context ({e}); install libegl1 libegl-mesa0 libgles2 libgl1-mesa-dri"
        )
    });
    // The application's own GL objects, made with its own glow context on the same GL context.
    let app = Device::new(ctx.load_gl().unwrap(), es).expect("application device");
    let mut renderer =
        Renderer::restricted(ctx.load_gl().unwrap(), es, restrictions).expect("renderer");
    let trace_cases = std::env::var("MANYLIGHT_ALLOC_TRACE").ok();
    let mut failures = Vec::new();
    for c in cases {
        let &Case {
            scene: name,
            lights,
            wait_for_gpu,
            camera_moves,
            auto_grid,
            methods: only,
            samples,
            size: (width, height),
            cell_cap,
            measured,
            second_view,
        } = c;
        let mut target = OffscreenTarget::new(&app, width, height).expect("application target");
        // The automatic grid's case keeps the real meshes: its choices follow the frames' measured
        // time, and its light count and size were chosen with those (see `common_cases`).
        let built = scene::builtin::build(name, Some((lights, 5))).unwrap();
        let mut scene = if auto_grid { built } else { with_boxes(built) };
        let start: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
        let eye = scene.camera.position;
        let options = RenderOptions {
            wait_for_gpu,
            grid: if camera_moves && !auto_grid {
                GridConfig::fixed(32.0)
            } else {
                GridConfig::default()
            },
            samples,
            measure: manylight::MeasureOptions {
                cell_cap,
                ..Default::default()
            },
            ..RenderOptions::default()
        };
        let methods = METHODS
            .iter()
            .map(|m| m.name)
            .filter(|m| only.is_empty() || only.contains(m));
        for method in methods {
            let case = format!(
                "{es}{} {name} {lights} lights wait_for_gpu={wait_for_gpu} \
                 camera_moves={camera_moves} auto_grid={auto_grid} samples={samples} \
                 cell_cap={cell_cap:?} second_view={second_view} \
                 {width}x{height} {method}",
                if restrictions.no_fragment_highp {
                    " without fragment highp"
                } else {
                    ""
                }
            );
            if let Err(e) = renderer.set_method_named(method) {
                assert!(
                    matches!(
                        (METHODS.iter().find(|m| m.name == method).unwrap().supported)(
                            renderer.caps()
                        ),
                        Support::Unsupported(_)
                    ),
                    "{case}: {e}"
                );
                eprintln!("{case}: not supported here");
                continue;
            }
            let mut frame = 0;
            let mut next_frame = |scene: &mut Scene| {
                move_lights(scene, &start, frame);
                if camera_moves {
                    move_camera(scene, eye, frame);
                }
                frame += 1;
                target.bind(&app);
                frame
            };
            let mut stats = FrameStats::default();
            // The frame's views: the whole target, and with `second_view` half of it.
            let views = [(width, height), (width.div_ceil(2), height.div_ceil(2))];
            let views = &views[..1 + usize::from(second_view)];
            for _ in 0..WARM_UP {
                let frame = next_frame(&mut scene);
                for &(w, h) in views {
                    renderer
                        .render_reusing(&scene, w, h, &options, &mut stats)
                        .unwrap_or_else(|e| panic!("{case} frame {frame}: {e}"));
                }
            }
            // `render` returns its stats by value: their strings are new each frame.
            let mut expected = 0i64;
            let blocks_before = INJECTOR_BLOCKS.load(Ordering::Relaxed);
            MEASURING.store(true, Ordering::Relaxed);
            let before = CALLS.load(Ordering::Relaxed);
            for _ in 0..MEASURED_RENDER {
                let frame = next_frame(&mut scene);
                for &(w, h) in views {
                    let stats = renderer
                        .render(&scene, w, h, &options)
                        .unwrap_or_else(|e| panic!("{case} frame {frame}: {e}"));
                    expected += owned_strings(&stats) as i64;
                }
            }
            let by_render = (CALLS.load(Ordering::Relaxed) - before) as i64;
            // The game's path.
            let before = CALLS.load(Ordering::Relaxed);
            let trace = trace_cases
                .as_deref()
                .is_some_and(|t| t == "all" || case.contains(t));
            TRACING.store(trace, Ordering::Relaxed);
            for _ in 0..measured {
                let frame = next_frame(&mut scene);
                for &(w, h) in views {
                    renderer
                        .render_reusing(&scene, w, h, &options, &mut stats)
                        .unwrap_or_else(|e| panic!("{case} frame {frame}: {e}"));
                }
            }
            TRACING.store(false, Ordering::Relaxed);
            MEASURING.store(false, Ordering::Relaxed);
            let blocks = INJECTOR_BLOCKS.load(Ordering::Relaxed) - blocks_before;
            let allowed_blocks = (POOL_ENTRIES_PER_FRAME * (MEASURED_RENDER + measured))
                .div_ceil(RAYON_INJECTOR_BLOCK);
            if cell_cap.is_some() {
                assert!(
                    stats.lights.overflowed > 0,
                    "{case}: the cap trimmed no cell"
                );
            }
            let reusing = (CALLS.load(Ordering::Relaxed) - before) as i64;
            eprintln!(
                "{case}: {reusing} allocations over {measured} frames (render_reusing); \
                 render: {by_render} over {MEASURED_RENDER} frames, {expected} of them its stats' \
                 strings; besides, rayon's job queue: {blocks} blocks"
            );
            if reusing > 0 || by_render != expected || blocks > allowed_blocks {
                failures.push(format!(
                    "{case}: {reusing} allocations in {measured} frames of render_reusing, \
                     {by_render} in {MEASURED_RENDER} of render (its stats' strings: {expected}), \
                     {blocks} blocks of rayon's job queue (at most {allowed_blocks})"
                ));
            }
        }
        target.destroy(&app);
    }
    renderer.destroy();
    RENDERS.with(|r| r.set(false));
    failures
}

#[test]
fn no_heap_allocation_per_frame_in_steady_state_es3() {
    let _serial = serial();
    let mut cases = common_cases();
    // MSAA: drawn into the renderer's multisampled target, resolved into the application's.
    cases.push(Case {
        wait_for_gpu: false,
        samples: 4,
        methods: &["forward", "tiled", "clustered", "auto"],
        ..CASE
    });
    // A split screen: two views of two sizes a frame, with MSAA (its target was made anew at
    // every call) and with deferred (its G-buffer likewise).
    cases.push(Case {
        wait_for_gpu: false,
        samples: 4,
        methods: &["forward", "clustered"],
        second_view: true,
        ..CASE
    });
    cases.push(Case {
        methods: &["deferred"],
        second_view: true,
        ..CASE
    });
    let failures = allocations_per_frame(EsVersion::Es3, &Restrictions::default(), &cases);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn no_heap_allocation_per_frame_in_steady_state_es2() {
    let _serial = serial();
    let failures = allocations_per_frame(EsVersion::Es2, &Restrictions::default(), &common_cases());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A device without fragment highp: only forward (and `auto`, which then always picks it)
/// runs, and past 1 023 lights forward keeps the ones that matter most (the cap's selection).
#[test]
fn no_heap_allocation_per_frame_in_steady_state_es2_without_fragment_highp() {
    let _serial = serial();
    let cases = [
        CASE,
        Case {
            lights: 1100,
            wait_for_gpu: false,
            ..CASE
        },
    ];
    let restrictions = Restrictions {
        no_fragment_highp: true,
        ..Default::default()
    };
    let failures = allocations_per_frame(EsVersion::Es2, &restrictions, &cases);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// A warm-up copies none of the scene's lights: it draws a frame with a fresh instance of the
/// method (whose buffers grow with the lights as a fresh method's first frame does) and an
/// ambient-only frame, and no more than that is allocated; a copy of the lights would add a
/// `Light` (96 bytes) a light.
#[test]
fn a_warm_up_copies_none_of_the_lights() {
    let _serial = serial();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let options = RenderOptions::default();
    let renderer = gpu.r();
    let lights = 25_000;
    let scene = with_boxes(scene::builtin::build("courtyard", Some((lights, 5))).unwrap());
    let peak_of = |renderer: &mut Renderer, step: &dyn Fn(&mut Renderer)| {
        let before = LIVE.load(Ordering::Relaxed);
        PEAK.store(before, Ordering::Relaxed);
        step(renderer);
        PEAK.load(Ordering::Relaxed) - before
    };
    // The renderer's own buffers grown, as a game's first frame leaves them.
    renderer.set_method_named("forward").unwrap();
    renderer.render_offscreen(&scene, 32, 18, &options).unwrap();
    // A fresh forward's first frame: what the warm-up's own frame allocates.
    renderer.set_method_named("tiled").unwrap();
    renderer.set_method_named("forward").unwrap();
    let frame = peak_of(renderer, &|r| {
        r.render_offscreen(&scene, 32, 18, &options).unwrap();
    });
    let warm_up = peak_of(renderer, &|r| {
        r.warm_up(&scene, &options).unwrap();
    });
    let light = std::mem::size_of::<manylight::scene::Light>() as isize;
    let copy = lights as isize * light;
    assert!(
        warm_up - frame < copy / 2,
        "the warm-up took {warm_up} bytes at most, a fresh method's frame {frame}: a copy of \
         the lights takes {copy}"
    );
}

/// `Scene::validate` runs every frame: a valid scene using every part it checks (point and
/// spot lights moving, suns, textures on both coordinate sets through transforms) is checked
/// without an allocation, while an invalid one names its field (which allocates: the count
/// sees it).
#[test]
fn validating_a_scene_of_every_part_allocates_nothing() {
    use glam::{Vec2, Vec3};
    use manylight::scene::surface_maps::{MapTexture, TextureTransform};
    use manylight::scene::{Cone, DirectionalLight, Light, Texture};
    let _serial = serial();
    let mut scene = scene::builtin::build("courtyard", Some((64, 5))).unwrap();
    assert!(!scene.animation.is_empty(), "the courtyard's lights move");
    scene.lights.push(Light::spot(
        DVec3::new(0.0, 3.0, 0.0),
        5.0,
        Vec3::ONE,
        2.0,
        Cone {
            direction: DVec3::NEG_Y,
            inner_deg: 20.0,
            outer_deg: 30.0,
        },
    ));
    scene.directional_lights.push(DirectionalLight::new(
        DVec3::new(-0.3, -1.0, 0.2),
        Vec3::ONE,
        1.5,
    ));
    let image = image::RgbaImage::from_pixel(4, 4, image::Rgba([128, 128, 255, 255]));
    let texture = Arc::new(Texture::new("map", image));
    let on_set = |uv_set| {
        Some(MapTexture {
            texture: texture.clone(),
            transform: TextureTransform {
                offset: Vec2::new(0.25, 0.5),
                rotation: 0.3,
                scale: Vec2::splat(2.0),
                uv_set,
            },
        })
    };
    for m in &mut scene.materials {
        m.diffuse_texture = Some(texture.clone());
        m.maps.base_transform = on_set(1).unwrap().transform;
        m.maps.normal = on_set(0);
        m.maps.occlusion = on_set(1);
        m.maps.emissive = Vec3::splat(0.5);
        m.maps.emissive_texture = on_set(0);
        m.maps.metallic_roughness = on_set(1);
    }
    let calls_of = |scene: &Scene| {
        RENDERS.with(|r| r.set(true));
        let before = CALLS.load(Ordering::Relaxed);
        let result = scene.validate();
        let calls = CALLS.load(Ordering::Relaxed) - before;
        RENDERS.with(|r| r.set(false));
        (result, calls)
    };
    let (result, calls) = calls_of(&scene);
    result.unwrap();
    assert_eq!(calls, 0, "validating a valid scene allocated {calls} times");
    scene.lights[3].intensity = f32::NAN;
    let (result, calls) = calls_of(&scene);
    let error = result.unwrap_err().to_string();
    assert!(error.contains("lights[3]"), "{error}");
    assert!(
        calls > 0,
        "naming the field allocated nothing: the count sees nothing"
    );
}

/// Contexts made and dropped again and again on one thread keep no file descriptor or
/// connection behind, and on one thread after another (a test harness's way) at most one a
/// thread. ANGLE keeps an X connection from each `eglInitialize`, and the display was
/// terminated at each last drop and initialised again: its 255th context failed
/// ("eglInitialize failed: EGL_NOT_INITIALIZED", Xvfb's 256 clients). It is now terminated
/// only when another thread makes the next one (docs/drivers.md: a thread change still costs
/// a connection there).
#[test]
#[cfg(target_os = "linux")]
fn contexts_made_and_dropped_again_and_again_keep_nothing_open() {
    let open = || std::fs::read_dir("/proc/self/fd").unwrap().count();
    let before = open();
    for i in 0..300 {
        let context =
            HeadlessContext::new(EsVersion::Es3).unwrap_or_else(|e| panic!("context {i}: {e}"));
        drop(context);
    }
    let threads = 20;
    for t in 0..threads {
        std::thread::spawn(move || {
            for i in 0..3 {
                let context = HeadlessContext::new(EsVersion::Es2)
                    .unwrap_or_else(|e| panic!("thread {t}, context {i}: {e}"));
                drop(context);
            }
        })
        .join()
        .unwrap();
    }
    // Other tests of this binary open and close files meanwhile: a margin for them, far
    // below one a context.
    let after = open();
    assert!(
        after <= before + threads + 40,
        "{before} descriptors open before 360 contexts, {after} after"
    );
}

/// A burst of lights (20 000 for three frames, an explosion's sparks) grows the renderer's CPU
/// buffers by megabytes; once `SHRINK_AFTER` frames in a row have needed a quarter of them at
/// most, they are given back: the live heap returns to within a twentieth of the burst's
/// growth, whether 20 lights go on moving in view or none is left in view (frames the method
/// does not draw). The next lit frame draws the picture of a renderer that saw no burst.
#[test]
fn a_burst_of_lights_gives_its_cpu_memory_back() {
    use manylight::gl::texture::SHRINK_AFTER;
    let _serial = serial();
    let few = with_boxes(scene::builtin::build("courtyard", Some((20, 5))).unwrap());
    let many = with_boxes(scene::builtin::build("courtyard", Some((20_000, 5))).unwrap());
    let mut dark = few.clone();
    for light in &mut dark.lights {
        light.position.y -= 1e5;
    }
    let opts = RenderOptions::default();
    for method in ["forward", "tiled", "clustered", "deferred"] {
        let expected = Gpu::new(EsVersion::Es3)
            .render_with(method, &few, (16, 9), &opts)
            .0;
        for (after, what) in [(&few, "20 lights in view"), (&dark, "none in view")] {
            let mut gpu = Gpu::new(EsVersion::Es3);
            gpu.r().set_method_named(method).unwrap();
            let mut frames = |scene: &Scene, count: usize| {
                let start: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
                let mut moving = scene.clone();
                for frame in 0..count {
                    move_lights(&mut moving, &start, frame);
                    gpu.r().render_offscreen(&moving, 16, 9, &opts).unwrap();
                }
            };
            frames(&few, 5);
            let before = LIVE.load(Ordering::Relaxed);
            frames(&many, 3);
            let burst = LIVE.load(Ordering::Relaxed) - before;
            frames(after, SHRINK_AFTER as usize + 2);
            let kept = LIVE.load(Ordering::Relaxed) - before;
            let what = format!("{method}, then {what}");
            eprintln!("{what}: {burst} bytes for the burst, {kept} kept after");
            assert!(burst > 1 << 20, "{what}: the burst took {burst} bytes");
            assert!(
                kept < burst / 20,
                "{what}: {kept} of the burst's {burst} bytes kept"
            );
            let (image, _) = gpu.render_with(method, &few, (16, 9), &opts);
            let d = manylight::metrics::diff(&image, &expected);
            assert_eq!(d.max_abs, 0, "{what}: the next frame differs");
        }
    }
}
