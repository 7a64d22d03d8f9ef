//! The side of a surface the eye sees is its triangles' winding, not its interpolated normal.
//! Near a smooth mesh's silhouette a front face's interpolated normal leans away from the eye;
//! turned towards the eye by `N · V`, as the shaders once did, it lit such pixels from the
//! wrong side (dark notches along silhouettes, or light leaking from behind). A quad whose
//! normals lean away from the eye on its left, lit from the left, must show that side lit, as
//! the light model says, with every method on ES 2.0 and 3.0: as built, mirrored by its
//! transform (the winding turns round on screen), wound the other way (as an OBJ file may
//! be), and seen from behind (the normals reversed). An OBJ without normals whose faces are
//! listed some one way, some the other, looks as the same OBJ listed consistently. A
//! transparent box, which a mirror maps onto itself, looks the same mirrored: its far side
//! still blends first.

use crate::common;

use std::sync::Arc;

use common::{max_oracle_error, Gpu};
use glam::{DMat4, DVec3, Vec3};
use manylight::metrics::cpu_reference::Encoding;
use manylight::scene::raycast::pixel_ray;
use manylight::scene::{Light, Material, Mesh, Object, Scene};
use manylight::MeshBuilder;
use manylight::{Camera, EsVersion, RenderOptions};

const W: u32 = 192;
const H: u32 = 108;

/// The quad's corners in the plane z = 0, counter-clockwise seen from +Z.
const CORNERS: [[f32; 2]; 4] = [[-1.5, -1.0], [1.5, -1.0], [1.5, 1.0], [-1.5, 1.0]];

/// The normals at its left corners lean left and away from +Z, those at its right lean
/// towards +Z: interpolated, they face away from an eye on +Z over the quad's left part.
fn normals() -> [Vec3; 4] {
    let left = Vec3::new(-1.0, 0.0, -0.35).normalize();
    let right = Vec3::new(0.3, 0.0, 1.0).normalize();
    [left, right, right, left]
}

/// The quad, its triangles listed counter-clockwise (or clockwise with `reversed`), placed by
/// `transform`, seen from `eye` and lit from `light` (both mirrored with the transform, so
/// that each scene shows the same picture up to the mirror).
fn scene(transform: DMat4, reversed: bool, eye: DVec3, light: DVec3) -> Scene {
    let positions = CORNERS.map(|[x, y]| Vec3::new(x, y, 0.0)).to_vec();
    let indices = if reversed {
        vec![0, 2, 1, 0, 3, 2]
    } else {
        vec![0, 1, 2, 0, 2, 3]
    };
    let mesh = Mesh::new(positions, normals().to_vec(), vec![], indices).unwrap();
    let mut s = Scene::empty();
    let grey = s.add_material(Material::flat("grey", Vec3::splat(0.8)));
    s.objects.push(Object {
        mesh: Arc::new(mesh),
        material: grey,
        transform,
    });
    s.ambient = Vec3::splat(0.05);
    let place = |p: DVec3| transform.transform_point3(p);
    s.camera = Camera::perspective(place(eye), DVec3::ZERO, 60.0, 0.1, 20.0);
    s.lights = vec![Light::point(place(light), 12.0, Vec3::ONE, 3.0)];
    s.validate().unwrap();
    s
}

