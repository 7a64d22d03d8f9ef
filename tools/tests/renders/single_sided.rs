//! A single-sided material (glTF's default, `doubleSided: false`) is drawn from its front
//! only: seen from behind, what lies beyond it shows, exactly as if it were not there, with
//! every method on ES 2.0 and 3.0 — opaque (the depth prepass and deferred's G-buffer cull
//! it too, or its depth would hide the wall), transparent (no far-side pass), placed by a
//! mirroring transform (its front is then clockwise on screen) — and the CPU light model
//! sees the same. A double-sided one is drawn from both sides. A glTF file's `doubleSided`
//! decides, `false` when it is left out.

use crate::common;

use std::sync::Arc;

use common::gltf::Builder;
use common::gltf_models::{pane, primitive};
use common::{max_oracle_error, Gpu};
use glam::{DMat4, DVec3, Vec3};
use manylight::metrics::cpu_reference::Encoding;
use manylight::scene::{Light, Material, Mesh, Object, Scene};
use manylight::{Camera, EsVersion, RenderOptions};
use serde_json::json;

const W: u32 = 192;
const H: u32 = 108;

/// A 2 × 2 square at z = 0 around the origin, its winding facing +Z (or −Z with `away`), its
/// normals along that facing.
fn square(away: bool) -> Mesh {
    let positions = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]
        .map(|[x, y]| Vec3::new(x, y, 0.0))
        .to_vec();
    let (indices, normal) = if away {
        (vec![0, 2, 1, 0, 3, 2], -Vec3::Z)
    } else {
        (vec![0, 1, 2, 0, 2, 3], Vec3::Z)
    };
    Mesh::new(positions, vec![normal; 4], vec![], indices).unwrap()
}

/// How the red pane in front of the green wall is made and placed.
#[derive(Clone, Copy, Debug)]
struct Pane {
    /// Its winding faces away from the eye (object space).
    away: bool,
    /// Placed mirrored in x (the winding turns round on screen, its front stays where its
    /// object-space front was: facing the same way).
    mirrored: bool,
    double_sided: bool,
    /// Half transparent.
    transparent: bool,
}

impl Pane {
    /// Whether the eye on +Z sees the pane: its front faces the eye, or it has two sides.
    fn seen(&self) -> bool {
        self.double_sided || !self.away
    }
}

/// The green wall at z = −2 facing the eye on +Z, lit from the eye's side, and the pane when
/// given.
fn scene(pane: Option<Pane>) -> Scene {
    let mut s = Scene::empty();
    let green = s.add_material(Material::flat("wall", Vec3::new(0.1, 0.8, 0.1)));
    s.objects.push(Object {
        mesh: Arc::new(square(false)),
        material: green,
        transform: DMat4::from_translation(DVec3::new(0.0, 0.0, -2.0))
            * DMat4::from_scale(DVec3::new(8.0, 5.0, 1.0)),
    });
    if let Some(p) = pane {
        let red = s.add_material(Material {
            double_sided: p.double_sided,
            alpha: if p.transparent { 0.5 } else { 1.0 },
            ..Material::flat("pane", Vec3::new(0.9, 0.1, 0.1))
        });
        let transform = if p.mirrored {
            DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0))
        } else {
            DMat4::IDENTITY
        };
        s.objects.push(Object {
            mesh: Arc::new(square(p.away)),
            material: red,
            transform,
        });
    }
    s.ambient = Vec3::splat(0.05);
    s.camera = Camera::perspective(DVec3::new(0.3, 0.2, 4.0), DVec3::ZERO, 60.0, 0.1, 20.0);
    s.lights = vec![Light::point(
        DVec3::new(0.5, 1.0, 3.0),
        20.0,
        Vec3::ONE,
        40.0,
    )];
    s.validate().unwrap();
    s
}

