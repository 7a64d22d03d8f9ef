//! The method table: what each context supports, and `auto`'s choices.

mod common;

use common::Gpu;
use manylight::methods::{Support, METHODS};
use manylight::scene;
use manylight::{EsVersion, RenderOptions};

#[test]
fn the_table_lists_every_method_with_its_support_per_context() {
    let names: Vec<_> = METHODS.iter().map(|m| m.name).collect();
    assert_eq!(names, ["forward", "tiled", "clustered", "deferred", "auto"]);
    for es in [EsVersion::Es2, EsVersion::Es3] {
        let gpu = Gpu::new(es);
        let caps = gpu.renderer.as_ref().unwrap().caps().clone();
        for m in METHODS {
            let support = (m.supported)(&caps);
            let expect_unsupported = m.name == "deferred" && es == EsVersion::Es2;
            assert_eq!(
                matches!(support, Support::Unsupported(_)),
                expect_unsupported,
                "{es} {}: {support:?}",
                m.name
            );
            assert!(m.min_es <= es || expect_unsupported, "{}", m.name);
        }
    }
}

#[test]
fn auto_picks_forward_for_few_lights_and_clustered_for_many_and_says_why() {
    let mut gpu = Gpu::new(EsVersion::Es2);
    for (lights, expected) in [(8, "forward"), (1024, "clustered")] {
        let s = scene::builtin::build("pillars", Some((lights, 3))).unwrap();
        gpu.r().set_method_named("forward").unwrap();
        let (reference, _) = gpu
            .r()
            .render_offscreen(&s, 128, 72, &RenderOptions::default())
            .unwrap();
        gpu.r().set_method_named("auto").unwrap();
        let (img, stats) = gpu
            .r()
            .render_offscreen(&s, 128, 72, &RenderOptions::default())
            .unwrap();
        assert_eq!(stats.method, "auto");
        assert_eq!(
            stats.auto_choice.as_deref(),
            Some(expected),
            "{lights} lights"
        );
        assert!(stats
            .auto_reason
            .as_deref()
            .is_some_and(|r| r.contains("lights")));
        assert!(manylight::metrics::diff(&reference, &img).max_abs <= 2);
    }
}
