//! An OBJ's load takes no more memory than the bound it asks of the allocator before tobj
//! parses it (`obj::load_memory_bound`): a failed allocation inside tobj would abort the
//! process, so that request is all that stands between a file too large for the machine and
//! an abort. Each file below is shaped to make one part of the load as large as it gets
//! (tobj's vertex lists, its face list, a polygon's own list, its meshes' vertices and
//! indices, the per-object costs, the rewrites before tobj), and the bound must cover the
//! peak of live bytes counted by the allocator. It must also stay near what real meshes take,
//! or it would refuse files the machine could load.

use std::alloc::{GlobalAlloc, Layout, System};
use std::fmt::Write;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::DMat4;
use manylight::scene::obj;
use manylight::scene::Scene;

/// The system allocator, keeping the live bytes and their peak. An allocation of exactly
/// [`PROBE`] bytes is the load's request for its bound, given back at once: not counted.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
static PROBE: AtomicUsize = AtomicUsize::new(0);

fn grew(bytes: usize) {
    let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

fn counted(size: usize) -> bool {
    size != PROBE.load(Ordering::Relaxed)
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if counted(layout.size()) {
            grew(layout.size());
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if counted(layout.size()) {
            grew(layout.size());
        }
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if counted(layout.size()) {
            LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // Old and new blocks may both be live while the contents move.
        grew(new_size);
        let moved = unsafe { System.realloc(ptr, layout, new_size) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        moved
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The peak of live bytes while `path` loads, over those live before, and what the load
/// asks for: to rewrite the text, and to parse it as bounded from its corners written and
/// from its distinct corners.
fn load_peak(path: &Path) -> (usize, u64, [u64; 2]) {
    let text = std::fs::read_to_string(path).unwrap();
    let (rewrite, written) = obj::load_memory_bounds(&text, false);
    let (_, distinct) = obj::load_memory_bounds(&text, true);
    drop(text);
    // The parse's request, given back at once, is not the load's memory.
    let bound = written;
    PROBE.store(bound as usize, Ordering::Relaxed);
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let mut scene = Scene::empty();
    let mut textures = manylight::scene::texture_budget::TextureBudget::default();
    let report = obj::load_into(
        &mut scene,
        path,
        DMat4::IDENTITY,
        None,
        &manylight::LoadOptions::default(),
        &mut textures,
    );
    let peak = PEAK.load(Ordering::Relaxed) - before;
    PROBE.store(0, Ordering::Relaxed);
    report.unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(!scene.objects.is_empty());
    (peak, rewrite, [written, distinct])
}

/// A `side`² grid of shared vertices with texture coordinates and normals, drawn as quads:
/// a mesh as exporters write them (each vertex in about six triangles).
fn grid(side: usize) -> String {
    let mut s = String::new();
    for y in 0..side {
        for x in 0..side {
            let (u, v) = (x as f32 / side as f32, y as f32 / side as f32);
            writeln!(s, "v {u} {v} 0\nvt {u} {v}\nvn 0 0 1").unwrap();
        }
    }
    for y in 0..side - 1 {
        for x in 0..side - 1 {
            let i = y * side + x + 1;
            let [a, b, c, d] = [i, i + 1, i + side + 1, i + side];
            writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c} {d}/{d}/{d}").unwrap();
        }
    }
    s
}

/// `n` triangles of their own three vertices each: a distinct vertex for every corner.
fn soup(n: usize) -> String {
    let mut s = String::new();
    for i in 0..n {
        let x = i as f32 * 0.001;
        writeln!(s, "v {x} 0 0\nv {x} 1 0\nv {x} 0 1\nvt 0 0\nvn 1 0 0").unwrap();
        writeln!(s, "f -3/-1/-1 -2/-1/-1 -1/-1/-1").unwrap();
    }
    s
}

/// One face of `corners` corners over four vertices: tobj keeps a list of its own for it.
fn fan(corners: usize) -> String {
    let mut s = String::from("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf");
    for i in 0..corners {
        write!(s, " {}", 1 + i % 4).unwrap();
    }
    s.push('\n');
    s
}

/// The same triangle `n` times, the shortest face line: tobj's face list at its largest
/// against the file's size.
fn repeated(n: usize) -> String {
    "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_string() + &"f 1 2 3\n".repeat(n)
}

/// `n` coloured vertices no face uses, and one triangle.
fn unused_vertices(n: usize) -> String {
    "v 0 0 0 1 1 1\n".repeat(n) + "f 1 2 3\n"
}

/// `n` objects of one quad each, over coloured vertices, the material changing between them.
fn objects(n: usize) -> String {
    let mut s = String::new();
    for i in 0..n {
        let x = i as f32;
        writeln!(s, "o part{i}\nusemtl m{}", i % 2).unwrap();
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            writeln!(s, "v {} {dy} 0 0.5 0.5 0.5", x + dx).unwrap();
        }
        s.push_str("f -4 -3 -2 -1\n");
    }
    s
}

/// Faces naming texture coordinates in some corners and not others, and one-number `vt`
/// lines: both rewritten before tobj reads the file.
fn rewritten(n: usize) -> String {
    let mut s = String::from("vt 0.5\n");
    for i in 0..n {
        writeln!(s, "v {} 0 0\nv {} 1 0\nv {} 0 1", i, i, i).unwrap();
        writeln!(s, "f -3/1 -2 -1").unwrap();
    }
    s
}

#[test]
fn a_load_takes_no_more_than_its_bound() {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        ("grid", grid(300)),
        ("soup", soup(60_000)),
        ("fan", fan(300_000)),
        ("repeated", repeated(200_000)),
        ("unused_vertices", unused_vertices(200_000)),
        ("objects", objects(3_000)),
        ("rewritten", rewritten(60_000)),
    ];
    for (name, text) in files {
        let path = dir.path().join(format!("{name}.obj"));
        std::fs::write(&path, &text).unwrap();
        let (peak, rewrite, [written, distinct]) = load_peak(&path);
        // The file's bytes and its text are both live while it is read; a rewritten text
        // lives beside the parse.
        let text = 2 * text.len() as u64 + if name == "rewritten" { rewrite } else { 0 };
        let load = peak.saturating_sub(text as usize).max(1) as f64;
        eprintln!(
            "{name}: peak {peak} bytes, text {text}, bounds {written} and {distinct} \
             ({:.2}x and {:.2}x what the load took besides the text)",
            written as f64 / load,
            distinct as f64 / load
        );
        assert!(distinct <= written, "{name}: {distinct} against {written}");
        assert!(
            peak as u64 <= distinct + text,
            "{name}: the load took {peak} bytes, past its bound {distinct} and the text's {text}"
        );
        // Bounded by its distinct corners, a mesh as exporters write them, or all of whose
        // corners are distinct, is refused only where less than a third of its need is free.
        if matches!(name, "grid" | "soup") {
            assert!(
                distinct as f64 <= 3.0 * load,
                "{name}: the bound {distinct} is far above the {load} bytes the load took"
            );
        }
    }
}