/// The four views: as built, mirrored, wound the other way, and seen from behind (the eye and
/// the light on −Z, where the back face's reversed normals lean away from an eye on the left).
fn scenes() -> [(&'static str, Scene); 4] {
    let (eye, light) = (DVec3::new(0.0, 0.0, 4.0), DVec3::new(-3.0, 0.0, 1.0));
    let (eye_behind, light_behind) = (DVec3::new(-2.5, 0.0, -3.0), DVec3::new(2.0, 0.0, -1.0));
    let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    [
        ("as built", scene(DMat4::IDENTITY, false, eye, light)),
        ("mirrored", scene(mirror, false, eye, light)),
        ("wound clockwise", scene(DMat4::IDENTITY, true, eye, light)),
        (
            "from behind",
            scene(DMat4::IDENTITY, false, eye_behind, light_behind),
        ),
    ]
}

/// The pixels where the quad's front face is seen with an interpolated normal leaning away
/// from the eye (`N · V < −0.1`) and facing the light (`N · L > 0.3`), worked out here from
/// the quad's own corners: the light model lights them well above the ambient term.
fn leaning_pixels(s: &Scene, transform: DMat4, behind: bool) -> Vec<(u32, u32)> {
    let to_object = transform.inverse();
    let light = to_object.transform_point3(s.lights[0].position);
    let eye = to_object.transform_point3(s.camera.position);
    let n = normals().map(|n| n.as_dvec3() * if behind { -1.0 } else { 1.0 });
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let (o, d) = pixel_ray(&s.camera, W, H, x as f64 + 0.5, y as f64 + 0.5);
            let (o, d) = (
                to_object.transform_point3(o),
                to_object.transform_vector3(d),
            );
            let p = o + d * (-o.z / d.z);
            // Bilinear over the quad equals the barycentric weights here: the normals vary
            // along x only.
            let u = (p.x + 1.5) / 3.0;
            if !(u > 0.02 && u < 0.98 && p.y.abs() < 0.98) {
                continue;
            }
            let normal = (n[0] * (1.0 - u) + n[1] * u).normalize();
            let v = (eye - p).normalize();
            let l = (light - p).normalize();
            if normal.dot(v) < -0.1 && normal.dot(l) > 0.3 {
                out.push((x, y));
            }
        }
    }
    out
}

#[test]
fn the_side_seen_is_the_windings_with_every_method() {
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let mirror = DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0));
    common::each_method(|es, method, gpu| {
        for (i, (what, s)) in scenes().iter().enumerate() {
            let img = gpu.render(s, W, H, &opts);
            let caps = gpu.r().caps().clone();
            let (err, at, covered) = max_oracle_error(&img, s, Encoding::Linear, &caps);
            assert!(
                covered > 2000,
                "{es} {method} {what}: {covered} pixels compared"
            );
            assert!(
                err <= 2.0,
                "{es} {method} {what}: {err:.1}/255 from the light model at {at:?}"
            );
            let transform = if i == 1 { mirror } else { DMat4::IDENTITY };
            let leaning = leaning_pixels(s, transform, i == 3);
            eprintln!(
                "{es} {method} {what}: {} leaning pixels, error {err:.2}",
                leaning.len()
            );
            assert!(leaning.len() > 100, "{what}: {} pixels", leaning.len());
            // Ambient alone is 0.05 · 0.8 = 0.04 of white, about 10/255.
            let dark = leaning
                .iter()
                .filter(|&&(x, y)| img.get_pixel(x, y)[0] < 40)
                .count();
            assert_eq!(
                dark,
                0,
                "{es} {method} {what}: {dark} of {} pixels whose normal faces the light \
                 but leans away from the eye are lit as if from behind",
                leaning.len()
            );
        }
    });
}

/// A half-transparent box centred on the origin, turned so that three faces show, placed
/// with or without a mirror through its centre (which maps the box onto itself), and lit
/// from the front left, so that its near and far sides differ.
fn glass_box(mirrored: bool) -> Scene {
    let mut b = MeshBuilder::new();
    b.cuboid(Vec3::splat(-1.0), Vec3::splat(1.0));
    let mut s = Scene::empty();
    let mut glass = Material::flat("glass", Vec3::new(0.9, 0.7, 0.3));
    glass.alpha = 0.5;
    let glass = s.add_material(glass);
    let mirror = if mirrored { -1.0 } else { 1.0 };
    let turn = DMat4::from_rotation_y(0.6) * DMat4::from_rotation_x(0.4);
    s.objects.push(Object {
        mesh: Arc::new(b.build().unwrap()),
        material: glass,
        transform: turn * DMat4::from_scale(DVec3::new(mirror, 1.0, 1.0)),
    });
    s.ambient = Vec3::splat(0.05);
    s.camera = Camera::perspective(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, 50.0, 0.1, 20.0);
    s.lights = vec![Light::point(
        DVec3::new(-2.0, 1.0, 3.0),
        10.0,
        Vec3::ONE,
        4.0,
    )];
    s.validate().unwrap();
    s
}

