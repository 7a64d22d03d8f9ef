//! `auto` on a driver with no memory for deferred's G-buffer (played by a test hook in
//! `gl::gbuffer`, since a real driver's out-of-memory cannot be provoked safely).

use crate::cluster::pack::MAX_INDEXED_LIGHTS;
use crate::gl::context::context_or_skip;
use crate::gl::gbuffer::REFUSE_NEXT;
use crate::gl::EsVersion;
use crate::scene::Light;
use crate::{RenderOptions, Renderer};

/// More lights in view than clustered indexes: `auto`'s turn for deferred. When its G-buffer
/// cannot be allocated, forward draws the frame (an error before) and says why; a frame as
/// large does not ask the driver again, a smaller one does.
#[test]
fn auto_draws_with_forward_when_the_gbuffer_does_not_fit_in_memory() {
    let Some(ctx) = context_or_skip(EsVersion::Es3) else {
        return;
    };
    let mut renderer = Renderer::new(ctx.load_gl().unwrap(), EsVersion::Es3).unwrap();
    // 260 rows of 256 small dim lights just above the plane, all in view.
    let mut s = crate::scene::builtin::build("plane", None).unwrap();
    s.lights.clear();
    for row in 0..260 {
        for column in 0..256 {
            let at = glam::DVec3::new(column as f64 / 64.0 - 2.0, row as f64 / 108.0 - 1.2, 0.2);
            s.lights.push(Light::point(at, 0.3, glam::Vec3::ONE, 1e-3));
        }
    }
    assert!(s.lights.len() > MAX_INDEXED_LIGHTS);
    renderer.set_method_named("auto").unwrap();
    let options = RenderOptions::default();
    REFUSE_NEXT.with(|r| r.set(true));
    // Small frames: forward over 66 560 lights is a software GPU's slow part.
    let (_, stats) = renderer.render_offscreen(&s, 16, 9, &options).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("forward"));
    let reason = stats.auto_reason.unwrap_or_default();
    assert!(
        reason.contains("deferred cannot: no memory for a 16×9 G-buffer"),
        "{reason}"
    );
    // Refused once: the next frame of that size does not try (the hook would let it).
    let (_, stats) = renderer.render_offscreen(&s, 16, 9, &options).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("forward"));
    // A smaller one does, and gets its G-buffer.
    let (_, stats) = renderer.render_offscreen(&s, 8, 4, &options).unwrap();
    assert_eq!(stats.auto_choice.as_deref(), Some("deferred"));
    assert!(stats.memory.gbuffer_bytes > 0);
}
