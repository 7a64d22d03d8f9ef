//! A ray caster over every triangle of a scene, in world space and `f64`: what the sampled-pixel
//! reference (`metrics::cpu_reference`) and the automatic grid's surface samples use to find the
//! surface a pixel sees.
//!
//! The acceleration structure is a bounding volume hierarchy built by median split of the
//! triangle centroids along the widest axis (quick to build; trace quality matters little for
//! the few thousand rays a reference casts). Traversal is iterative, nearer child first, and
//! the ray test is Möller–Trumbore with both faces accepted (the renderer draws surfaces
//! two-sided).

use glam::{DMat3, DVec3, DVec4};

use super::{Camera, Projection, Scene};

/// Most triangles in a leaf.
const LEAF_SIZE: usize = 4;

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

/// One triangle in world space with what is needed to rebuild a hit on it.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    v: [DVec3; 3],
    /// Vertex normals times the normal matrix, made unit (zero where the matrix takes them to
    /// nothing): the GPU interpolates exactly these (`mesh.vert`) and normalises per fragment.
    n: [DVec3; 3],
    object: u32,
    triangle: u32,
}

/// A BVH node: a leaf holds `count > 0` triangles from `first`; an inner node (`count == 0`)
/// has its two children at `first` and `first + 1`.
#[derive(Clone, Copy, Debug)]
struct Node {
    min: DVec3,
    max: DVec3,
    first: u32,
    count: u32,
}

/// A BVH over every triangle of a scene, world space, `f64`.
#[derive(Debug)]
pub struct SceneRaycaster {
    triangles: Vec<Triangle>,
    nodes: Vec<Node>,
}

impl SceneRaycaster {
    /// Transforms every triangle of every object to world space and builds the hierarchy.
    pub fn new(scene: &Scene) -> Self {
        let mut triangles = Vec::new();
        for (object, o) in scene.objects.iter().enumerate() {
            let mesh = &o.mesh;
            let normal_matrix =
                super::normal_matrix::normal_matrix(&DMat3::from_mat4(o.transform));
            let pos: Vec<DVec3> = mesh
                .positions
                .iter()
                .map(|p| o.transform.transform_point3(p.as_dvec3()))
                .collect();
            // `Mesh::new` always fills normals; a hand-built mesh without them shades flat.
            let has_normals = mesh.normals.len() == mesh.positions.len();
            for (triangle, idx) in mesh.indices.chunks_exact(3).enumerate() {
                let [a, b, c] = [idx[0], idx[1], idx[2]].map(|i| i as usize);
                let v = [pos[a], pos[b], pos[c]];
                let n = if has_normals {
                    [a, b, c].map(|i| {
                        super::direction::unit(normal_matrix * mesh.normals[i].as_dvec3())
                            .unwrap_or(DVec3::ZERO)
                    })
                } else {
                    [(v[1] - v[0]).cross(v[2] - v[0]); 3]
                };
                triangles.push(Triangle {
                    v,
                    n,
                    object: object as u32,
                    triangle: triangle as u32,
                });
            }
        }
        let (nodes, order) = build(&triangles);
        let triangles = order.iter().map(|&i| triangles[i as usize]).collect();
        SceneRaycaster { triangles, nodes }
    }

