//! A warning, once a renderer, when a frame has nothing to draw.

/// Warns (once: `warned`) of a scene without a triangle to draw (no objects, or meshes with
/// no indices): its frames are the clear colour alone, which a game may mean (a loading
/// screen) but a broken import does not.
pub(super) fn warn_of_nothing_to_draw(scene: &crate::scene::Scene, warned: &mut bool) {
    if *warned || scene.objects.iter().any(|o| !o.mesh.indices.is_empty()) {
        return;
    }
    *warned = true;
    log::warn!(
        "the scene has no triangles to draw ({} objects): its frames show the clear colour \
         alone",
        scene.objects.len()
    );
}
