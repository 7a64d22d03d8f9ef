//! A scene with no triangles to draw renders the clear colour alone, as a game may mean it
//! (a loading screen), but never silently: the library warned of nothing, so a broken import
//! in a game gave black frames without a word (helper-129).

use crate::common;

use common::warnings::warnings_containing;
use common::Gpu;
use manylight::scene::{self, Scene};
use manylight::{EsVersion, RenderOptions};

#[test]
fn a_scene_without_triangles_is_warned_of_once_a_renderer() {
    common::warnings::install();
    let said = || warnings_containing("has no triangles to draw (0 objects)").len();
    let before = said();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let mut empty = Scene::empty();
    empty.lights = scene::builtin::build("plane", Some((4, 1))).unwrap().lights;
    for _ in 0..2 {
        let (img, _) = gpu
            .r()
            .render_offscreen(&empty, 32, 18, &RenderOptions::default())
            .unwrap();
        assert!(
            img.pixels().all(|p| p.0[..3] == [0, 0, 0]),
            "not the clear colour"
        );
    }
    assert_eq!(said(), before + 1, "warned once a renderer");
    drop(gpu);
    let plane = scene::builtin::build("plane", Some((4, 1))).unwrap();
    let quiet = warnings_containing("has no triangles to draw").len();
    Gpu::new(EsVersion::Es3)
        .r()
        .render_offscreen(&plane, 32, 18, &RenderOptions::default())
        .unwrap();
    assert_eq!(
        warnings_containing("has no triangles to draw").len(),
        quiet,
        "a scene with triangles is not warned of"
    );
}
