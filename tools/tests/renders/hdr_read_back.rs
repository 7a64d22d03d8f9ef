//! HDR read-back on an ES 2.0 context itself (a Mali-T6xx or Adreno 3xx with the half-float
//! extensions), not an ES 3.x one keeping to ES 2.0: there `glReadPixels` may take only the
//! context's own read format. Mesa capped to ES 2.0 refuses `RGBA`/`FLOAT` from a half-float
//! target (every HDR render failed with `GL_INVALID_OPERATION` while `Caps::hdr_output` said
//! yes) and reads it as `RGBA`/`HALF_FLOAT_OES`.

use crate::common;

use common::Gpu;
use manylight::{EsVersion, RenderOptions};

/// Set in the child process whose contexts Mesa caps to ES 2.0.
const PURE_ES2: &str = "MANYLIGHT_TEST_PURE_ES2";

#[test]
fn hdr_reads_back_what_the_linear_picture_shows_on_a_pure_es2_context() {
    let pure = std::env::var_os(PURE_ES2).is_some();
    if !pure && !common::other_implementation_than_mesa("MESA_GLES_VERSION_OVERRIDE") {
        common::child::rerun_with(
            "hdr_read_back::hdr_reads_back_what_the_linear_picture_shows_on_a_pure_es2_context",
            &[("MESA_GLES_VERSION_OVERRIDE", "2.0"), (PURE_ES2, "1")],
            "on ES 2.0",
        );
    }
    // Here too: the ES 2.0 context this implementation gives.
    let mut gpu = Gpu::new(EsVersion::Es2);
    let caps = gpu.r().caps().clone();
    if pure {
        assert!(
            caps.gl_version.contains("OpenGL ES 2.0"),
            "{}",
            caps.gl_version
        );
        // Mesa's ES 2.0 has the half-float extensions: the check below is not skipped.
        assert!(caps.hdr_output(), "{:?}", caps.extensions);
    }
    let scene = manylight::scene::builtin::build("plane", Some((8, 1))).unwrap();
    let options = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let hdr = gpu.r().render_offscreen_hdr(&scene, 32, 18, &options);
    assert_eq!(caps.hdr_output(), hdr.is_ok(), "{:?}", hdr.as_ref().err());
    let Ok((hdr, _)) = hdr else {
        return;
    };
    let (linear, _) = gpu.r().render_offscreen(&scene, 32, 18, &options).unwrap();
    // Where the radiance is below 1 the 8-bit linear picture is it rounded (each from its
    // own fp16 sums on llvmpipe: 2/255).
    let mut lit = 0;
    for (i, p) in linear.pixels().enumerate() {
        for c in 0..3 {
            let (h, l) = (hdr[i][c], f32::from(p.0[c]) / 255.0);
            assert!(h.is_finite(), "pixel {i}: {:?}", hdr[i]);
            if h < 1.0 {
                assert!(
                    (h - l).abs() <= 2.0 / 255.0,
                    "pixel {i} channel {c}: {h} / {l}"
                );
            }
            lit += usize::from(h > 0.1);
        }
    }
    assert!(lit > 100, "a lit picture: {lit} channels above 0.1");
}