#[test]
fn a_mirrored_transparent_box_blends_its_far_side_first() {
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let mut gpu = Gpu::new(EsVersion::Es3);
    let plain = gpu.render(&glass_box(false), W, H, &opts);
    let mirrored = gpu.render(&glass_box(true), W, H, &opts);
    let covered = plain.pixels().filter(|p| p[0] > 0).count();
    assert!(covered > 1000, "the box covers {covered} pixels");
    let differ = plain
        .pixels()
        .zip(mirrored.pixels())
        .filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 2))
        .count();
    eprintln!("{differ} of {covered} pixels differ");
    assert!(
        differ < 30,
        "{differ} pixels differ between the box and its mirror image, which is the same box"
    );
}

/// An octahedron as an OBJ without normals, its faces counter-clockwise seen from outside but
/// for those numbered in `reversed`.
fn octahedron_obj(reversed: &[usize]) -> String {
    let mut obj = String::from("v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n");
    let faces = [
        [1, 3, 5],
        [3, 2, 5],
        [2, 4, 5],
        [4, 1, 5],
        [3, 1, 6],
        [2, 3, 6],
        [4, 2, 6],
        [1, 4, 6],
    ];
    for (i, [a, b, c]) in faces.into_iter().enumerate() {
        let (b, c) = if reversed.contains(&i) {
            (c, b)
        } else {
            (b, c)
        };
        obj += &format!("f {a} {b} {c}\n");
    }
    obj
}

#[test]
fn an_obj_without_normals_listed_both_ways_looks_as_one_listed_one_way() {
    let (eye, light) = (DVec3::new(2.0, 1.5, 3.0), DVec3::new(2.5, 2.0, 2.0));
    let consistent = render_obj(&octahedron_obj(&[]), eye, (light, 10.0, 12.0));
    // The faces towards the eye and the light among them.
    let mixed = render_obj(&octahedron_obj(&[0, 5]), eye, (light, 10.0, 12.0));
    let lit = consistent.pixels().filter(|p| p[0] > 60).count();
    assert!(lit > 500, "{lit} lit pixels");
    assert_eq!(differing_pixels(&consistent, &mixed), 0);
}

/// `obj` loaded as a file and rendered (linear, forward on ES 3.0) from `eye` towards the
/// origin, lit by one white light (position, radius, intensity).
fn render_obj(
    obj: &str,
    eye: DVec3,
    (at, radius, intensity): (DVec3, f32, f32),
) -> image::RgbaImage {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("model.obj");
    std::fs::write(&path, obj).unwrap();
    let (mut s, _) = manylight::scene::load(path.to_str().unwrap(), None).unwrap();
    s.camera = Camera::perspective(eye, DVec3::ZERO, 50.0, 0.1, 20.0);
    s.lights = vec![Light::point(at, radius, Vec3::ONE, intensity)];
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    Gpu::new(EsVersion::Es3).render(&s, W, H, &opts)
}

/// Pixels of `a` and `b` more than 1/255 apart in some channel.
fn differing_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels()
        .zip(b.pixels())
        .filter(|(a, b)| (0..3).any(|c| a[c].abs_diff(b[c]) > 1))
        .count()
}

/// A sheet listed in both windings without normals (a common way to model a two-sided sheet):
/// the copy is dropped as a duplicate, and the normals are those of the sheet listed once.
/// Computed with the copy, they cancelled and the sheet was lit as if it faced up (+Y).
#[test]
fn a_sheet_listed_both_ways_without_normals_looks_as_the_sheet_listed_once() {
    let sheet = |faces: &str| {
        let obj = format!("v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n{faces}");
        let light = (DVec3::new(0.0, 0.0, 1.0), 3.0, 2.0);
        render_obj(&obj, DVec3::new(0.0, 0.0, 4.0), light)
    };
    let once = sheet("f 1 2 3\nf 1 3 4\n");
    let both = sheet("f 1 2 3\nf 1 3 4\nf 1 3 2\nf 1 4 3\n");
    let centre = once.get_pixel(W / 2, H / 2);
    assert!(centre[0] > 60, "the sheet is lit: {centre:?}");
    assert_eq!(differing_pixels(&once, &both), 0);
}