fn every_pane() -> Vec<Pane> {
    let mut panes = Vec::new();
    for away in [false, true] {
        for mirrored in [false, true] {
            for double_sided in [false, true] {
                for transparent in [false, true] {
                    panes.push(Pane {
                        away,
                        mirrored,
                        double_sided,
                        transparent,
                    });
                }
            }
        }
    }
    panes
}

/// The pixels around the pane's middle (it covers about a third of the picture's height).
fn middle() -> impl Iterator<Item = (u32, u32)> {
    (W / 2 - 12..W / 2 + 12).flat_map(|x| (H / 2 - 8..H / 2 + 8).map(move |y| (x, y)))
}

/// Largest difference of any channel between two pictures over `pixels`, in 8-bit steps.
fn max_difference(
    a: &image::RgbaImage,
    b: &image::RgbaImage,
    pixels: impl Iterator<Item = (u32, u32)>,
) -> u8 {
    pixels
        .flat_map(|(x, y)| {
            let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
            (0..3).map(move |c| p[c].abs_diff(q[c]))
        })
        .max()
        .unwrap_or(0)
}

#[test]
fn a_single_sided_surface_is_seen_from_its_front_only_with_every_method() {
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    common::each_method(|es, method, gpu| {
        let wall_alone = gpu.render(&scene(None), W, H, &opts);
        // The wall alone is green where the pane would be.
        assert!(middle().all(|(x, y)| {
            let p = wall_alone.get_pixel(x, y);
            p[1] > p[0] + 40
        }));
        for pane in every_pane() {
            let s = scene(Some(pane));
            let img = gpu.render(&s, W, H, &opts);
            let what = format!("{es} {method} {pane:?}");
            let from_wall = max_difference(&img, &wall_alone, middle());
            if pane.seen() {
                assert!(from_wall > 40, "{what}: the pane is missing ({from_wall})");
                let red = middle().all(|(x, y)| {
                    let p = img.get_pixel(x, y);
                    p[0] > p[1]
                });
                assert!(red || pane.transparent, "{what}: not red");
            } else {
                // Culled: the picture is the wall's alone, everywhere.
                let everywhere = (0..W).flat_map(|x| (0..H).map(move |y| (x, y)));
                let d = max_difference(&img, &wall_alone, everywhere);
                assert!(d <= 2, "{what}: {d}/255 from the wall alone");
            }
            if !pane.transparent {
                let caps = gpu.r().caps().clone();
                let (err, at, covered) = max_oracle_error(&img, &s, Encoding::Linear, &caps);
                assert!(covered > 3000, "{what}: {covered} pixels compared");
                assert!(
                    err <= 2.0,
                    "{what}: {err:.1}/255 from the light model at {at:?}"
                );
            }
        }
    });
}

/// A glTF pane in front of a double-sided wall, both facing the camera on +Z, the pane's
/// winding (`wound_away`) and normals (`normals_away`) turned to face away or not, with
/// `doubleSided` left out, `false` or `true`, its node `mirrored` along x or not.
fn gltf_pane(
    wound_away: bool,
    normals_away: bool,
    double_sided: Option<bool>,
    mirrored: bool,
) -> String {
    let mut b = Builder::default();
    let mut near = pane(2.0, 2.0);
    if wound_away {
        near.positions = near
            .positions
            .chunks(3)
            .rev()
            .flat_map(|p| p.to_vec())
            .collect();
    }
    if normals_away {
        near.normals = [0.0, 0.0, -1.0].repeat(4);
    }
    let near = primitive(&mut b, &near, Some(0));
    let far = primitive(&mut b, &pane(6.0, 4.0), Some(1));
    let mut pane_material = json!({"pbrMetallicRoughness":
        {"baseColorFactor": [0.9, 0.1, 0.1, 1.0], "metallicFactor": 0.0}});
    if let Some(d) = double_sided {
        pane_material["doubleSided"] = json!(d);
    }
    b.gltf(json!({
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0, "translation": [0, -1, 0],
             "scale": [if mirrored { -1 } else { 1 }, 1, 1]},
            {"mesh": 1, "translation": [0, -2, -2]},
            {"camera": 0, "translation": [0, 0, 4]}
        ],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 1.0, "znear": 0.1, "zfar": 20}}],
        "meshes": [{"primitives": [near]}, {"primitives": [far]}],
        "materials": [pane_material, {"doubleSided": true, "pbrMetallicRoughness":
            {"baseColorFactor": [0.1, 0.8, 0.1, 1.0], "metallicFactor": 0.0}}]
    }))
}

