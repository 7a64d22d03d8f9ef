//! A ray caster over every triangle of a scene, in `f64`: what the sampled-pixel reference
//! (`metrics::cpu_reference`) and the automatic grid's surface samples use to find the surface
//! a pixel sees.
//!
//! It is instance-aware: one bounding volume hierarchy per distinct mesh (objects that place
//! the same `Arc<Mesh>` share it), in mesh space, and a top-level hierarchy over the placed
//! objects' world bounds. A ray enters each object through the inverse of its transform, so
//! a placement costs a few hundred bytes whatever its mesh. A transform without a usable
//! inverse (flattened to a plane) is traced in world space instead, its triangles carried
//! through the transform as they are tested. The ray test is Möller–Trumbore with both faces
//! accepted (the renderer draws surfaces two-sided); `t` is the world ray's parameter in
//! either space, since an affine map keeps it.

mod bvh;

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DMat3, DMat4, DVec3, DVec4};

use super::{Camera, Mesh, Projection, Scene};
use bvh::Node;

/// The nearest surface along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter: distance from the origin when the direction is unit length.
    pub t: f64,
    /// World-space point hit.
    pub position: DVec3,
    /// Interpolated vertex normal, world space, unit length (not flipped towards the ray).
    pub normal: DVec3,
    /// Index into [`Scene::objects`].
    pub object: usize,
    /// Triangle index within that object's mesh (`indices[3 * triangle..]`).
    pub triangle: usize,
}

/// The nearest opaque surface along a ray, and what lies in front of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstOpaque {
    /// Nearest hit on an opaque object, if any before the ray's end.
    pub hit: Option<Hit>,
    /// Ray parameter of the nearest non-opaque surface no farther than `hit` (anywhere on the
    /// ray when there is no opaque hit).
    pub transparent_t: Option<f64>,
    /// Ray parameter of the next opaque surface (another triangle) when it lies within
    /// [`COPLANAR`] of `hit` (relative): a depth buffer may resolve the two either way.
    pub runner_up_t: Option<f64>,
}

/// Relative distance within which a second opaque surface makes the nearest one ambiguous for
/// a GPU: 24-bit depth at a far plane thousands of times the near plane resolves about 10⁻⁴ of
/// the distance; ten times that, for coplanar decals and doubled faces in real models.
pub const COPLANAR: f64 = 1e-3;

/// The hierarchy of one distinct mesh, in mesh space: leaves refer to triangles through
/// `order` (triangle indices), vertices are read from the shared mesh as they are tested.
#[derive(Debug)]
struct MeshBvh {
    mesh: Arc<Mesh>,
    nodes: Vec<Node>,
    order: Vec<u32>,
}

/// One placed object.
#[derive(Clone, Copy, Debug)]
struct Instance {
    /// Object space → world space.
    to_world: DMat4,
    /// World space → object space, `None` when the transform has no usable inverse.
    to_object: Option<DMat4>,
    mesh: u32,
    object: u32,
}

/// Per-thread traversal stacks (top level, mesh level): the automatic grid casts rays during
/// a frame, and a frame in steady state allocates nothing.
type Stacks = (Vec<u32>, Vec<u32>);

thread_local! {
    static STACKS: std::cell::RefCell<Stacks> = const {
        std::cell::RefCell::new((Vec::new(), Vec::new()))
    };
}

/// A two-level BVH over the placed meshes of a scene, `f64`.
#[derive(Debug)]
pub struct SceneRaycaster {
    meshes: Vec<MeshBvh>,
    /// Placed objects in the top level's leaf order.
    instances: Vec<Instance>,
    nodes: Vec<Node>,
}

/// The best hits of one search.
struct Search {
    /// (t, u, v, instance slot, triangle) of the nearest opaque hit.
    best: Option<(f64, f64, f64, usize, u32)>,
    best_t: f64,
    runner_up: f64,
    transparent_t: f64,
}

impl Search {
    /// Boxes and hits are accepted a little beyond the best hit, so a near runner-up is found.
    fn reach(&self) -> f64 {
        if self.best_t.is_finite() {
            self.best_t * (1.0 + COPLANAR)
        } else {
            self.best_t
        }
    }
}

