//! `RenderOptions::max_assign_threads`: a game whose own rayon jobs fill the global pool can
//! keep the light assignment on its render thread. With the default, a frame called from
//! outside the pool waits for one of the pool's workers (the frame stalled behind a game's
//! long job, an embedding review found); with 1 it never enters rayon. A program of its own:
//! its tests hold every worker of the global pool, one test at a time.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc, Barrier, Mutex, MutexGuard};
use std::time::Duration;

use common::Gpu;
use manylight::{EsVersion, RenderOptions};

/// Lights enough that the assignment's rules take the pool (from 4 096).
const LIGHTS: usize = 8192;

/// Each test holds the global pool's workers: one at a time.
fn alone() -> MutexGuard<'static, ()> {
    static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// Holds every worker of rayon's global pool in a job until the returned sender is dropped or
/// sent to; returns once all of them are held.
fn hold_the_global_pool() -> mpsc::Sender<()> {
    let workers = rayon::current_num_threads();
    let (release, wait) = mpsc::channel::<()>();
    let wait = Arc::new(std::sync::Mutex::new(wait));
    let held = Arc::new(Barrier::new(workers + 1));
    for _ in 0..workers {
        let (wait, held) = (wait.clone(), held.clone());
        rayon::spawn(move || {
            held.wait();
            // Each job waits for the one release (or the sender's drop) in turn.
            let _ = wait.lock().unwrap().recv();
        });
    }
    held.wait();
    release
}

/// Renders on `gpu` while the global pool is held; a watchdog lets the pool go after `patience`
/// and says whether it had to (the frame waited for a worker).
fn frame_waited_for_the_pool(
    gpu: &mut Gpu,
    options: &RenderOptions,
    patience: Duration,
) -> (bool, usize) {
    let scene = manylight::scene::builtin::build("courtyard", Some((LIGHTS, 5))).unwrap();
    let mut threads = 0;
    let waited = waited_for_the_held_pool(patience, || {
        let (_, stats) = gpu
            .r()
            .render_offscreen(&scene, 64, 36, options)
            .expect("render");
        threads = stats.assignment.threads;
    });
    (waited, threads)
}

/// Runs `work` while every worker of the global pool is held; a watchdog lets the pool go
/// after `patience` and says whether it had to (`work` waited for a worker).
fn waited_for_the_held_pool(patience: Duration, work: impl FnOnce()) -> bool {
    let release = hold_the_global_pool();
    let workers = rayon::current_num_threads();
    let had_to = Arc::new(AtomicBool::new(false));
    let (done, finished) = mpsc::channel::<()>();
    let watchdog = {
        let had_to = had_to.clone();
        std::thread::spawn(move || {
            if finished.recv_timeout(patience).is_err() {
                had_to.store(true, Ordering::SeqCst);
            }
            // Every held job takes one release.
            for _ in 0..workers {
                let _ = release.send(());
            }
        })
    };
    work();
    let _ = done.send(());
    watchdog.join().unwrap();
    had_to.load(Ordering::SeqCst)
}

#[test]
fn one_assignment_thread_never_waits_for_a_busy_pool() {
    let _alone = alone();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let one = RenderOptions {
        max_assign_threads: 1,
        ..RenderOptions::default()
    };
    for method in ["clustered", "tiled"] {
        gpu.r().set_method_named(method).unwrap();
        let (waited, threads) = frame_waited_for_the_pool(&mut gpu, &one, Duration::from_secs(60));
        assert!(!waited, "{method}: the frame waited for the held pool");
        assert_eq!(threads, 1, "{method}");
    }
    // The hazard the option avoids: by default the same frame takes the pool, and waits.
    if rayon::current_num_threads() >= 2 {
        gpu.r().set_method_named("clustered").unwrap();
        let default = RenderOptions::default();
        let (waited, threads) =
            frame_waited_for_the_pool(&mut gpu, &default, Duration::from_secs(2));
        assert!(waited && threads >= 2, "waited {waited}, {threads} threads");
    }
    // Posing moving lights: `set_time_on_this_thread` never waits for the pool and poses
    // what `set_time` poses; `set_time` itself takes the pool at this many lights, and waits.
    let mut scene = manylight::scene::builtin::build("courtyard", Some((LIGHTS, 5))).unwrap();
    assert!(scene.animation.iter().any(|t| t.rest.len() >= 4096));
    let mut posed = scene.clone();
    let waited = waited_for_the_held_pool(Duration::from_secs(60), || {
        scene.set_time_on_this_thread(2.5);
    });
    assert!(!waited, "set_time_on_this_thread waited for the held pool");
    if rayon::current_num_threads() >= 2 {
        let waited = waited_for_the_held_pool(Duration::from_secs(2), || posed.set_time(2.5));
        assert!(waited, "set_time did not take the pool");
    } else {
        posed.set_time(2.5);
    }
    assert_eq!(scene.lights, posed.lights);
    // 0 threads is refused naming the field.
    let none = RenderOptions {
        max_assign_threads: 0,
        ..RenderOptions::default()
    };
    let scene = manylight::scene::builtin::build("plane", Some((4, 1))).unwrap();
    let err = gpu.r().render_offscreen(&scene, 8, 8, &none).unwrap_err();
    assert!(err.to_string().contains("max_assign_threads"), "{err}");
}

/// Where renderer calls take turns (llvmpipe), a frame whose assignment waited for the pool
/// held the turn meanwhile, and the pool's workers, each in a renderer call of its own (views
/// rendered in rayon jobs), waited for the turn: neither ever went on. The frame now lets the
/// turn go while it waits for the pool, which it has when the workers' jobs end (each renders
/// for a few seconds, long enough to be under way when the frame's assignment starts).
/// Mesa only: elsewhere calls take no turns, and ANGLE makes a second thread's context wait
/// until the first thread's are gone.
#[test]
fn a_frame_waiting_for_the_pool_lets_the_pools_renderers_go_on() {
    if !common::renders_with_mesa() {
        return;
    }
    let _alone = alone();
    let (done, finished) = mpsc::channel();
    std::thread::spawn(move || {
        for _ in 0..rayon::current_num_threads() {
            rayon::spawn(move || {
                let mut gpu = Gpu::new(EsVersion::Es3);
                let scene = manylight::scene::builtin::build("plane", Some((16, 1))).unwrap();
                let one = RenderOptions {
                    max_assign_threads: 1,
                    ..RenderOptions::default()
                };
                let begun = std::time::Instant::now();
                while begun.elapsed() < Duration::from_secs(4) {
                    gpu.r().render_offscreen(&scene, 32, 18, &one).unwrap();
                }
            });
        }
        let mut gpu = Gpu::new(EsVersion::Es3);
        let scene = manylight::scene::builtin::build("courtyard", Some((LIGHTS, 5))).unwrap();
        let mut threads = 0;
        for _ in 0..3 {
            let (_, stats) = (gpu.r())
                .render_offscreen(&scene, 32, 18, &RenderOptions::default())
                .unwrap();
            threads = threads.max(stats.assignment.threads);
        }
        let _ = done.send(threads);
    });
    let Ok(threads) = finished.recv_timeout(Duration::from_secs(300)) else {
        // The pool's workers stay stuck, and the other test would wait for them for good: the
        // process ends, saying why past the harness's capture of `eprintln!`.
        let why = "three frames did not finish in 5 minutes: the frame and the pool wait for \
                   each other\n";
        let _ = std::io::Write::write_all(&mut std::io::stderr(), why.as_bytes());
        std::process::exit(1);
    };
    if rayon::current_num_threads() >= 2 {
        assert!(threads >= 2, "the assignment never took the pool");
    }
}
