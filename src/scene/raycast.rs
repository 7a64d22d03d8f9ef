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
//! accepted on a double-sided material ([`Hit::face`] tells which) and the front alone on a
//! single-sided one, as the renderer culls them; `t` is the world ray's parameter in either
//! space, since an affine map keeps it.
//!
//! A hierarchy is asked of the allocator before it is built: one the process cannot allocate
//! now leaves its mesh out (rays pass through it), counted by
//! [`SceneRaycaster::left_out_triangles`], rather than aborting the process.

mod bvh;

use std::collections::HashMap;
use std::sync::{Arc, Weak};

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
    /// The triangle's unit normal on its front side (the one its winding faces, turned back
    /// for a mirroring transform): the side `Mesh::new` winds towards its vertex normals.
    pub face: DVec3,
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
    mesh: Held,
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// The allocator refused the hierarchy: the mesh is left out (no nodes), and built again
    /// by the next caster rather than kept.
    refused: bool,
}

/// A hierarchy's mesh: its `Arc` while a [`SceneRaycaster`] casts, a `Weak` while a
/// [`KeptCaster`] waits, so a mesh the game drops meanwhile is freed (its GPU upload too). The
/// `Weak` keeps the allocation, so no other mesh takes its address, the key it is found by.
#[derive(Debug)]
enum Held {
    Live(Arc<Mesh>),
    Kept(Weak<Mesh>),
}

impl Held {
    fn address(&self) -> *const Mesh {
        match self {
            Held::Live(mesh) => Arc::as_ptr(mesh),
            Held::Kept(mesh) => Weak::as_ptr(mesh),
        }
    }
}

impl MeshBvh {
    /// Its mesh: a [`SceneRaycaster`]'s hierarchies are all live.
    fn mesh(&self) -> &Mesh {
        match &self.mesh {
            Held::Live(mesh) => mesh,
            Held::Kept(_) => unreachable!("a kept caster casts no ray"),
        }
    }
}

/// A [`SceneRaycaster`] put away between uses ([`SceneRaycaster::keep`]) without holding its
/// meshes: [`KeptCaster::wake`] gives it back while the scene still has them all, and
/// [`SceneRaycaster::rebuilt`] keeps the hierarchies of those it still has.
#[derive(Debug)]
pub struct KeptCaster(SceneRaycaster);

impl KeptCaster {
    /// The caster again, for the scene it was built from (the same meshes, transforms and
    /// sides); itself back when one of its meshes was dropped since.
    pub fn wake(mut self) -> Result<SceneRaycaster, KeptCaster> {
        for m in &mut self.0.meshes {
            if let Held::Kept(mesh) = &m.mesh {
                match mesh.upgrade() {
                    Some(live) => m.mesh = Held::Live(live),
                    // Those woken so far are put away again.
                    None => return Err(self.0.keep()),
                }
            }
        }
        Ok(self.0)
    }
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
    /// Its material is single-sided: only its front faces are surfaces.
    front_only: bool,
    /// `to_world` mirrors, which turns the placed winding round.
    mirrored: bool,
}

impl Instance {
    /// The sign of a hit's winding (Möller–Trumbore's determinant) that is a surface in
    /// `frame`: `None` for both (double-sided). In object space the front is the positive
    /// one; carried into world space by a mirroring transform it turns negative.
    fn front_sign(&self, frame: &Frame) -> Option<bool> {
        let positive = match frame {
            Frame::Object { .. } => true,
            Frame::World { .. } => !self.mirrored,
        };
        self.front_only.then_some(positive)
    }
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
    /// Mesh hierarchies built by its construction, not kept from a previous caster.
    meshes_built: usize,
    /// [`SceneRaycaster::left_out_triangles`].
    left_out: u64,
}

/// The best hits of one search.
struct Search {
    /// (t, u, v, instance slot, triangle) of the nearest opaque hit.
    best: Option<(f64, f64, f64, usize, u32)>,
    best_t: f64,
    runner_up: f64,
    transparent_t: f64,
    /// Box and triangle tests it may still make (a shared reference: boxes are tested
    /// through one).
    work_left: std::cell::Cell<u64>,
}

