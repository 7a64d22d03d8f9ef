//! Memory stays flat over many frames: with lights moving every frame, after a warm-up the
//! renderer's live heap bytes (counted by this test binary's allocator) and its live GL objects
//! do not grow, for every method. `cargo bench --bench soak` runs the long version (2 000
//! frames a method, resident memory sampled; docs/performance.md has its figures).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicIsize, Ordering};

use common::Gpu;
use glam::DVec3;
use manylight::methods::METHODS;
use manylight::{scene, EsVersion, RenderOptions};

/// The system allocator, keeping a count of the bytes live.
struct Counting;

static LIVE: AtomicIsize = AtomicIsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size() as isize, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as isize, Ordering::Relaxed);
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE.fetch_add(
            new_size as isize - layout.size() as isize,
            Ordering::Relaxed,
        );
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

#[test]
fn live_heap_and_gl_objects_stay_flat_over_frames_of_moving_lights() {
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut scene = scene::builtin::build("courtyard", Some((128, 5))).unwrap();
    let start: Vec<DVec3> = scene.lights.iter().map(|l| l.position).collect();
    let options = RenderOptions::default();
    let (warm_up, measured) = (40, 120);
    for method in METHODS.iter().map(|m| m.name) {
        gpu.r().set_method(method).unwrap();
        let mut at_warm_up = None;
        for frame in 0..warm_up + measured {
            let t = frame as f64 / 30.0;
            for (i, (light, origin)) in scene.lights.iter_mut().zip(&start).enumerate() {
                let a = t * (1.0 + (i % 5) as f64) + i as f64;
                light.position = *origin + DVec3::new(a.cos(), 0.2 * a.sin(), a.sin());
            }
            gpu.r()
                .render_offscreen(&scene, 48, 27, &options)
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
