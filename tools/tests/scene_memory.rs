//! Meshes built in code and the ray caster's hierarchies (the automatic grid's surface sample,
//! the CPU reference) ask the allocator before they grow: where it refuses (an address-space
//! limit, a 32-bit process), the builder names the shape and the caster leaves the mesh out,
//! where a buffer grown without asking aborted the process (a 5 791² sphere under
//! `ulimit -v 2000000`; a 12.5 M-triangle mesh's hierarchy on the default method's first
//! frame).
//!
//! This program's allocator refuses every allocation past a size the test sets
//! (`common/refusing_allocator.rs`): a buffer that grows without asking aborts the program, so
//! the test fails.

use glam::{DMat4, DVec3, Vec3};
use manylight::scene::raycast::SceneRaycaster;
use manylight::{Material, MeshBuilder, Scene};

#[path = "common/refusing_allocator.rs"]
mod refusing_allocator;
use refusing_allocator::{refusing_past, serial, Refusing};

#[global_allocator]
static ALLOCATOR: Refusing = Refusing;

/// A UV sphere of 401² vertices (about 320 000 triangles; 1.9 MB of positions) at `centre`.
fn large_sphere(builder: &mut MeshBuilder, centre: Vec3) {
    builder.sphere(centre, 1.0, 400, 400);
}

/// A shape the allocator refuses adds nothing, and `build` names it; the shapes before it are
/// kept out of the mesh, as for a shape whose values are refused.
#[test]
fn a_shape_the_allocator_refuses_is_named_by_build() {
    let _serial = serial();
    let refused = refusing_past(1 << 20, || {
        let mut builder = MeshBuilder::new();
        builder.cuboid(Vec3::ZERO, Vec3::ONE);
        large_sphere(&mut builder, Vec3::ZERO);
        builder.build().map(|mesh| mesh.positions.len())
    });
    let e = refused
        .expect_err("a sphere past the memory given")
        .to_string();
    assert!(e.contains("MeshBuilder::sphere"), "{e}");
    assert!(e.contains("cannot allocate now"), "{e}");
    let mut builder = MeshBuilder::new();
    large_sphere(&mut builder, Vec3::ZERO);
    assert_eq!(builder.build().unwrap().positions.len(), 401 * 401);
}

/// A mesh whose hierarchy the allocator refuses is left out of the caster and counted; the
/// others are cast as before, and the next caster builds the refused one again.
#[test]
fn a_hierarchy_the_allocator_refuses_leaves_its_mesh_out() {
    let _serial = serial();
    let mut scene = Scene::empty();
    let material = scene.add_material(Material::flat("m", Vec3::splat(0.5)));
    let mut builder = MeshBuilder::new();
    large_sphere(&mut builder, Vec3::ZERO);
    let sphere = builder.build().unwrap();
    let sphere_triangles = sphere.triangle_count() as u64;
    let mut builder = MeshBuilder::new();
    builder.cuboid(Vec3::new(4.0, -1.0, -1.0), Vec3::new(6.0, 1.0, 1.0));
    scene.add_object(sphere, material, DMat4::IDENTITY);
    scene.add_object(builder.build().unwrap(), material, DMat4::IDENTITY);
    let down = DVec3::new(0.0, -1.0, 0.0);
    let (above_sphere, above_box) = (DVec3::new(0.0, 5.0, 0.0), DVec3::new(5.0, 5.0, 0.0));
    // The sphere's triangle boxes alone take 15 MB.
    let caster = refusing_past(4 << 20, || SceneRaycaster::new(&scene));
    assert_eq!(caster.left_out_triangles(), sphere_triangles);
    assert!(
        caster.hit(above_sphere, down).is_none(),
        "a left-out mesh was hit"
    );
    let on_box = caster.hit(above_box, down).expect("the box is cast");
    assert!((on_box.t - 4.0).abs() < 1e-9, "{}", on_box.t);
    let again = SceneRaycaster::rebuilt(Some(caster.keep()), &scene);
    assert_eq!(again.left_out_triangles(), 0);
    assert_eq!(again.meshes_built(), 1, "the refused one, built again");
    let on_sphere = again.hit(above_sphere, down).expect("the sphere is cast");
    assert!((on_sphere.t - 4.0).abs() < 1e-3, "{}", on_sphere.t);
}