/// The ray as one object sees it.
enum Frame<'a> {
    /// In object space (the world ray through the inverse transform).
    Object { origin: DVec3, dir: DVec3 },
    /// In world space, triangles carried through `to_world` as they are tested.
    World {
        to_world: &'a DMat4,
        origin: DVec3,
        dir: DVec3,
    },
}

impl SceneRaycaster {
    /// Builds one hierarchy per distinct mesh and one over the placed objects.
    pub fn new(scene: &Scene) -> Self {
        let mut meshes: Vec<MeshBvh> = Vec::new();
        let mut mesh_index: HashMap<*const Mesh, u32> = HashMap::new();
        let mut instances = Vec::new();
        let mut boxes = Vec::new();
        for (object, o) in scene.objects.iter().enumerate() {
            let mesh = *mesh_index.entry(Arc::as_ptr(&o.mesh)).or_insert_with(|| {
                meshes.push(MeshBvh::new(&o.mesh));
                (meshes.len() - 1) as u32
            });
            let Some(root) = meshes[mesh as usize].nodes.first() else {
                continue; // no triangles
            };
            let world = bvh::transformed_box(root.min, root.max, &o.transform);
            if !(world.0.is_finite() && world.1.is_finite()) {
                continue; // a scene that validates has finite transforms
            }
            boxes.push(world);
            instances.push(Instance {
                to_world: o.transform,
                to_object: usable_inverse(&o.transform),
                mesh,
                object: object as u32,
            });
        }
        let (nodes, order) = bvh::build(&boxes);
        drop(boxes);
        let instances = order.iter().map(|&i| instances[i as usize]).collect();
        SceneRaycaster {
            meshes,
            instances,
            nodes,
        }
    }

