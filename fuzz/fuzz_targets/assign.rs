//! The light assignment on grids and lights made from the input: any view size, projection,
//! near and far plane, footprint, cascades, slice depth, first split and most slices; lights
//! anywhere, of any radius, points and spots with any axis and cone, non-finite values among
//! them.
//!
//! Checks: no panic; one thread and a pool of two (bands, or chunks of lights) list the same
//! lights in every cell; and where the lights and the grid are of a size the checks can
//! compute exactly, a point a light reaches ([`points`]) is in a cell that lists it.
#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use manylight::cluster::assign::{AssignLimits, Assigner, Assignment};
use manylight::cluster::grid::{ClusterGrid, Coverage, GridConfig, GridMode, GridProjection};
use manylight::cluster::view_light::GpuLight;
use manylight::glam::{DMat4, DVec3, Vec3};
use manylight::{Cone, Light};

/// The input, read a few bytes at a time; zeros once it runs out.
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        match self.0.split_first() {
            Some((&b, rest)) => {
                self.0 = rest;
                b
            }
            None => 0,
        }
    }

    fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.byte(), self.byte()])
    }

    /// Mostly a value in ±327.67 at 0.01 steps; one in sixteen any `f32` bit pattern.
    fn float(&mut self) -> f32 {
        let v = self.u16();
        if v & 0xF == 0xF {
            f32::from_bits(u32::from_le_bytes([
                self.byte(),
                self.byte(),
                self.byte(),
                self.byte(),
            ]))
        } else {
            (v as i16) as f32 / 100.0
        }
    }

    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// A grid (its size, projection, planes and cells) from the input, and the camera's far plane.
fn grid(bytes: &mut Bytes) -> (ClusterGrid, f64) {
    let width = 1 + bytes.byte() as u32 % 200;
    let height = 1 + bytes.byte() as u32 % 200;
    let aspect = width as f64 / height as f64;
    let near: f64 = [0.1, 1e-4, 1e-7, 0.0, 1.0, 30.0][bytes.byte() as usize % 6];
    // Beyond the near plane, as a camera's (`Camera::validate` refuses others).
    let far: f64 = near + [80.0, 1e4, 1e7, f64::INFINITY, 2.0, 0.5][bytes.byte() as usize % 6];
    let projection_kind = bytes.byte();
    let projection = if projection_kind % 4 == 3 {
        let half_y = 0.01 + bytes.byte() as f64;
        GridProjection::Orthographic {
            half_x: half_y * aspect,
            half_y,
        }
    } else {
        let tan_y = (0.5 + bytes.byte() as f64 * 89.0 / 255.0)
            .to_radians()
            .tan();
        GridProjection::Perspective {
            tan_x: tan_y * aspect,
            tan_y,
        }
    };
    let mut config = GridConfig::fixed(2.0 + bytes.byte() as f64 / 4.0);
    config.mode = GridMode::Fixed;
    // Low bits: cascades; high bits: where the first cascade starts (on values that begin
    // the slice table's buckets, and off them).
    let cascades = bytes.byte();
    config.cascades = 1 + cascades as u32 % 16;
    config.first_split =
        [None, Some(1.0), Some(0.25), Some(near * 1.5 + 0.3)][cascades as usize >> 6];
    // Low bits: slice depth; the next two: the most slices a cascade has.
    let slices = bytes.byte() as usize;
    config.slice_depth = [1.0, 0.25, 4.0, 1.0 / 16.0][slices % 4];
    if let Some(most) = [None, Some(1), Some(2), Some(255)][(slices >> 2) % 4] {
        config.max_slices = most;
    }
    if bytes.byte() % 4 == 1 {
        config.measure.coverage = Coverage::CascadeBox;
    }
    // An infinite far plane: the grid ends where the scene's depths do (as the renderer
    // builds it), and the assignment is told the camera's.
    let scene_far = if far.is_finite() { far } else { 100.0 };
    let grid = ClusterGrid::new(width, height, projection, near, scene_far, &config);
    (grid, far)
}

/// A light as the renderer makes it from a scene's (identity view: the position is in view
/// space), its axis then left unnormalised or zero now and then.
fn light(bytes: &mut Bytes) -> GpuLight {
    let position = Vec3::new(bytes.float(), bytes.float(), bytes.float()).as_dvec3();
    let radius = bytes.float().abs();
    let kind = bytes.byte();
    let spot = kind.is_multiple_of(3);
    let light = if spot {
        let direction = Vec3::new(bytes.float(), bytes.float(), bytes.float()).as_dvec3();
        let outer_deg = 0.5 + bytes.byte() as f64 * 179.0 / 255.0;
        let inner_deg = outer_deg * bytes.byte() as f64 / 255.0;
        let cone = Cone {
            direction: direction.normalize_or(DVec3::Z),
            inner_deg,
            outer_deg,
        };
        Light::spot(position, radius, Vec3::ONE, 1.0, cone)
    } else {
        Light::point(position, radius, Vec3::ONE, 1.0)
    };
    let mut gpu = GpuLight::from_light(&light, &DMat4::IDENTITY);
    if spot && kind.is_multiple_of(5) {
        gpu.direction *= bytes.float();
    }
    gpu
}

fn pool() -> &'static rayon::ThreadPool {
    static POOL: OnceLock<rayon::ThreadPool> = OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a pool of two threads")
    })
}

