//! The shared engine of tiled and clustered forward: assign lights to a grid on the CPU every
//! frame, upload three data textures (lights, grid, indices), and shade in one geometry pass
//! where each fragment loops over its cell's lights only.
//!
//! Uploads are ring-buffered over [`RING`] texture sets: a frame writes the set the GPU used
//! `RING` frames ago, never one an in-flight frame may still read (drivers would otherwise stall
//! or copy on a rewrite).

use std::fmt::Write as _;
use std::time::Instant;

use glam::Vec3;

use super::geometry::{self, GeometryProgram, UNIT_METHOD};
use super::grid_choice::{self, AutoGrid};
use super::uniforms::{self, LightData, Surface, Transforms};
use super::GridReport;
use super::{FrameContext, MethodStats, ShaderFeatures, ShadingMethod};
use crate::cluster::assign::{AssignLimits, Assigner};
use crate::cluster::auto::{assign_work, FrameCost};
use crate::cluster::grid::{ClusterGrid, GridConfig, GridMode, GridProjection};
use crate::cluster::pack::{
    pack_lights_into, GpuLight, LightEncoding, PackedLights, DATA_TEXTURE_WIDTH,
};
use crate::cluster::pack_grid::{
    grid_fits_table, grid_texels, pack_grid_into, pack_indices_into, GridEncoding, PackedTexels,
    MAX_INDEXED_LIGHTS, RGBA8_CELL_CAP,
};
use crate::gl::program::{Resolver, Sampler, Uniform, UniformSet};
use crate::gl::texture::{DataFormat, DataTexture};
use crate::gl::{Device, EsVersion};
use crate::Error;

/// Texture sets in the upload ring.
pub const RING: usize = 3;

/// Which grid the method builds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Culling {
    /// 2D screen tiles, one slice over the whole depth range.
    Tiled,
    /// The dense cascaded cluster grid.
    Clustered,
}

/// The `clustered` shader's uniforms (tiled and clustered forward).
pub struct ClusteredProgram {
    transforms: Transforms,
    surface: Surface,
    lights: LightData,
    cells: CellLookup,
    /// The frame's longest cell list (the uniform light loop's bound).
    longest_list: Uniform<f32>,
}

/// `cluster_lookup.glsl`: how a fragment finds its cell and reads its list.
struct CellLookup {
    viewport: Uniform<[f32; 2]>,
    depth_map: Uniform<Vec3>,
    cascade_count: Uniform<f32>,
    grid: Uniform<Sampler>,
    indices: Uniform<Sampler>,
    /// ES 2.0: 1 / the grid's and the index texture's heights.
    inv_heights: Uniform<[f32; 2]>,
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
                depth_map: r.required("u_depthMap"),
                cascade_count: r.required("u_cascadeCount"),
                grid: r.required("u_grid"),
                indices: r.required_when(lit, "u_indices"),
                inv_heights: r.required_when(es2, "u_gridInvHeight"),
            },
            // Only the ES 2.0 loop has a constant bound to stop early.
            longest_list: r.required_when(
                lit && es2 && f.has(ShaderFeatures::UNIFORM_LIGHT_LOOP),
                "u_longestList",
            ),
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
}

struct TextureSet {
    lights: DataTexture,
    light_encoding: LightEncoding,
    grid: DataTexture,
    indices: DataTexture,
}

impl TextureSet {
    fn new(dev: &Device, light_encoding: LightEncoding) -> Result<TextureSet, Error> {
        let light_format = match light_encoding {
            LightEncoding::Float32 => DataFormat::Rgba32F,
            LightEncoding::Rgba8 => DataFormat::Rgba8,
        };
        let (grid, indices) = match dev.es() {
            EsVersion::Es2 => (DataFormat::Rgba8, DataFormat::Rgba8),
            EsVersion::Es3 => (DataFormat::R32Ui, DataFormat::Rgba16Ui),
        };
        Ok(TextureSet {
            lights: DataTexture::new(dev, light_format)?,
            light_encoding,
            grid: DataTexture::new(dev, grid)?,
            indices: DataTexture::new(dev, indices)?,
        })
    }

    fn destroy(mut self, dev: &Device) {
        self.lights.destroy(dev);
        self.grid.destroy(dev);
        self.indices.destroy(dev);
    }