    /// Number of triangles placed (each object's mesh counted once per placement).
    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .map(|i| self.meshes[i.mesh as usize].order.len())
            .sum()
    }

    /// Number of distinct meshes, each with one hierarchy.
    pub fn mesh_count(&self) -> usize {
        self.meshes.len()
    }

    /// Heap bytes the caster holds besides the meshes themselves (shared with the scene).
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of;
        let per_mesh: usize = self
            .meshes
            .iter()
            .map(|m| m.nodes.capacity() * size_of::<Node>() + m.order.capacity() * 4)
            .sum();
        per_mesh
            + self.meshes.capacity() * size_of::<MeshBvh>()
            + self.instances.capacity() * size_of::<Instance>()
            + self.nodes.capacity() * size_of::<Node>()
    }

    /// Nearest surface along `origin + t·dir` with `t > 0`, either face.
    pub fn hit(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        self.first_opaque_hit(origin, dir, f64::INFINITY, |_| true)
            .hit
    }

    /// Nearest surface of an object for which `is_opaque(object index)` holds, with
    /// `0 < t <= t_max`, and the nearest other surface in front of it (for transparent objects
    /// that the GPU blends over what is behind them).
    pub fn first_opaque_hit(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        is_opaque: impl Fn(usize) -> bool,
    ) -> FirstOpaque {
        let mut search = Search {
            best: None,
            best_t: t_max,
            runner_up: f64::INFINITY,
            transparent_t: f64::INFINITY,
        };
        let inv = dir.recip();
        let (mut top, mut inner) = STACKS.with(|s| std::mem::take(&mut *s.borrow_mut()));
        bvh::traverse(
            &self.nodes,
            &mut top,
            &mut search,
            |node, s| node.slab(origin, inv, s.reach()),
            |s, range| {
                for slot in range {
                    let instance = &self.instances[slot];
                    let opaque = is_opaque(instance.object as usize);
                    let frame = match &instance.to_object {
                        Some(m) => Frame::Object {
                            origin: m.transform_point3(origin),
                            dir: m.transform_vector3(dir),
                        },
                        None => Frame::World {
                            to_world: &instance.to_world,
                            origin,
                            dir,
                        },
                    };
                    let mesh = &self.meshes[instance.mesh as usize];
                    mesh.search(&frame, &mut inner, s, |s, t, u, v, triangle| {
                        if !opaque {
                            if t <= s.best_t {
                                s.transparent_t = s.transparent_t.min(t);
                            }
                        } else if t < s.best_t {
                            s.runner_up = s.best_t;
                            s.best_t = t;
                            s.best = Some((t, u, v, slot, triangle));
                        } else {
                            s.runner_up = s.runner_up.min(t);
                        }
                    });
                }
            },
        );
        STACKS.with(|s| *s.borrow_mut() = (top, inner));
        let hit = search
            .best
            .map(|(t, u, v, slot, triangle)| self.make_hit((slot, triangle), (t, u, v), origin, dir));
        // Ties count as in front: a transparent surface coplanar with an opaque one is blended.
        let limit = hit.map_or(t_max, |h| h.t);
        FirstOpaque {
            hit,
            transparent_t: (search.transparent_t <= limit).then_some(search.transparent_t),
            runner_up_t: hit
                .filter(|_| search.runner_up <= search.reach())
                .map(|_| search.runner_up),
        }
    }

    /// The hit at `(t, u, v)` on `triangle` of the object in `slot`.
    fn make_hit(
        &self,
        (slot, triangle): (usize, u32),
        (t, u, v): (f64, f64, f64),
        origin: DVec3,
        dir: DVec3,
    ) -> Hit {
        let instance = &self.instances[slot];
        let mesh = &self.meshes[instance.mesh as usize].mesh;
        let corners = corners(mesh, triangle);
        let world = corners.map(|i| {
            instance
                .to_world
                .transform_point3(mesh.positions[i].as_dvec3())
        });
        let geometric = (world[1] - world[0]).cross(world[2] - world[0]);
        // Vertex normals times the normal matrix, made unit (zero where the matrix takes them
        // to nothing), interpolated and normalised again: what `mesh.vert` and the fragment
        // shader do. `Mesh::new` always fills normals; a hand-built mesh without them shades
        // flat.
        let n = if mesh.normals.len() == mesh.positions.len() {
            let normal_matrix =
                super::normal_matrix::normal_matrix(&DMat3::from_mat4(instance.to_world));
            let n = corners.map(|i| {
                super::direction::unit(normal_matrix * mesh.normals[i].as_dvec3())
                    .unwrap_or(DVec3::ZERO)
            });
            n[0] * (1.0 - u - v) + n[1] * u + n[2] * v
        } else {
            geometric
        };
        Hit {
            t,
            position: origin + dir * t,
            normal: n
                .try_normalize()
                .unwrap_or_else(|| geometric.normalize()),
            object: instance.object as usize,
            triangle: triangle as usize,
        }
    }
}

