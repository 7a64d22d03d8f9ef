//! Objects that repeat an earlier one exactly: the same mesh, material and placement. On an
//! opaque surface each copy adds only overdraw, every copy of a pixel shaded again.
//! Transparent ones keep their copies (each blends once more).

use std::cmp::Ordering;
use std::sync::Arc;

use super::{Object, Scene};

/// Drops every opaque object equal to an earlier one (mesh shared, same material index,
/// bit-identical transform), keeping the order of the rest; returns how many were dropped.
/// Sorts object numbers (4 bytes an object), so the search holds no copy of the keys.
pub(super) fn drop_repeated_objects(scene: &mut Scene) -> usize {
    let objects = &scene.objects;
    let materials = &scene.materials;
    let opaque = |o: &Object| {
        materials
            .get(o.material)
            .is_some_and(|m| !m.is_transparent())
    };
    let mut order: Vec<u32> = (0..objects.len() as u32)
        .filter(|&i| opaque(&objects[i as usize]))
        .collect();
    // Equal objects side by side, the earliest first among them.
    order.sort_unstable_by(|&a, &b| {
        compare(&objects[a as usize], &objects[b as usize]).then(a.cmp(&b))
    });
    let mut repeated = vec![false; objects.len()];
    for pair in order.windows(2) {
        let (first, next) = (&objects[pair[0] as usize], &objects[pair[1] as usize]);
        if compare(first, next) == Ordering::Equal {
            repeated[pair[1] as usize] = true;
        }
    }
    let before = objects.len();
    let mut i = 0;
    scene.objects.retain(|_| {
        i += 1;
        !repeated[i - 1]
    });
    before - scene.objects.len()
}

/// Orders objects by mesh, material and transform bits: equal when each is the same.
fn compare(a: &Object, b: &Object) -> Ordering {
    let bits = |o: &Object| o.transform.to_cols_array().map(f64::to_bits);
    Arc::as_ptr(&a.mesh)
        .cmp(&Arc::as_ptr(&b.mesh))
        .then(a.material.cmp(&b.material))
        .then_with(|| bits(a).cmp(&bits(b)))
}

#[cfg(test)]
mod tests {
    use crate::scene::meshbuild::MeshBuilder;
    use crate::scene::{Material, Scene};
    use glam::{DMat4, DVec3, Vec3};

    /// A scene file placing the plane five times: three alike, one moved, one recoloured.
    /// The two repeats go, with a warning; what differs stays.
    #[cfg(feature = "scene-files")]
    #[test]
    fn exact_repeats_of_an_object_are_dropped_at_load_with_a_warning() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.json");
        let plane = r#"{"builtin": "plane"}"#;
        let moved = r#"{"builtin": "plane", "transform": {"translate": [0, 0, 1]}}"#;
        let red = r#"{"builtin": "plane", "color": [1, 0, 0]}"#;
        let objects = [plane, plane, moved, plane, red].join(",");
        std::fs::write(&path, format!(r#"{{"objects": [{objects}]}}"#)).unwrap();
        let (scene, report) = crate::scene::load(path.to_str().unwrap(), None).unwrap();
        let once = crate::scene::builtin::build("plane", None)
            .unwrap()
            .objects
            .len();
        assert_eq!(scene.objects.len(), 3 * once);
        let said: Vec<_> = report
            .warnings
            .iter()
            .filter(|w| w.contains("repeat"))
            .collect();
        assert_eq!(said.len(), 1, "{:?}", report.warnings);
        assert!(
            said[0].contains(&format!("{} objects repeat", 2 * once)),
            "{said:?}"
        );
    }

    /// Copies of a transparent object each blend once more: kept.
    #[test]
    fn transparent_repeats_are_kept() {
        let mut s = Scene::empty();
        let mut glass = Material::flat("glass", Vec3::ONE);
        glass.alpha = 0.5;
        let glass = s.add_material(glass);
        let stone = s.add_material(Material::flat("stone", Vec3::ONE));
        let mut b = MeshBuilder::new();
        b.quad(Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y);
        let mesh = std::sync::Arc::new(b.build().unwrap());
        for material in [glass, glass, stone, stone] {
            s.add_object(mesh.clone(), material, DMat4::from_translation(DVec3::ZERO));
        }
        assert_eq!(super::drop_repeated_objects(&mut s), 1);
        let kept: Vec<_> = s.objects.iter().map(|o| o.material).collect();
        assert_eq!(kept, [glass, glass, stone]);
    }
}