impl Search {
    /// Takes one test from the work left; false once none is left.
    fn spend(&self) -> bool {
        let left = self.work_left.get();
        self.work_left.set(left.saturating_sub(1));
        left > 0
    }

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
        Self::rebuilt(None, scene)
    }

    /// Puts the caster away: it keeps its hierarchies but not their meshes.
    pub fn keep(mut self) -> KeptCaster {
        for m in &mut self.meshes {
            if let Held::Live(mesh) = &m.mesh {
                m.mesh = Held::Kept(Arc::downgrade(mesh));
            }
        }
        KeptCaster(self)
    }

    /// [`SceneRaycaster::new`], keeping `previous`'s hierarchy of every mesh the scene still
    /// places: objects that move rebuild only the level over the placed objects.
    pub fn rebuilt(previous: Option<KeptCaster>, scene: &Scene) -> Self {
        let mut kept: HashMap<*const Mesh, MeshBvh> = previous
            .map(|p| p.0.meshes)
            .unwrap_or_default()
            .into_iter()
            .map(|m| (m.mesh.address(), m))
            .collect();
        let mut meshes: Vec<MeshBvh> = Vec::new();
        let mut mesh_index: HashMap<*const Mesh, u32> = HashMap::new();
        let mut meshes_built = 0;
        let mut instances = Vec::new();
        let mut boxes = Vec::new();
        let mut left_out = 0;
        for (object, o) in scene.objects.iter().enumerate() {
            let key = Arc::as_ptr(&o.mesh);
            let mesh = *mesh_index.entry(key).or_insert_with(|| {
                let bvh = match kept.remove(&key).filter(|bvh| !bvh.refused) {
                    Some(bvh) => MeshBvh {
                        mesh: Held::Live(o.mesh.clone()),
                        ..bvh
                    },
                    None => {
                        meshes_built += 1;
                        MeshBvh::new(&o.mesh)
                    }
                };
                meshes.push(bvh);
                (meshes.len() - 1) as u32
            });
            let bvh = &meshes[mesh as usize];
            if bvh.refused {
                left_out += o.mesh.triangle_count() as u64;
            }
            let Some(root) = bvh.nodes.first() else {
                continue; // no triangles, or left out
            };
            let world = bvh::transformed_box(root.min, root.max, &o.transform);
            if !(world.0.is_finite() && world.1.is_finite()) {
                continue; // a scene that validates has finite transforms
            }
            boxes.push(world);
            let material = scene.materials.get(o.material);
            instances.push(Instance {
                to_world: o.transform,
                to_object: usable_inverse(&o.transform),
                mesh,
                object: object as u32,
                front_only: material.is_some_and(|m| !m.double_sided),
                mirrored: super::normal_matrix::mirrors(&DMat3::from_mat4(o.transform)),
            });
        }
        // Objects are few next to triangles; refused, nothing is placed.
        let (nodes, order) = bvh::build(&boxes).unwrap_or_else(|_| {
            left_out = scene
                .objects
                .iter()
                .map(|o| o.mesh.triangle_count() as u64)
                .sum();
            Default::default()
        });
        drop(boxes);
        let instances = order.iter().map(|&i| instances[i as usize]).collect();
        SceneRaycaster {
            meshes,
            instances,
            nodes,
            meshes_built,
            left_out,
        }
    }

    /// Triangles the caster leaves out, each placement counted (rays pass through them):
    /// those of meshes whose hierarchy this process could not allocate, or every one where the
    /// placed objects' could not be. 0 normally.
    pub fn left_out_triangles(&self) -> u64 {
        self.left_out
    }

    /// How many mesh hierarchies its construction built (the rest were kept).
    pub fn meshes_built(&self) -> usize {
        self.meshes_built
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

    /// Nearest surface along `origin + t·dir` with `t > 0` (either face of a double-sided
    /// material).
    pub fn hit(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        self.first_opaque_hit(origin, dir, f64::INFINITY, |_| true)
            .hit
    }

    /// [`Self::hit`] making at most `*work` box and triangle tests, taken from it; `None` when
    /// they run out before the search ends (the nearest surface is then not known). Triangles
    /// that overlap one another defeat any hierarchy: a ray then tests most of them.
    pub fn hit_within(&self, origin: DVec3, dir: DVec3, work: &mut u64) -> Option<Option<Hit>> {
        let (found, left) = self.search(origin, dir, f64::INFINITY, |_| true, *work);
        *work = left;
        (left > 0).then_some(found.hit)
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
        self.search(origin, dir, t_max, is_opaque, u64::MAX).0
    }

    /// [`Self::first_opaque_hit`] within `work` box and triangle tests, and the work left.
    fn search(
        &self,
        origin: DVec3,
        dir: DVec3,
        t_max: f64,
        is_opaque: impl Fn(usize) -> bool,
        work: u64,
    ) -> (FirstOpaque, u64) {
        let mut search = Search {
            best: None,
            best_t: t_max,
            runner_up: f64::INFINITY,
            transparent_t: f64::INFINITY,
            work_left: std::cell::Cell::new(work),
        };
        let inv = dir.recip();
        let (mut top, mut inner) = STACKS.with(|s| std::mem::take(&mut *s.borrow_mut()));
        bvh::traverse(
            &self.nodes,
            &mut top,
            &mut search,
            |node, s| {
                s.spend()
                    .then(|| node.slab(origin, inv, s.reach()))
                    .flatten()
            },
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
                    let front = instance.front_sign(&frame);
                    mesh.search(&frame, front, &mut inner, s, |s, t, u, v, triangle| {
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
        let hit = search.best.map(|(t, u, v, slot, triangle)| {
            self.make_hit((slot, triangle), (t, u, v), origin, dir)
        });
        // Ties count as in front: a transparent surface coplanar with an opaque one is blended.
        let limit = hit.map_or(t_max, |h| h.t);
        let found = FirstOpaque {
            hit,
            transparent_t: (search.transparent_t <= limit).then_some(search.transparent_t),
            runner_up_t: hit
                .filter(|_| search.runner_up <= search.reach())
                .map(|_| search.runner_up),
        };
        (found, search.work_left.get())
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
        let mesh = self.meshes[instance.mesh as usize].mesh();
        let corners = corners(mesh, triangle);
        let world = corners.map(|i| {
            instance
                .to_world
                .transform_point3(mesh.positions[i].as_dvec3())
        });
        let linear = DMat3::from_mat4(instance.to_world);
        let geometric = (world[1] - world[0]).cross(world[2] - world[0]);
        // A mirroring transform turns the placed winding round; the GPU draws such an object
        // with the opposite front face.
        let face = if super::normal_matrix::mirrors(&linear) {
            -geometric
        } else {
            geometric
        };
        // Made unit without squaring: the cross product of huge edges overflows a square.
        let face = super::direction::unit(face).unwrap_or(DVec3::ZERO);
        // Vertex normals times the normal matrix, made unit (zero where the matrix takes them
        // to nothing), interpolated and normalised again: what `mesh.vert` and the fragment
        // shader do. `Mesh::new` always fills normals; a hand-built mesh without them shades
        // flat.
        let n = if mesh.normals.len() == mesh.positions.len() {
            let normal_matrix = super::normal_matrix::normal_matrix(&linear);
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
            normal: n.try_normalize().unwrap_or(face),
            face,
            object: instance.object as usize,
            triangle: triangle as usize,
        }
    }
}

impl MeshBvh {
    /// The mesh's hierarchy, or none (`refused`) where the allocator refuses it.
    fn new(mesh: &Arc<Mesh>) -> MeshBvh {
        let triangles = mesh.triangle_count();
        let mut boxes = Vec::new();
        let built = boxes.try_reserve_exact(triangles).and_then(|()| {
            boxes.extend((0..triangles as u32).map(|t| {
                let [a, b, c] = corners(mesh, t).map(|i| mesh.positions[i].as_dvec3());
                (a.min(b).min(c), a.max(b).max(c))
            }));
            bvh::build(&boxes)
        });
        let refused = built.is_err();
        let (nodes, order) = built.unwrap_or_default();
        MeshBvh {
            mesh: Held::Live(mesh.clone()),
            nodes,
            order,
            refused,
        }
    }

    /// Tests the ray against every triangle whose boxes it reaches, calling `found` with
    /// `(t, u, v, triangle)` for each hit within the search's reach whose winding's sign is
    /// `front` (any with `None`).
    fn search(
        &self,
        frame: &Frame,
        front: Option<bool>,
        stack: &mut Vec<u32>,
        s: &mut Search,
        mut found: impl FnMut(&mut Search, f64, f64, f64, u32),
    ) {
        let mesh = self.mesh();
        let positions = &mesh.positions;
        let (origin, dir) = match *frame {
            Frame::Object { origin, dir } | Frame::World { origin, dir, .. } => (origin, dir),
        };
        let inv = dir.recip();
        let vertices = |triangle: u32| {
            let v = corners(mesh, triangle).map(|i| positions[i].as_dvec3());
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
                _ if !s.spend() => None,
                Frame::Object { .. } => node.slab(origin, inv, s.reach()),
                Frame::World { to_world, .. } => {
                    node.slab_transformed(to_world, origin, inv, s.reach())
                }
            },
            |s, range| {
                for &triangle in &self.order[range] {
                    if !s.spend() {
                        return;
                    }
                    if let Some((t, u, v, positive)) = intersect(vertices(triangle), origin, dir) {
                        if t <= s.reach() && front.is_none_or(|f| f == positive) {
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

/// Möller–Trumbore, both faces: `(t, u, v, positive)` with `t > 0`, the hit at
/// `(1 − u − v)·v0 + u·v1 + v·v2`; `positive` when the ray meets the side the winding faces
/// (counter-clockwise seen from the origin).
fn intersect([v0, v1, v2]: [DVec3; 3], origin: DVec3, dir: DVec3) -> Option<(f64, f64, f64, bool)> {
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
    (t > 0.0).then_some((t, u, v, det > 0.0))
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
mod tests;