impl MeshBvh {
    fn new(mesh: &Arc<Mesh>) -> MeshBvh {
        let boxes: Vec<(DVec3, DVec3)> = (0..mesh.triangle_count() as u32)
            .map(|t| {
                let [a, b, c] = corners(mesh, t).map(|i| mesh.positions[i].as_dvec3());
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let (nodes, order) = bvh::build(&boxes);
        MeshBvh {
            mesh: mesh.clone(),
            nodes,
            order,
        }
    }

    /// Tests the ray against every triangle whose boxes it reaches, calling `found` with
    /// `(t, u, v, triangle)` for each hit within the search's reach.
    fn search(
        &self,
        frame: &Frame,
        stack: &mut Vec<u32>,
        s: &mut Search,
        mut found: impl FnMut(&mut Search, f64, f64, f64, u32),
    ) {
        let positions = &self.mesh.positions;
        let (origin, dir) = match *frame {
            Frame::Object { origin, dir } | Frame::World { origin, dir, .. } => (origin, dir),
        };
        let inv = dir.recip();
        let vertices = |triangle: u32| {
            let v = corners(&self.mesh, triangle).map(|i| positions[i].as_dvec3());
            match frame {
                Frame::Object { .. } => v,
                Frame::World { to_world, .. } => v.map(|p| to_world.transform_point3(p)),
            }
        };
        bvh::traverse(
            &self.nodes,
            stack,
            s,
            |node, s| match frame {
                Frame::Object { .. } => node.slab(origin, inv, s.reach()),
                Frame::World { to_world, .. } => {
                    node.slab_transformed(to_world, origin, inv, s.reach())
                }
            },
            |s, range| {
                for &triangle in &self.order[range] {
                    if let Some((t, u, v)) = intersect(vertices(triangle), origin, dir) {
                        if t <= s.reach() {
                            found(s, t, u, v, triangle);
                        }
                    }
                }
            },
        );
    }
}

/// Vertex indices of a triangle.
fn corners(mesh: &Mesh, triangle: u32) -> [usize; 3] {
    let i = 3 * triangle as usize;
    [0, 1, 2].map(|k| mesh.indices[i + k] as usize)
}

/// The inverse of an affine transform when it is well enough conditioned to carry rays into
/// object space: its volume not below 10⁻⁹ of its columns' (a flat or nearly flat object is
/// traced in world space instead).
fn usable_inverse(m: &DMat4) -> Option<DMat4> {
    let m3 = DMat3::from_mat4(*m);
    let columns = m3.x_axis.length() * m3.y_axis.length() * m3.z_axis.length();
    let det = m3.determinant();
    let inverse = m.inverse();
    (det.abs() > 1e-9 * columns && columns.is_finite() && inverse.is_finite()).then_some(inverse)
}

/// Möller–Trumbore, both faces: `(t, u, v)` with `t > 0`, the hit at
/// `(1 − u − v)·v0 + u·v1 + v·v2`.
fn intersect([v0, v1, v2]: [DVec3; 3], origin: DVec3, dir: DVec3) -> Option<(f64, f64, f64)> {
    let (e1, e2) = (v1 - v0, v2 - v0);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some((t, u, v))
}

/// World-space ray `(origin, unit direction)` through window position (`px`, `py`) in pixels
/// from the top-left corner (pixel (x, y) has its centre at (x + 0.5, y + 0.5)), found by
/// unprojecting the near and far planes with the inverse of projection × view, so perspective
/// and orthographic cameras both work. The origin lies on the near plane, as clipping puts it.
pub fn pixel_ray(camera: &Camera, width: u32, height: u32, px: f64, py: f64) -> (DVec3, DVec3) {
    let aspect = width as f64 / height as f64;
    let inv_vp = (camera.projection_matrix(aspect) * camera.view_matrix()).inverse();
    let ndc_x = 2.0 * px / width as f64 - 1.0;
    let ndc_y = 1.0 - 2.0 * py / height as f64; // image rows run top-down, NDC y up
    let unproject = |z: f64| {
        let p = inv_vp * DVec4::new(ndc_x, ndc_y, z, 1.0);
        p.truncate() / p.w
    };
    // An infinite far plane unprojects to w = 0 (a point at infinity, sign lost to rounding):
    // any depth between the planes gives the same line.
    let far_z = match camera.projection {
        Projection::Perspective { far, .. } if far.is_infinite() => 0.0,
        _ => 1.0,
    };
    let origin = unproject(-1.0);
    (origin, (unproject(far_z) - origin).normalize())
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use glam::Vec3;
    use rand::{Rng, SeedableRng};

    use super::*;
    use crate::scene::{Material, Mesh, Object};

    fn scene_of(meshes: Vec<(Mesh, DMat4)>) -> Scene {
        let mut scene = Scene::empty();
        let material = scene.add_material(Material::default());
        for (mesh, transform) in meshes {
            scene.objects.push(Object {
                mesh: Arc::new(mesh),
                material,
                transform,
            });
        }
        scene
    }

    fn triangle_at(z: f32) -> Mesh {
        let p = vec![
            Vec3::new(-5.0, -5.0, z),
            Vec3::new(5.0, -5.0, z),
            Vec3::new(0.0, 5.0, z),
        ];
        Mesh::new(p, vec![], vec![], vec![0, 1, 2]).unwrap()
    }

    #[test]
    fn quad_hit_point_and_interpolated_normal() {
        // Normals tilt along x only, so the interpolation is the same on both triangles.
        let a = std::f32::consts::FRAC_1_SQRT_2;
        let (left, right) = (Vec3::new(-a, 0.0, a), Vec3::new(a, 0.0, a));
        let quad = Mesh::new(
            vec![
                Vec3::new(-1.0, -1.0, 0.0),
                Vec3::new(1.0, -1.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(-1.0, 1.0, 0.0),
            ],
            vec![left, right, right, left],
            vec![],
            vec![0, 1, 2, 0, 2, 3],
        )
        .unwrap();
        // Non-uniform scale: the normal goes through the inverse transpose, x halved.
        let transform = DMat4::from_translation(DVec3::new(0.0, 0.0, -3.0))
            * DMat4::from_scale(DVec3::new(2.0, 1.0, 1.0));
        let rc = SceneRaycaster::new(&scene_of(vec![(quad, transform)]));
        assert_eq!(rc.triangle_count(), 2);

        let h = rc.hit(DVec3::new(1.0, 0.3, 5.0), -DVec3::Z).unwrap();
        assert!((h.t - 8.0).abs() < 1e-12);
        assert!((h.position - DVec3::new(1.0, 0.3, -3.0)).length() < 1e-12);
        // World x = 1 is object x = 0.5: a quarter of `left` and three quarters of `right`
        // give (0.5a, 0, a) in object space, (0.25a, 0, a) after the normal matrix.
        let expected = DVec3::new(0.25, 0.0, 1.0).normalize();
        assert!((h.normal - expected).length() < 1e-6, "{:?}", h.normal);
        assert_eq!((h.object, h.triangle), (0, 0)); // below the diagonal: triangle 0, 1, 2
        let other = rc.hit(DVec3::new(-1.0, 0.3, 5.0), -DVec3::Z).unwrap();
        assert_eq!(other.triangle, 1);

        // Back face: hit too, the same unflipped normal.
        let back = rc.hit(DVec3::new(1.0, 0.3, -10.0), DVec3::Z).unwrap();
        assert!((back.t - 7.0).abs() < 1e-12);
        assert!((back.normal - expected).length() < 1e-6);
        // Behind the origin or beside the quad: no hit.
        assert!(rc.hit(DVec3::new(1.0, 0.3, -10.0), -DVec3::Z).is_none());
        assert!(rc.hit(DVec3::new(2.5, 0.0, 5.0), -DVec3::Z).is_none());
    }

    #[test]
    fn nearest_of_two_overlapping_triangles() {
        let rc = SceneRaycaster::new(&scene_of(vec![
            (triangle_at(-1.0), DMat4::IDENTITY),
            (triangle_at(0.0), DMat4::IDENTITY),
        ]));
        let from_front = rc.hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z).unwrap();
        assert_eq!(from_front.object, 1);
        assert!((from_front.t - 5.0).abs() < 1e-12);
        let from_back = rc.hit(DVec3::new(0.0, 0.0, -5.0), DVec3::Z).unwrap();
        assert_eq!(from_back.object, 0);
        assert!((from_back.t - 4.0).abs() < 1e-12);

        // Object 1 see-through: the opaque hit is object 0, with object 1 in front of it.
        let r = rc.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |o| {
            o == 0
        });
        assert_eq!(r.hit.unwrap().object, 0);
        assert_eq!(r.transparent_t, Some(5.0));
        // The ray ends before the opaque one: only the transparent surface is reported.
        let r = rc.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, 5.5, |o| o == 0);
        assert_eq!((r.hit, r.transparent_t), (None, Some(5.0)));
        // A transparent surface behind the opaque one is not reported.
        let r = rc.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |o| {
            o == 1
        });
        assert_eq!((r.hit.unwrap().object, r.transparent_t), (1, None));
    }

    /// A face doubled within the depth a GPU can resolve is ambiguous; one 1 % behind is not.
    #[test]
    fn a_nearly_coplanar_second_surface_is_reported() {
        let doubled = SceneRaycaster::new(&scene_of(vec![
            (triangle_at(0.0), DMat4::IDENTITY),
            (triangle_at(-0.0001), DMat4::IDENTITY),
        ]));
        let r =
            doubled.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |_| {
                true
            });
        assert_eq!(r.hit.unwrap().object, 0);
        assert!((r.runner_up_t.unwrap() - 5.0001).abs() < 1e-9);
        let apart = SceneRaycaster::new(&scene_of(vec![
            (triangle_at(0.0), DMat4::IDENTITY),
            (triangle_at(-0.05), DMat4::IDENTITY),
        ]));
        let r = apart.first_opaque_hit(DVec3::new(0.0, 0.0, 5.0), -DVec3::Z, f64::INFINITY, |_| {
            true
        });
        assert_eq!((r.hit.unwrap().object, r.runner_up_t), (0, None));
    }

    /// The nearest hits found the simple way: every triangle of every object carried to world
    /// space and tested (what the caster did before it was instance-aware), with the normal
    /// interpolated from world-space barycentrics.
    fn brute_force(
        scene: &Scene,
        origin: DVec3,
        dir: DVec3,
        opaque: impl Fn(usize) -> bool,
    ) -> (Option<Hit>, Option<f64>) {
        let (mut best, mut transparent) = (None::<Hit>, f64::INFINITY);
        for (object, o) in scene.objects.iter().enumerate() {
            let m = &o.mesh;
            let nm = crate::scene::normal_matrix::normal_matrix(&DMat3::from_mat4(o.transform));
            for triangle in 0..m.triangle_count() {
                let c = corners(m, triangle as u32);
                let v = c.map(|i| o.transform.transform_point3(m.positions[i].as_dvec3()));
                let Some((t, u, w)) = intersect(v, origin, dir) else {
                    continue;
                };
                if !opaque(object) {
                    transparent = transparent.min(t);
                } else if best.is_none_or(|b| t < b.t) {
                    let n = c.map(|i| {
                        crate::scene::direction::unit(nm * m.normals[i].as_dvec3())
                            .unwrap_or(DVec3::ZERO)
                    });
                    best = Some(Hit {
                        t,
                        position: origin + dir * t,
                        normal: (n[0] * (1.0 - u - w) + n[1] * u + n[2] * w).normalize(),
                        object,
                        triangle,
                    });
                }
            }
        }
        let limit = best.map_or(f64::INFINITY, |b| b.t);
        (best, (transparent <= limit).then_some(transparent))
    }

    fn close(a: f64, b: f64) -> bool {
        a == b || (a - b).abs() <= 1e-9 * a.abs().max(1.0)
    }

    /// Casts `rays` random rays at `scene` and checks every hit against [`brute_force`]: the
    /// same object and triangle, `t` and normal to rounding, the same transparent surface.
    /// Returns (hits, rays with a transparent surface in front).
    fn agrees_with_brute_force(
        scene: &Scene,
        rng: &mut rand_pcg::Pcg64,
        rays: usize,
        spread: f32,
        opaque: impl Fn(usize) -> bool + Copy,
    ) -> (usize, usize) {
        let rc = SceneRaycaster::new(scene);
        let (mut hits, mut transparent) = (0, 0);
        for _ in 0..rays {
            let origin = rand_point(rng, 2.0 * spread).as_dvec3();
            let dir = (rand_point(rng, 0.8 * spread).as_dvec3() - origin).normalize();
            for (opaque, name) in [(&(|_| true) as &dyn Fn(usize) -> bool, "all"), (&opaque, "some")]
            {
                let (want, want_t) = brute_force(scene, origin, dir, opaque);
                let got = rc.first_opaque_hit(origin, dir, f64::INFINITY, opaque);
                let same = match (got.hit, want) {
                    (Some(g), Some(w)) => {
                        (g.object, g.triangle) == (w.object, w.triangle)
                            && close(g.t, w.t)
                            && (g.position - w.position).length() <= 1e-9 * w.t.max(1.0)
                            && (g.normal - w.normal).length() < 1e-6
                    }
                    (g, w) => g.is_none() && w.is_none(),
                };
                assert!(same, "{name}: {:?} vs {want:?} ({origin}, {dir})", got.hit);
                match (got.transparent_t, want_t) {
                    (Some(g), Some(w)) => assert!(close(g, w), "{g} vs {w}"),
                    (g, w) => assert_eq!(g, w),
                }
                hits += got.hit.is_some() as usize;
                transparent += got.transparent_t.is_some() as usize;
            }
        }
        (hits, transparent)
    }

    fn rand_point(rng: &mut rand_pcg::Pcg64, s: f32) -> Vec3 {
        Vec3::new(
            rng.random_range(-s..s),
            rng.random_range(-s..s),
            rng.random_range(-s..s),
        )
    }

    /// `triangles` random small triangles within ±`size`, with random vertex normals.
    fn random_mesh(rng: &mut rand_pcg::Pcg64, triangles: usize, size: f32) -> Mesh {
        let mut positions = Vec::new();
        for _ in 0..triangles {
            let c = rand_point(rng, size);
            for _ in 0..3 {
                positions.push(c + rand_point(rng, 0.08 * size));
            }
        }
        let normals = (0..positions.len())
            .map(|_| rand_point(rng, 1.0) + Vec3::Z * 1.5)
            .collect();
        let indices = (0..positions.len() as u32).collect();
        Mesh::new(positions, normals, vec![], indices).unwrap()
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        // Several objects with transforms, so object and triangle indices are checked too.
        let mut meshes = Vec::new();
        for o in 0..4 {
            let mesh = random_mesh(&mut rng, 600, 10.0);
            let transform = DMat4::from_translation(DVec3::new(o as f64, 0.0, 0.0))
                * DMat4::from_rotation_y(o as f64 * 0.3);
            meshes.push((mesh, transform));
        }
        let scene = scene_of(meshes);
        let (hits, transparent) =
            agrees_with_brute_force(&scene, &mut rng, 1000, 10.0, |o| o.is_multiple_of(2));
        assert!(hits > 1000 && transparent > 250, "{hits} hits, {transparent}");
    }

    /// One mesh placed many times — moved, rotated, mirrored, scaled unevenly, far from the
    /// origin, flattened to a plane (no inverse: traced in world space) — is one hierarchy,
    /// and every placement is hit where the world-space triangles are.
    #[test]
    fn repeated_placements_share_one_hierarchy_and_agree_with_brute_force() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        let mesh = Arc::new(random_mesh(&mut rng, 300, 3.0));
        let mut scene = Scene::empty();
        let material = scene.add_material(Material::default());
        let transforms = [
            DMat4::IDENTITY,
            DMat4::from_translation(DVec3::new(4.0, 1.0, -2.0)) * DMat4::from_rotation_x(1.1),
            DMat4::from_translation(DVec3::new(-3.0, 2.0, 1.0))
                * DMat4::from_scale(DVec3::new(-1.0, 1.0, 1.0)),
            DMat4::from_translation(DVec3::new(0.0, -4.0, 3.0))
                * DMat4::from_rotation_z(0.4)
                * DMat4::from_scale(DVec3::new(2.5, 0.3, 1.0)),
            DMat4::from_translation(DVec3::new(2.0, 3.0, 4.0))
                * DMat4::from_scale(DVec3::new(1.0, 1.0, 0.0)),
            DMat4::from_translation(DVec3::new(-4.0, -2.0, -3.0))
                * DMat4::from_scale(DVec3::new(0.5, 1e-12, 0.5)),
            DMat4::from_rotation_y(2.0) * DMat4::from_scale(DVec3::splat(-0.7)),
        ];
        for transform in transforms {
            scene.add_object(mesh.clone(), material, transform);
        }
        let rc = SceneRaycaster::new(&scene);
        assert_eq!(rc.mesh_count(), 1);
        assert_eq!(rc.triangle_count(), 300 * transforms.len());
        let flat = rc.instances.iter().filter(|i| i.to_object.is_none());
        // Squashed to 10⁻¹² still has an inverse that works; flattened to 0 has none.
        assert_eq!(flat.count(), 1, "the flattened placement is traced in world space");
        let (hits, transparent) =
            agrees_with_brute_force(&scene, &mut rng, 1500, 5.0, |o| o % 3 != 1);
        assert!(hits > 500 && transparent > 100, "{hits} hits, {transparent}");

        // Far from the origin: the same, relative to the distance.
        let far = DMat4::from_translation(DVec3::new(3e6, -1e6, 2e6));
        for o in &mut scene.objects {
            o.transform = far * o.transform;
        }
        let rc = SceneRaycaster::new(&scene);
        let mut found = 0;
        for _ in 0..300 {
            let target = far.transform_point3(rand_point(&mut rng, 4.0).as_dvec3());
            let origin = target + rand_point(&mut rng, 20.0).as_dvec3();
            let dir = (target - origin).normalize();
            let (want, _) = brute_force(&scene, origin, dir, |_| true);
            let got = rc.hit(origin, dir);
            assert_eq!(
                got.map(|h| (h.object, h.triangle)),
                want.map(|w| (w.object, w.triangle))
            );
            if let (Some(g), Some(w)) = (got, want) {
                assert!((g.t - w.t).abs() < 1e-6, "{} vs {}", g.t, w.t);
                found += 1;
            }
        }
        assert!(found > 50, "{found}");
    }

    /// The memory a placement costs does not depend on its mesh: 100 000 placements of a
    /// 2 000-triangle mesh hold one mesh hierarchy and a fixed few hundred bytes each.
    #[test]
    fn memory_per_placement_is_constant() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
        let mesh = Arc::new(random_mesh(&mut rng, 2000, 1.0));
        let placed = |n: usize| {
            let mut scene = Scene::empty();
            let material = scene.add_material(Material::default());
            for i in 0..n {
                let at = DVec3::new((i % 400) as f64 * 3.0, (i / 400) as f64 * 3.0, 0.0);
                scene.add_object(mesh.clone(), material, DMat4::from_translation(at));
            }
            SceneRaycaster::new(&scene)
        };
        let (one, many) = (placed(1), placed(100_000));
        assert_eq!((one.mesh_count(), many.mesh_count()), (1, 1));
        assert_eq!(many.triangle_count(), 2000 * 100_000);
        let per_placement = (many.heap_bytes() - one.heap_bytes()) / 100_000;
        assert!(per_placement <= 400, "{per_placement} bytes a placement");
        // One mesh's hierarchy: about one node per two triangles and an index per triangle.
        assert!(one.heap_bytes() < 2000 * 64, "{} bytes", one.heap_bytes());
    }

    #[test]
    fn pixel_ray_through_the_centre_points_at_the_target() {
        let position = DVec3::new(3.0, 2.0, 7.0);
        let target = DVec3::new(-1.0, 0.5, 0.0);
        let forward = (target - position).normalize();
        let projections = [
            Projection::Perspective {
                fov_y_deg: 50.0,
                near: 0.5,
                far: 100.0,
            },
            Projection::Perspective {
                fov_y_deg: 50.0,
                near: 0.5,
                far: f64::INFINITY,
            },
            Projection::Orthographic {
                height: 4.0,
                near: 0.5,
                far: 100.0,
            },
        ];
        for projection in projections {
            let cam = Camera {
                position,
                target,
                up: DVec3::Y,
                projection,
            };
            let (w, h) = (101, 75);
            let (o, d) = pixel_ray(&cam, w, h, 50.5, 37.5);
            assert!((d - forward).length() < 1e-9, "{projection:?}: {d:?}");
            assert!((o - (position + forward * 0.5)).length() < 1e-9, "{o:?}");
            // The top row looks up: row 0 is the top of the view.
            let (_, top) = pixel_ray(&cam, w, h, 50.5, 0.5);
            let (o_top, _) = pixel_ray(&cam, w, h, 50.5, 0.5);
            let up = forward.cross(DVec3::Y).cross(forward).normalize();
            assert!(top.dot(up) > -1e-12 && (o_top - o).dot(up) > 0.0);
            let (o_left, _) = pixel_ray(&cam, w, h, 0.5, 37.5);
            assert!((o_left - o).dot(forward.cross(DVec3::Y)) < 0.0); // column 0 is the left
        }
    }
}