    /// Number of triangles in the hierarchy.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
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
        let mut best: Option<(f64, f64, f64, usize)> = None; // (t, u, v, triangle slot)
        let mut best_t = t_max;
        let mut runner_up = f64::INFINITY;
        // Boxes are pruned a little beyond the best hit, so a near runner-up is still found.
        let reach = |t: f64| {
            if t.is_finite() {
                t * (1.0 + COPLANAR)
            } else {
                t
            }
        };
        let mut transparent_t = f64::INFINITY;
        let inv = dir.recip();
        // The traversal stack is kept per thread: the automatic grid casts rays during a frame,
        // and a frame in steady state allocates nothing.
        thread_local! {
            static STACK: std::cell::RefCell<Vec<u32>> = const { std::cell::RefCell::new(Vec::new()) };
        }
        let mut stack = STACK.with(|s| std::mem::take(&mut *s.borrow_mut()));
        stack.clear();
        if !self.nodes.is_empty() && slab(&self.nodes[0], origin, inv, reach(best_t)).is_some() {
            stack.push(0);
        }
        while let Some(ni) = stack.pop() {
            let node = &self.nodes[ni as usize];
            // The box was entered when pushed; a nearer opaque hit found since may rule it out.
            if slab(node, origin, inv, reach(best_t)).is_none() {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for slot in range {
                    let tri = &self.triangles[slot];
                    let Some((t, u, v)) = intersect(tri, origin, dir) else {
                        continue;
                    };
                    if t > reach(best_t) {
                        continue;
                    }
                    if !is_opaque(tri.object as usize) {
                        if t <= best_t {
                            transparent_t = transparent_t.min(t);
                        }
                    } else if t < best_t {
                        runner_up = best_t;
                        best_t = t;
                        best = Some((t, u, v, slot));
                    } else {
                        runner_up = runner_up.min(t);
                    }
                }
                continue;
            }
            let (a, b) = (node.first, node.first + 1);
            let ta = slab(&self.nodes[a as usize], origin, inv, reach(best_t));
            let tb = slab(&self.nodes[b as usize], origin, inv, reach(best_t));
            // Push the farther child first so the nearer one is traversed first.
            match (ta, tb) {
                (Some(ta), Some(tb)) if ta <= tb => stack.extend([b, a]),
                (Some(_), Some(_)) => stack.extend([a, b]),
                (Some(_), None) => stack.push(a),
                (None, Some(_)) => stack.push(b),
                (None, None) => {}
            }
        }
        STACK.with(|s| *s.borrow_mut() = stack);
        let hit = best.map(|(t, u, v, slot)| self.make_hit(slot, origin, dir, t, u, v));
        // Ties count as in front: a transparent surface coplanar with an opaque one is blended.
        let limit = hit.map_or(t_max, |h| h.t);
        FirstOpaque {
            hit,
            transparent_t: (transparent_t <= limit).then_some(transparent_t),
            runner_up_t: hit.filter(|h| runner_up <= reach(h.t)).map(|_| runner_up),
        }
    }

    fn make_hit(&self, slot: usize, origin: DVec3, dir: DVec3, t: f64, u: f64, v: f64) -> Hit {
        let tri = &self.triangles[slot];
        let n = tri.n[0] * (1.0 - u - v) + tri.n[1] * u + tri.n[2] * v;
        let geometric = || (tri.v[1] - tri.v[0]).cross(tri.v[2] - tri.v[0]).normalize();
        let normal = n.try_normalize().unwrap_or_else(geometric);
        Hit {
            t,
            position: origin + dir * t,
            normal,
            object: tri.object as usize,
            triangle: tri.triangle as usize,
        }
    }
}

/// Builds the hierarchy; returns the nodes and the triangle order the leaves refer to.
fn build(triangles: &[Triangle]) -> (Vec<Node>, Vec<u32>) {
    let n = triangles.len();
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let boxes: Vec<(DVec3, DVec3)> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.v;
            (a.min(b).min(c), a.max(b).max(c))
        })
        .collect();
    let centroids: Vec<DVec3> = boxes.iter().map(|(lo, hi)| (*lo + *hi) * 0.5).collect();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let empty = Node {
        min: DVec3::ZERO,
        max: DVec3::ZERO,
        first: 0,
        count: 0,
    };
    let mut nodes = vec![empty];
    let mut work = vec![(0usize, 0usize, n)];
    while let Some((ni, start, end)) = work.pop() {
        let items = &mut order[start..end];
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let (mut clo, mut chi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &i in items.iter() {
            let (bl, bh) = boxes[i as usize];
            (lo, hi) = (lo.min(bl), hi.max(bh));
            let c = centroids[i as usize];
            (clo, chi) = (clo.min(c), chi.max(c));
        }
        nodes[ni].min = lo;
        nodes[ni].max = hi;
        if items.len() <= LEAF_SIZE {
            nodes[ni].first = start as u32;
            nodes[ni].count = items.len() as u32;
            continue;
        }
        let extent = chi - clo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        // Median split: always halves the set, so the depth stays log₂(n) even when many
        // centroids coincide.
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |&a, &b| {
            centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
        });
        let left = nodes.len();
        nodes.extend([empty, empty]);
        nodes[ni].first = left as u32;
        work.push((left, start, start + mid));
        work.push((left + 1, start + mid, end));
    }
    (nodes, order)
}