/// glTF's front is the winding's side, whatever the normals say (§3.7.2.1: a node's
/// determinant decides the winding; §3.9.5: back faces only on double-sided materials), and
/// `doubleSided` is `false` when left out.
#[test]
fn a_gltf_material_is_single_sided_unless_it_says_double_sided() {
    let dir = tempfile::tempdir().unwrap();
    let mut gpu = Gpu::new(EsVersion::Es3);
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let cases = [
        // (wound away, normals away, doubleSided, the pane seen)
        (true, true, None, false),
        (true, true, Some(false), false),
        (true, true, Some(true), true),
        (false, false, None, true),
        // Normals against the winding: the winding decides (the normals light it).
        (false, true, None, true),
        (true, false, None, false),
        (true, false, Some(true), true),
    ];
    // Mirrored along x by its node (a negative determinant): the pane maps onto itself and
    // its front (now clockwise on screen, §3.7.2.1) still faces the same way.
    let mirrorings = cases.iter().flat_map(|&c| [(c, false), (c, true)]);
    for ((wound_away, normals_away, double_sided, seen), mirrored) in mirrorings {
        let what = format!(
            "wound away {wound_away}, normals away {normals_away}, doubleSided \
             {double_sided:?}, mirrored {mirrored}"
        );
        let path = common::files::write(
            dir.path(),
            "pane.gltf",
            gltf_pane(wound_away, normals_away, double_sided, mirrored),
        );
        let (mut s, _) = common::files::load(&path).unwrap();
        assert_eq!(
            s.materials[s.objects[0].material].double_sided,
            double_sided == Some(true),
            "{what}"
        );
        s.ambient = Vec3::splat(0.3);
        let img = gpu.render(&s, W, H, &opts);
        let p = img.get_pixel(W / 2, H / 2);
        assert_eq!(p[0] > p[1], seen, "{what}: the middle is {p:?}");
    }
}

/// A transparent double-sided pane, whose triangles lie in one plane and face one way, is drawn
/// once without culling: as many draws as a single-sided pane facing the eye (it was drawn
/// once a side, one of the two drawing nothing: particle and foliage cards paid double), and
/// its picture, whichever way it is wound or mirrored, with every method.
#[test]
fn a_transparent_pane_showing_both_sides_is_drawn_once() {
    let opts = RenderOptions {
        linear: true,
        ..Default::default()
    };
    let facing = Pane {
        away: false,
        mirrored: false,
        double_sided: false,
        transparent: true,
    };
    common::each_method(|es, method, gpu| {
        let render = |gpu: &mut Gpu, pane| {
            let s = scene(Some(pane));
            gpu.r().render_offscreen(&s, W, H, &opts).unwrap()
        };
        let (reference, once) = render(gpu, facing);
        for (away, mirrored) in [(false, false), (true, false), (false, true), (true, true)] {
            let pane = Pane {
                away,
                mirrored,
                double_sided: true,
                ..facing
            };
            let (img, stats) = render(gpu, pane);
            let what = format!("{es} {method} {pane:?}");
            assert_eq!(stats.draw_calls, once.draw_calls, "{what}: draws");
            let everywhere = (0..W).flat_map(|x| (0..H).map(move |y| (x, y)));
            let d = max_difference(&img, &reference, everywhere);
            assert!(d <= 1, "{what}: {d}/255 from the pane facing the eye");
        }
    });
}