    fn gpu_bytes(&self) -> usize {
        self.lights.gpu_bytes() + self.grid.gpu_bytes() + self.indices.gpu_bytes()
    }
}

/// Tiled or clustered forward.
pub struct CulledForward {
    culling: Culling,
    ring: Vec<Option<TextureSet>>,
    frame: usize,
    grid: Option<(GridKey, ClusterGrid)>,
    /// Assignment buffers, reused frame after frame.
    assigner: Assigner,
    /// The automatic grid's choice and calibration (clustered, [`GridMode::Auto`]).
    auto: AutoGrid,
    /// What a frame fills and uploads, kept so a frame allocates nothing once they have grown:
    /// the visible lights, their texels, the grid's and the index list's texels.
    visible: Vec<GpuLight>,
    packed_lights: PackedLights,
    packed_grid: PackedTexels,
    packed_indices: PackedTexels,
    /// Why a tiled or fixed grid is what it is (the automatic grid keeps its own reason).
    reason: String,
    /// Whether the overflow policy's dropping lights has been warned about (once per method:
    /// `FrameStats::overflowed_lights` counts every frame's).
    warned_overflow: bool,
}

/// What the grid depends on; it is rebuilt only when this changes.
#[derive(Clone, Debug, PartialEq)]
struct GridKey {
    size: (u32, u32),
    projection: GridProjection,
    near: u64,
    far: u64,
    config: GridConfig,
}

impl CulledForward {
    /// A method with no GPU resources yet (created on first render).
    pub fn new(culling: Culling) -> Self {
        CulledForward {
            culling,
            ring: (0..RING).map(|_| None).collect(),
            frame: 0,
            grid: None,
            assigner: Assigner::new(),
            auto: AutoGrid::default(),
            visible: Vec::new(),
            packed_lights: PackedLights::default(),
            packed_grid: PackedTexels::default(),
            packed_indices: PackedTexels::default(),
            reason: String::new(),
            warned_overflow: false,
        }
    }

    /// Rebuilds the grid when the viewport, projection or grid settings changed (the
    /// automatic grid's included).
    fn update_grid(&mut self, ctx: &FrameContext, limits: &AssignLimits, encoding: GridEncoding) {
        let projection = GridProjection::from_matrix(&ctx.projection.as_dmat4());
        let config = match self.culling {
            Culling::Clustered if self.automatic(ctx) => {
                let choice = self.auto.config(ctx, projection, limits, encoding);
                choice.config.clone()
            }
            Culling::Clustered => ctx.options.grid.clone(),
            // Tiled shares the clustered grid's coverage setting (to measure it).
            Culling::Tiled => GridConfig {
                coverage: ctx.options.grid.coverage,
                ..GridConfig::tiles(ctx.options.tile_px)
            },
        };
        let key = GridKey {
            size: ctx.viewport,
            projection,
            near: ctx.near.to_bits(),
            far: ctx.content_far.to_bits(),
            config: config.clone(),
        };
        if self.grid.as_ref().map(|(k, _)| k) != Some(&key) {
            let (w, h) = ctx.viewport;
            match &mut self.grid {
                // In place: a moving camera changes the depth range, and so the grid, every
                // frame.
                Some((old_key, grid)) => {
                    grid.rebuild(w, h, projection, ctx.near, ctx.content_far, &config);
                    *old_key = key;
                }
                None => {
                    let grid =
                        ClusterGrid::new(w, h, projection, ctx.near, ctx.content_far, &config);
                    self.grid = Some((key, grid));
                }
            }
        }
    }

    /// Whether this frame's grid is the automatic one.
    fn automatic(&self, ctx: &FrameContext) -> bool {
        self.culling == Culling::Clustered && ctx.options.grid.mode == GridMode::Auto
    }

    /// Writes why a tiled or fixed grid is what it is into `self.reason` (the automatic grid
    /// says it in [`AutoGrid::reason`]).
    fn write_grid_reason(&mut self, ctx: &FrameContext) {
        self.reason.clear();
        match self.culling {
            Culling::Tiled => {
                let _ = write!(self.reason, "tiled: tile_px = {}", ctx.options.tile_px);
            }
            Culling::Clustered if self.automatic(ctx) => {}
            Culling::Clustered => {
                grid_choice::write_fixed_reason(&mut self.reason, &ctx.options.grid)
            }
        }
    }
}