fn cell_lights(a: &Assignment, cell: usize) -> Vec<u32> {
    let (o, n) = (a.offsets[cell] as usize, a.counts[cell] as usize);
    a.indices
        .range(o..o + n)
        .into_iter()
        .map(|i| a.visible[i as usize])
        .collect()
}

/// Whether `light` reaches the view-space point `p` (the shader's test, with a margin inside
/// its edges so that rounding in this check never asks for a light the shader would not add).
fn reaches(light: &GpuLight, p: DVec3) -> bool {
    let to = p - light.position.as_dvec3();
    let dist = to.length();
    if dist >= light.radius as f64 * (1.0 - 1e-6) {
        return false;
    }
    if light.spot_scale != 0.0 && dist > 0.0 {
        let cos = (to / dist).dot(light.direction.as_dvec3());
        let edge = 1.0 - light.spot_offset as f64 / light.spot_scale as f64;
        return cos >= edge + 1e-6;
    }
    true
}

/// The cell of the view-space point `p`, if it is on screen and between the planes (with a
/// margin: a point on a cell's border may be either side).
fn cell_of(grid: &ClusterGrid, p: DVec3) -> Option<usize> {
    let d = -p.z;
    if !(d > grid.near * (1.0 + 1e-6) + 1e-9 && d < grid.far * (1.0 - 1e-6)) {
        return None;
    }
    let (hx, hy) = grid.projection.half_extent(d);
    let (nx, ny) = (p.x / hx, p.y / hy);
    if !(nx.abs() < 1.0 - 1e-6 && ny.abs() < 1.0 - 1e-6) {
        return None;
    }
    let (px, py) = (
        (nx + 1.0) * 0.5 * grid.width as f64,
        (ny + 1.0) * 0.5 * grid.height as f64,
    );
    Some(grid.cell_index(grid.cell_of_fragment(px, py, d)) as usize)
}

/// Points `light` reaches: its centre, points 0.9 of its radius from it along each axis and
/// towards the eye, and 0.99 of it along the eight diagonals (near its edge, where a bound
/// that is a little too tight shows first).
fn points(light: &GpuLight) -> Vec<DVec3> {
    let c = light.position.as_dvec3();
    let r = light.radius as f64 * 0.9;
    let mut out = vec![c];
    for axis in [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        -DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
    ] {
        out.push(c + axis * r);
    }
    for diagonal in 0..8 {
        let sign = |bit: i32| if diagonal & bit == 0 { 1.0 } else { -1.0 };
        let direction = DVec3::new(sign(1), sign(2), sign(4)) / 3f64.sqrt();
        out.push(c + direction * light.radius as f64 * 0.99);
    }
    if c.length() > 0.0 {
        out.push(c - c.normalize() * r.min(c.length()));
    }
    if light.spot_scale != 0.0 {
        out.push(c + light.direction.as_dvec3() * r);
    }
    out.into_iter().filter(|&p| reaches(light, p)).collect()
}

/// Whether the checks of what reaches where are exact enough for this light: finite, of a
/// size between 10⁻³ and 10⁴, within 10⁴ of the eye, a spot's axis of unit length.
fn checkable(light: &GpuLight) -> bool {
    let p = light.position;
    let spot_ok = light.spot_scale == 0.0
        || ((light.direction.length() - 1.0).abs() < 1e-3 && light.spot_scale.is_finite());
    p.is_finite() && p.length() < 1e4 && (1e-3..1e4).contains(&light.radius) && spot_ok
}

fuzz_target!(|data: &[u8]| {
    let mut bytes = Bytes(data);
    let (grid, far) = grid(&mut bytes);
    if grid.total_cells > 1 << 14 {
        return;
    }
    let mut lights = Vec::new();
    while !bytes.is_empty() && lights.len() < 64 {
        lights.push(light(&mut bytes));
    }
    let limits = AssignLimits {
        max_threads: 1,
        cell_cap: u32::MAX,
        ..AssignLimits::default()
    };
    let one = Assigner::new().assign(&grid, &lights, far, &limits).clone();
    let two_limits = AssignLimits {
        max_threads: 2,
        parallel_threshold: 0,
        ..limits
    };
    let mut assigner = Assigner::new();
    let two = pool().install(|| assigner.assign(&grid, &lights, far, &two_limits).clone());
    assert_eq!(
        one.visible, two.visible,
        "one thread and two see other lights"
    );
    assert_eq!(one.counts, two.counts, "one thread and two list otherwise");
    for cell in 0..one.counts.len() {
        if one.counts[cell] != 0 {
            assert_eq!(
                cell_lights(&one, cell),
                cell_lights(&two, cell),
                "one thread and two list otherwise in cell {cell}"
            );
        }
    }
    if one.unlisted.is_some() || one.stats.overflowed_lights > 0 || one.counts.is_empty() {
        return;
    }
    for (i, light) in lights.iter().enumerate() {
        if !checkable(light) {
            continue;
        }
        for p in points(light) {
            if let Some(cell) = cell_of(&grid, p) {
                assert!(
                    cell_lights(&one, cell).contains(&(i as u32)),
                    "light {i} {light:?} reaches {p:?} but cell {cell} does not list it"
                );
            }
        }
    }
});