/// Entry parameter of the ray into the node's box within `[0, t_max]`, if it enters at all.
fn slab(node: &Node, origin: DVec3, inv_dir: DVec3, t_max: f64) -> Option<f64> {
    let t0 = (node.min - origin) * inv_dir;
    let t1 = (node.max - origin) * inv_dir;
    // A zero direction component gives ±∞ (or NaN on the slab's plane, which min/max ignore).
    let enter = t0.min(t1).max_element().max(0.0);
    let exit = t0.max(t1).min_element().min(t_max);
    (enter <= exit).then_some(enter)
}

/// Möller–Trumbore, both faces: `(t, u, v)` with `t > 0`, the hit at
/// `(1 − u − v)·v0 + u·v1 + v·v2`.
fn intersect(tri: &Triangle, origin: DVec3, dir: DVec3) -> Option<(f64, f64, f64)> {
    let [v0, v1, v2] = tri.v;
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

    use glam::{DMat4, Vec3};
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

    fn brute_force(
        rc: &SceneRaycaster,
        origin: DVec3,
        dir: DVec3,
        opaque: impl Fn(usize) -> bool,
    ) -> (Option<(f64, usize, usize)>, Option<f64>) {
        let (mut best, mut transparent) = (None::<(f64, usize, usize)>, f64::INFINITY);
        for tri in &rc.triangles {
            if let Some((t, _, _)) = intersect(tri, origin, dir) {
                if !opaque(tri.object as usize) {
                    transparent = transparent.min(t);
                } else if best.is_none_or(|b| t < b.0) {
                    best = Some((t, tri.object as usize, tri.triangle as usize));
                }
            }
        }
        let limit = best.map_or(f64::INFINITY, |b| b.0);
        (best, (transparent <= limit).then_some(transparent))
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let rand_point = |rng: &mut rand_pcg::Pcg64, s: f32| {
            Vec3::new(
                rng.random_range(-s..s),
                rng.random_range(-s..s),
                rng.random_range(-s..s),
            )
        };
        // Several objects with transforms, so object and triangle indices are checked too.
        let mut meshes = Vec::new();
        for o in 0..4 {
            let mut positions = Vec::new();
            for _ in 0..600 {
                let c = rand_point(&mut rng, 10.0);
                for _ in 0..3 {
                    positions.push(c + rand_point(&mut rng, 0.8));
                }
            }
            let indices = (0..positions.len() as u32).collect();
            let mesh = Mesh::new(positions, vec![], vec![], indices).unwrap();
            let transform = DMat4::from_translation(DVec3::new(o as f64, 0.0, 0.0))
                * DMat4::from_rotation_y(o as f64 * 0.3);
            meshes.push((mesh, transform));
        }
        let rc = SceneRaycaster::new(&scene_of(meshes));
        let opaque = |o: usize| o.is_multiple_of(2);
        let (mut hits, mut transparent) = (0, 0);
        for _ in 0..2000 {
            let origin = rand_point(&mut rng, 20.0).as_dvec3();
            let dir = (rand_point(&mut rng, 8.0).as_dvec3() - origin).normalize();
            let expected = brute_force(&rc, origin, dir, |_| true).0;
            let got = rc.hit(origin, dir);
            assert_eq!(
                got.map(|h| (h.object, h.triangle)),
                expected.map(|e| (e.1, e.2))
            );
            if let (Some(g), Some(e)) = (got, expected) {
                assert_eq!(g.t, e.0);
                hits += 1;
            }
            let (eo, et) = brute_force(&rc, origin, dir, opaque);
            let r = rc.first_opaque_hit(origin, dir, f64::INFINITY, opaque);
            assert_eq!(r.hit.map(|h| (h.t, h.object, h.triangle)), eo);
            assert_eq!(r.transparent_t, et);
            transparent += et.is_some() as usize;
        }
        assert!(
            hits > 1000 && transparent > 500,
            "{hits} hits, {transparent}"
        );
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