impl ShadingMethod for CulledForward {
    fn name(&self) -> &'static str {
        match self.culling {
            Culling::Tiled => "tiled",
            Culling::Clustered => "clustered",
        }
    }

    /// Renders one frame (see the module docs).
    fn render(&mut self, ctx: &mut FrameContext) -> Result<MethodStats<'_>, Error> {
        let method = self.name();
        let dev = ctx.dev;
        let es = dev.es();
        let grid_encoding = GridEncoding::for_es(es);
        let capacity = super::capacity::capacities(dev.caps());
        let max_rows = dev.caps().max_texture_size.max(1) as usize;
        let mut max_indices = capacity.index_entries;
        let cell_cap = ctx
            .options
            .cell_cap
            .unwrap_or(u32::MAX)
            .min(capacity.cell_lights.unwrap_or(u32::MAX));
        if let Some(m) = ctx.options.max_indices {
            max_indices = max_indices.min(m);
        }
        let limits = AssignLimits {
            cell_cap,
            max_indices,
            ..AssignLimits::default()
        };
        let camera_far = ctx.far;
        let lights = ctx.lights;
        self.update_grid(ctx, &limits, grid_encoding);
        let automatic = self.automatic(ctx);
        self.write_grid_reason(ctx);
        let (grid_key, grid) = self.grid.as_ref().expect("updated above");
        // Refused before any assignment: a grid the texture cannot hold would only fail at the
        // upload, after allocating its lists.
        let texels = grid_texels(grid);
        if texels > max_rows * DATA_TEXTURE_WIDTH as usize {
            return Err(Error::Limit(format!(
                "a {} px cell footprint (grid.footprint_px) makes {} grid cells; this context's \
                 grid texture holds {}: use a larger footprint, deeper slices (grid.slice_depth) \
                 or the automatic grid",
                grid_key.config.footprint_px,
                grid.total_cells,
                max_rows * DATA_TEXTURE_WIDTH as usize - (texels - grid.total_cells as usize)
            )));
        }
        // The table's 24-bit first cells: a limit only where the texture holds more cells
        // (16 384 rows of 1 024 texels hold 2²⁴ texels, table included).
        if let Some(what) = grid_fits_table(grid) {
            return Err(Error::Limit(format!(
                "a {} px cell footprint (grid.footprint_px) with these limits (grid.max_tiles, \
                 grid.max_slices) makes {what}: use a larger footprint or the automatic grid",
                grid_key.config.footprint_px
            )));
        }
        let started = Instant::now();
        let assignment = self.assigner.assign(grid, lights, camera_far, &limits);
        let assign_ms = started.elapsed().as_secs_f64() * 1e3;
        let dropped = assignment.stats.overflowed_lights;
        if dropped > 0 && !self.warned_overflow {
            self.warned_overflow = true;
            let cap = match limits.cell_cap {
                u32::MAX => "no cap per cell".to_string(),
                cap => format!("a cell keeps at most {cap} lights"),
            };
            log::warn!(
                "{method}: {dropped} light references left out of this frame's cell lists, so \
                 the image lacks those lights where they reach ({cap}, and at most {} \
                 references fit in the index list here: the index texture's capacity on this \
                 context or RenderOptions::max_indices; each cell keeps the lights that matter \
                 most to it, and FrameStats::overflowed_lights counts the dropped ones every \
                 frame): a coarser grid (grid.footprint_px), deeper slices (grid.slice_depth) \
                 or the automatic grid avoid it",
                limits.max_indices
            );
        }
        if assignment.visible.len() > MAX_INDEXED_LIGHTS {
            return Err(Error::Limit(format!(
                "{} lights are visible in this frame; tiled and clustered shading index at most {MAX_INDEXED_LIGHTS}",
                assignment.visible.len()
            )));
        }
        let upload_started = Instant::now();
        self.visible.clear();
        self.visible
            .extend(assignment.visible.iter().map(|&i| lights[i as usize]));
        let encoding = ctx.features.light_encoding();
        let (packed_lights, packed_grid, packed_indices) = (
            &mut self.packed_lights,
            &mut self.packed_grid,
            &mut self.packed_indices,
        );
        pack_lights_into(&self.visible, encoding, packed_lights);
        pack_grid_into(grid, assignment, grid_encoding, packed_grid);
        pack_indices_into(&assignment.indices, grid_encoding, packed_indices);

        let slot = self.frame % RING;
        self.frame += 1;
        if self.ring[slot]
            .as_ref()
            .is_some_and(|s| s.light_encoding != encoding)
        {
            if let Some(old) = self.ring[slot].take() {
                old.destroy(dev);
            }
        }
        if self.ring[slot].is_none() {
            self.ring[slot] = Some(TextureSet::new(dev, encoding)?);
        }
        let set = self.ring[slot].as_mut().expect("created above");
        set.lights.upload(
            dev,
            packed_lights.width,
            packed_lights.height,
            &packed_lights.bytes,
        )?;
        set.grid.upload(
            dev,
            packed_grid.width,
            packed_grid.height,
            &packed_grid.bytes,
        )?;
        set.indices.upload(
            dev,
            packed_indices.width,
            packed_indices.height,
            &packed_indices.bytes,
        )?;
        let upload_bytes =
            packed_lights.bytes.len() + packed_grid.bytes.len() + packed_indices.bytes.len();
        let upload_ms = upload_started.elapsed().as_secs_f64() * 1e3;
        if automatic {
            let work = assign_work(
                assignment.stats.runs,
                assignment.indices.len(),
                grid.total_cells,
            );
            self.auto.record(
                grid,
                &assignment.counts,
                FrameCost {
                    assign_ms,
                    assign_work: work,
                    upload_ms,
                    upload_bytes: upload_bytes as f64,
                    ..FrameCost::default()
                },
            );
        }

        let set = &*set;
        let inv_heights = [
            uniforms::inv_height(&set.grid),
            uniforms::inv_height(&set.indices),
        ];
        let (w, h) = ctx.viewport;
        let depth_map = Vec3::new(
            grid.a as f32,
            grid.b as f32,
            if grid.mapping == crate::cluster::grid::DepthMapping::Log2 {
                1.0
            } else {
                0.0
            },
        );
        let cascades = grid.cascades.len() as f32;
        let longest_list = assignment.stats.max_lights_per_cluster as f32;
        let ranges = [packed_lights.pos_range, packed_lights.radius_range];
        geometry::draw_objects(
            ctx,
            "clustered",
            RGBA8_CELL_CAP,
            &mut |p: &ClusteredProgram, dev| {
                p.lights.bind(dev, &set.lights, UNIT_METHOD, ranges);
                set.grid.bind(dev, UNIT_METHOD + 1);
                set.indices.bind(dev, UNIT_METHOD + 2);
                p.cells.grid.set(dev, UNIT_METHOD + 1);
                p.cells.indices.set(dev, UNIT_METHOD + 2);
                p.cells.inv_heights.set(dev, inv_heights);
                p.cells.viewport.set(dev, [w as f32, h as f32]);
                p.cells.depth_map.set(dev, depth_map);
                p.cells.cascade_count.set(dev, cascades);
                p.longest_list.set(dev, longest_list);
            },
        )?;
        Ok(MethodStats {
            upload_bytes,
            assign_ms: Some(assign_ms),
            assign: Some(assignment.stats),
            grid: Some(GridReport {
                footprint_px: grid_key.config.footprint_px,
                cells: grid.total_cells,
                reason: if automatic {
                    self.auto.reason()
                } else {
                    &self.reason
                },
            }),
            ..MethodStats::default()
        })
    }

    fn observe_frame(&mut self, frame_ms: Option<f64>, gpu_ms: Option<f64>) {
        self.auto.observe(frame_ms, gpu_ms);
    }

    fn light_lists(&self) -> Option<super::LightLists<'_>> {
        Some((&self.grid.as_ref()?.1, self.assigner.assignment()))
    }

    /// GPU bytes of all ring sets.
    fn gpu_bytes(&self) -> usize {
        self.ring.iter().flatten().map(TextureSet::gpu_bytes).sum()
    }

    /// Frees the ring.
    fn destroy(&mut self, dev: &Device) {
        for set in self.ring.iter_mut().filter_map(Option::take) {
            set.destroy(dev);
        }
    }
}
