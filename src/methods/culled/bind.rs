//! Stage bind: the textures and uniform values every program of the frame gets, computed
//! once per frame and set on each program the geometry pass draws with.

use glam::Vec3;

use super::upload::{TextureSet, Uploaded};
use crate::cluster::assign::Assignment;
use crate::cluster::grid::{ClusterGrid, DepthMapping};
use crate::gl::program::{Resolver, Sampler, Uniform, UniformSet};
use crate::gl::texture::DataTexture;
use crate::gl::{Device, EsVersion};
use crate::methods::directional::DirectionalUniforms;
use crate::methods::geometry::{GeometryProgram, UNIT_METHOD};
use crate::methods::uniforms::{self, inv_height, LightData, Surface, Transforms};
use crate::methods::ShaderFeatures;

/// Texture units of the light, grid and index textures.
const UNIT_LIGHTS: u32 = UNIT_METHOD;
const UNIT_GRID: u32 = UNIT_METHOD + 1;
const UNIT_INDICES: u32 = UNIT_METHOD + 2;

/// The `clustered` shader's uniforms (tiled and clustered forward).
pub struct ClusteredProgram {
    transforms: Transforms,
    surface: Surface,
    lights: LightData,
    cells: CellLookup,
    /// The frame's longest cell list (the uniform light loop's bound).
    longest_list: Uniform<f32>,
    directional: DirectionalUniforms,
}

/// `cluster_lookup.glsl`: how a fragment finds its cell and reads its list.
struct CellLookup {
    viewport: Uniform<[f32; 2]>,
    frame_origin: Uniform<[f32; 2]>,
    depth_map: Uniform<Vec3>,
    cascade_count: Uniform<f32>,
    grid: Uniform<Sampler>,
    indices: Uniform<Sampler>,
    /// ES 2.0: 1 / the grid's and the index texture's heights.
    inv_heights: Uniform<[f32; 2]>,
    /// ES 3.0: the view's half extents and whether it is orthographic (`shadedFrameXY`).
    projection: Uniform<Vec3>,
}

impl UniformSet for ClusteredProgram {
    fn resolve(r: &mut Resolver<'_>) -> Self {
        let f = uniforms::features(r);
        let es2 = r.es() == EsVersion::Es2;
        // Every variant finds its cell; a count variant does not read its list.
        let lit = !f.has(ShaderFeatures::COUNT_EVALS);
        ClusteredProgram {
            transforms: Transforms::resolve(r, lit),
            surface: Surface::shaded(r, lit),
            lights: LightData::resolve(r, lit),
            cells: CellLookup {
                viewport: r.required("u_viewport"),
                frame_origin: r.required_when(es2, "u_frameOrigin"),
                depth_map: r.required("u_depthMap"),
                cascade_count: r.required("u_cascadeCount"),
                grid: r.required("u_grid"),
                indices: r.required_when(lit, "u_indices"),
                inv_heights: r.required_when(es2, "u_gridInvHeight"),
                projection: r.required_when(!es2, "u_cellProjection"),
            },
            // Only the ES 2.0 loop has a constant bound to stop early.
            longest_list: r.required_when(
                lit && es2 && f.has(ShaderFeatures::UNIFORM_LIGHT_LOOP),
                "u_longestList",
            ),
            directional: DirectionalUniforms::resolve(r, lit),
        }
    }
}

impl GeometryProgram for ClusteredProgram {
    fn transforms(&self) -> &Transforms {
        &self.transforms
    }
    fn surface(&self) -> &Surface {
        &self.surface
    }
    fn directional(&self) -> Option<&DirectionalUniforms> {
        Some(&self.directional)
    }
}

/// What every program of the frame gets.
pub(super) struct Bindings<'a> {
    set: &'a TextureSet,
    light_ranges: [f32; 2],
    viewport: [f32; 2],
    frame_origin: [f32; 2],
    /// The depth → cascade mapping: `a`, `b`, and 1 for log2 (see `cluster_lookup.glsl`).
    depth_map: Vec3,
    cascades: f32,
    inv_heights: [f32; 2],
    projection: Vec3,
    longest_list: f32,
}

impl<'a> Bindings<'a> {
    /// The frame's values, from its uploads, grid and assignment.
    pub(super) fn new(
        uploaded: &Uploaded<'a>,
        grid: &ClusterGrid,
        assignment: &Assignment,
        (w, h): (u32, u32),
        origin: [u32; 2],
    ) -> Self {
        let set = uploaded.set;
        let log2 = if grid.mapping == DepthMapping::Log2 {
            1.0
        } else {
            0.0
        };
        Bindings {
            set,
            light_ranges: uploaded.light_ranges,
            viewport: [w as f32, h as f32],
            frame_origin: origin.map(|v| v as f32),
            depth_map: Vec3::new(grid.a as f32, grid.b as f32, log2),
            cascades: grid.cascades.len() as f32,
            inv_heights: [inv_height(&set.grid), inv_height(&set.indices)],
            projection: {
                let ([x, y], orthographic) = grid.projection.half_extents();
                Vec3::new(x, y, f32::from(u8::from(orthographic)))
            },
            longest_list: assignment.stats.max_lights_per_cluster as f32,
        }
    }

    /// Binds the frame's textures and sets its values on the current program `p`.
    pub(super) fn bind(&self, p: &ClusteredProgram, dev: &Device) {
        p.lights
            .bind(dev, &self.set.lights, UNIT_LIGHTS, self.light_ranges);
        let cells = &p.cells;
        bind_texture(dev, &self.set.grid, UNIT_GRID, &cells.grid);
        bind_texture(dev, &self.set.indices, UNIT_INDICES, &cells.indices);
        cells.inv_heights.set(dev, self.inv_heights);
        cells.viewport.set(dev, self.viewport);
        cells.frame_origin.set(dev, self.frame_origin);
        cells.depth_map.set(dev, self.depth_map);
        cells.cascade_count.set(dev, self.cascades);
        cells.projection.set(dev, self.projection);
        p.longest_list.set(dev, self.longest_list);
    }
}

fn bind_texture(dev: &Device, texture: &DataTexture, unit: u32, sampler: &Uniform<Sampler>) {
    texture.bind(dev, unit);
    sampler.set(dev, unit);
}
