//! Texel layouts of the cluster grid and the light index list.
//!
//! Both textures are [`DATA_TEXTURE_WIDTH`] texels wide, rows as needed.
//!
//! ```text
//! Grid texture: a cascade table (two texels a cascade), then one texel per cell.
//!
//!   ES 2.0, RGBA8 (4 bytes per texel)
//!     texel 2k     cascade k: tx.hi tx.lo ty.hi ty.lo                 (tiles_x, tiles_y)
//!     texel 2k+1   cascade k: slices first.hi first.mid first.lo      (slices, first cell)
//!     texel 2C+i   cell i: where its list starts, 32-bit big-endian
//!     texel 2C+N   where the last cell's list ends (N cells)
//!     → starts ≤ 2²⁴ (exact integers in the shader's highp float), counts ≤ 4 095 (the
//!       shader's constant loop bound)
//!
//!   ES 3.0, R32UI (4 bytes per texel)
//!     texel 2k     cascade k: tiles_x | tiles_y << 16
//!     texel 2k+1   cascade k: slices | first cell << 8
//!     texel 2C+i   cell i: where its list starts in the index list
//!     texel 2C+N   where the last cell's list ends (N cells)
//!
//!   Both: a cell's count is the next texel's start less its own (the lists are contiguous,
//!   cell after cell): one fetch more a fragment (not a light) than an (offset, count) texel,
//!   for half the bytes on ES 3.0 and 16 times the indices on ES 2.0 (a 20-bit offset beside a
//!   12-bit count addressed 2²⁰). Tiles < 2¹⁶ a side, slices ≤ 255 a cascade, cells < 2²⁴
//!   ([`grid_fits_table`]).
//!
//! Index texture: light numbers (positions in the uploaded light texture), grouped by cell.
//!   ES 2.0, RGBA8: two 16-bit indices per texel (i.hi i.lo j.hi j.lo)    2 bytes per index
//!   ES 3.0, RGBA16UI: four indices per texel (index i in channel i mod 4)   2 bytes per index
//!   → at most 65 536 lights per frame; the ES 3.0 texture holds twice the references of the
//!     ES 2.0 one for the same rows (four times those of one index a texel: a fine grid at
//!     1280×720 lists tens of millions)
//! ```
//!
//! Budget at 640×360 with the automatic grid on the courtyard (about 140 000 cells, 1 024
//! lights, ~660 000 indices): 560 KB grid + 1.3 MB indices per frame on either version.

use super::lights::DATA_TEXTURE_WIDTH;
use crate::cluster::assign::index_list::IndexList;
use crate::cluster::assign::Assignment;
use crate::cluster::grid::ClusterGrid;
use crate::cluster::headroom::try_zeroed_with_room;

/// Texels per cascade in the grid texture's table.
pub const TABLE_TEXELS_PER_CASCADE: u32 = 2;

/// Most cells a grid's table can address (the first cell of a cascade has 24 bits).
pub const MAX_TABLE_CELLS: u32 = 1 << 24;

/// `None` when the cascade table can describe `grid` (see the module docs), else what does
/// not fit.
pub fn grid_fits_table(grid: &ClusterGrid) -> Option<String> {
    if grid.total_cells >= MAX_TABLE_CELLS {
        return Some(format!(
            "{} cells (the grid texture's table addresses fewer than {MAX_TABLE_CELLS})",
            grid.total_cells
        ));
    }
    grid.cascades
        .iter()
        .find(|c| c.tiles_x > 0xFFFF || c.tiles_y > 0xFFFF || c.slices > 255)
        .map(|c| {
            format!(
                "a cascade of {} × {} tiles and {} slices (the table holds at most 65 535 tiles \
                 a side and 255 slices)",
                c.tiles_x, c.tiles_y, c.slices
            )
        })
}

/// Most lights a cell can hold on ES 2.0: the shader's constant loop bound.
pub const RGBA8_CELL_CAP: u32 = 4095;

/// Most lights per frame the 16-bit index lists can name.
pub const MAX_INDEXED_LIGHTS: usize = 1 << 16;

/// Most indices the RGBA8 grid's list starts can address: integers a highp (fp32) float holds
/// exactly, as the ES 2.0 shader decodes them.
pub const RGBA8_OFFSET_LIMIT: usize = 1 << 24;

/// How grid and index texels are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GridEncoding {
    /// RGBA8 bytes (ES 2.0).
    Rgba8,
    /// Integer textures read with `texelFetch` (ES 3.0).
    Uint,
}

impl GridEncoding {
    /// The encoding a feature level reads: RGBA8 on ES 2.0, integer textures on ES 3.0.
    pub fn for_es(es: crate::gl::EsVersion) -> GridEncoding {
        match es {
            crate::gl::EsVersion::Es2 => GridEncoding::Rgba8,
            crate::gl::EsVersion::Es3 => GridEncoding::Uint,
        }
    }

    /// Bytes per cell in the grid texture.
    pub fn cell_bytes(self) -> usize {
        4
    }

    /// Bytes per light index in the index texture (16-bit light numbers either way).
    pub fn index_bytes(self) -> usize {
        2
    }

    /// Light indices per texel of the index texture (RGBA8: two, RGBA16UI: four).
    pub fn indices_per_texel(self) -> usize {
        match self {
            GridEncoding::Rgba8 => 2,
            GridEncoding::Uint => 4,
        }
    }
}

/// Texels ready to upload.
#[derive(Clone, Debug, PartialEq)]
pub struct PackedTexels {
    /// Width in texels.
    pub width: u32,
    /// Rows the texels take (at least 1): the texture's height.
    pub height: u32,
    /// The texels in use, row-major: the last row only as far as they reach (the rest of it
    /// is never read, so it is neither packed nor uploaded).
    pub bytes: Vec<u8>,
}

fn rows_for(texels: usize) -> u32 {
    texels.div_ceil(DATA_TEXTURE_WIDTH as usize).max(1) as u32
}

fn be24(v: u32) -> [u8; 3] {
    let b = v.to_be_bytes();
    [b[1], b[2], b[3]]
}

/// Texels of `grid`'s grid texture: the cascade table, then one per cell (and one more, where
/// the last cell's list ends).
pub fn grid_texels(grid: &ClusterGrid) -> usize {
    // Saturating: a refused grid's cell count saturates at u32::MAX, past a 32-bit usize.
    (grid.cascades.len() * TABLE_TEXELS_PER_CASCADE as usize)
        .saturating_add(grid.total_cells as usize)
        .saturating_add(1)
}

impl Default for PackedTexels {
    fn default() -> Self {
        PackedTexels::empty()
    }
}

impl PackedTexels {
    /// No texels yet: a buffer for [`pack_grid_into`] or [`pack_indices_into`] to fill frame
    /// after frame.
    pub fn empty() -> PackedTexels {
        PackedTexels {
            width: DATA_TEXTURE_WIDTH,
            height: 0,
            bytes: Vec::new(),
        }
    }
}

/// Packs the cascade table and where each cell's list starts (and, after the last cell, where
/// its list ends).
///
/// # Panics
///
/// Where its bytes cannot be allocated (a frame uses [`pack_grid_into`], which says so).
pub fn pack_grid(grid: &ClusterGrid, a: &Assignment, encoding: GridEncoding) -> PackedTexels {
    let mut packed = PackedTexels::empty();
    pack_grid_into(grid, a, encoding, &mut packed).expect("the grid texels are allocated");
    packed
}

/// [`pack_grid`] into `packed`, reusing its bytes (no allocation once they have grown); the
/// bytes the allocator refused, if it did.
pub fn pack_grid_into(
    grid: &ClusterGrid,
    a: &Assignment,
    encoding: GridEncoding,
    packed: &mut PackedTexels,
) -> Result<(), u64> {
    let table = grid.cascades.len() * TABLE_TEXELS_PER_CASCADE as usize;
    let height = rows_for(grid_texels(grid));
    let bytes = &mut packed.bytes;
    try_zeroed_with_room(bytes, grid_texels(grid) * 4)?;
    let mut put =
        |texel: usize, value: [u8; 4]| bytes[texel * 4..texel * 4 + 4].copy_from_slice(&value);
    match encoding {
        GridEncoding::Rgba8 => {
            for (k, c) in grid.cascades.iter().enumerate() {
                let [xh, xl] = (c.tiles_x as u16).to_be_bytes();
                let [yh, yl] = (c.tiles_y as u16).to_be_bytes();
                put(2 * k, [xh, xl, yh, yl]);
                let [f0, f1, f2] = be24(c.first_cell);
                put(2 * k + 1, [c.slices.min(255) as u8, f0, f1, f2]);
            }
        }
        GridEncoding::Uint => {
            for (k, c) in grid.cascades.iter().enumerate() {
                put(2 * k, (c.tiles_x | c.tiles_y << 16).to_le_bytes());
                put(
                    2 * k + 1,
                    (c.slices.min(255) | c.first_cell << 8).to_le_bytes(),
                );
            }
        }
    }
    // Each cell's list start, then where the last list ends (the lists are contiguous, cell
    // after cell, also after the overflow policy compacted them).
    let end = match (a.offsets.last(), a.counts.last()) {
        (Some(&o), Some(&n)) => o + n,
        _ => 0,
    };
    let word = |v: u32| match encoding {
        GridEncoding::Rgba8 => v.to_be_bytes(),
        GridEncoding::Uint => v.to_le_bytes(),
    };
    for (cell, &offset) in a.offsets.iter().enumerate() {
        put(table + cell, word(offset));
    }
    put(table + a.offsets.len(), word(end));
    packed.width = DATA_TEXTURE_WIDTH;
    packed.height = height;
    Ok(())
}

/// Packs the index list (16-bit light numbers; entries of a 32-bit list keep their low 16
/// bits: a renderer refuses more than [`MAX_INDEXED_LIGHTS`] visible lights before packing).
///
/// # Panics
///
/// Where its bytes cannot be allocated (a frame uses [`pack_indices_into`], which says so).
pub fn pack_indices(indices: &IndexList, encoding: GridEncoding) -> PackedTexels {
    let mut packed = PackedTexels::empty();
    pack_indices_into(indices, encoding, &mut packed).expect("the index texels are allocated");
    packed
}

/// [`pack_indices`] into `packed`, reusing its bytes (no allocation once they have grown);
/// the bytes the allocator refused, if it did.
pub fn pack_indices_into(
    indices: &IndexList,
    encoding: GridEncoding,
    packed: &mut PackedTexels,
) -> Result<(), u64> {
    let per_texel = encoding.indices_per_texel();
    let texels = indices.len().div_ceil(per_texel);
    let height = rows_for(texels);
    let bytes = &mut packed.bytes;
    try_zeroed_with_room(bytes, texels * per_texel * encoding.index_bytes())?;
    match (indices.as_u16(), indices.as_u32()) {
        (Some(list), _) => put_indices(bytes, list.iter().copied(), encoding),
        (_, Some(list)) => put_indices(bytes, list.iter().map(|&v| v as u16), encoding),
        _ => {}
    }
    packed.width = DATA_TEXTURE_WIDTH;
    packed.height = height;
    Ok(())
}

/// Writes `values` two bytes each: big-endian pairs for RGBA8 (texel i/2 holds index i in .xy
/// when i is even, .zw when odd), little-endian for RGBA16UI (texel i/4, channel i mod 4).
fn put_indices(bytes: &mut [u8], values: impl Iterator<Item = u16>, encoding: GridEncoding) {
    let pairs = bytes.chunks_exact_mut(2).zip(values);
    match encoding {
        GridEncoding::Rgba8 => pairs.for_each(|(pair, v)| pair.copy_from_slice(&v.to_be_bytes())),
        GridEncoding::Uint => pairs.for_each(|(pair, v)| pair.copy_from_slice(&v.to_le_bytes())),
    }
}

/// Reads a cell's (offset, count) back exactly as the shader decodes it.
pub fn unpack_cell(
    packed: &PackedTexels,
    grid: &ClusterGrid,
    cell: u32,
    encoding: GridEncoding,
) -> (u32, u32) {
    let t = grid.cascades.len() * TABLE_TEXELS_PER_CASCADE as usize + cell as usize;
    let start_at = |t: usize| {
        let texel: [u8; 4] = packed.bytes[t * 4..t * 4 + 4].try_into().unwrap();
        match encoding {
            GridEncoding::Rgba8 => u32::from_be_bytes(texel),
            GridEncoding::Uint => u32::from_le_bytes(texel),
        }
    };
    let (start, end) = (start_at(t), start_at(t + 1));
    (start, end.wrapping_sub(start))
}

/// Reads index `i` back exactly as the shader decodes it: from texel `i / n`, channel pair or
/// channel `i mod n` (`n` indices a texel).
pub fn unpack_index(packed: &PackedTexels, i: usize, encoding: GridEncoding) -> u32 {
    let per_texel = encoding.indices_per_texel();
    let (texel, slot) = (i / per_texel, i % per_texel);
    let at = texel * 2 * per_texel + slot * 2;
    let b = &packed.bytes[at..at + 2];
    match encoding {
        GridEncoding::Rgba8 => u16::from_be_bytes([b[0], b[1]]) as u32,
        GridEncoding::Uint => u16::from_le_bytes([b[0], b[1]]) as u32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cluster::assign::{assign, AssignLimits};
    use crate::cluster::grid::{GridConfig, GridProjection};
    use crate::cluster::view_light::GpuLight;
    use crate::scene::Light;
    use glam::{DVec3, Vec3};

    #[test]
    fn grid_and_indices_round_trip_exactly_in_both_encodings() {
        let grid = ClusterGrid::new(
            640,
            360,
            GridProjection::Perspective {
                tan_x: 1.0,
                tan_y: 0.6,
            },
            0.1,
            60.0,
            &GridConfig::default(),
        );
        let lights: Vec<GpuLight> = (0..2000)
            .map(|i| {
                let f = i as f64;
                let p = DVec3::new(
                    (f * 0.7).sin() * 20.0,
                    (f * 0.3).cos() * 8.0,
                    -1.0 - (f * 0.013) % 55.0,
                );
                GpuLight::from_light(
                    &Light::point(p, 1.0 + (i % 5) as f32, Vec3::ONE, 1.0),
                    &glam::DMat4::IDENTITY,
                )
            })
            .collect();
        let full = assign(&grid, &lights, 60.0, &AssignLimits::default());
        assert!(full.indices.len() > 1000);
        // Also lists the overflow policy trimmed and compacted (ES 3.0 derives each count
        // from the next cell's start, so the lists must stay contiguous).
        let capped = assign(
            &grid,
            &lights,
            60.0,
            &AssignLimits {
                cell_cap: 2,
                ..AssignLimits::default()
            },
        );
        assert!(capped.stats.overflowed_lights > 0);
        for (a, enc) in [
            (&full, GridEncoding::Rgba8),
            (&full, GridEncoding::Uint),
            (&capped, GridEncoding::Rgba8),
            (&capped, GridEncoding::Uint),
        ] {
            let g = pack_grid(&grid, a, enc);
            let ix = pack_indices(&a.indices, enc);
            for cell in 0..grid.total_cells {
                assert_eq!(
                    unpack_cell(&g, &grid, cell, enc),
                    (a.offsets[cell as usize], a.counts[cell as usize])
                );
            }
            for (i, v) in a.indices.to_vec().into_iter().enumerate() {
                assert_eq!(unpack_index(&ix, i, enc), v);
            }
            assert_eq!(g.width, DATA_TEXTURE_WIDTH);
            // RGBA8 holds two indices a texel, RGBA16UI four: the rows the list needs.
            let (per_texel, texel_bytes) = match enc {
                GridEncoding::Rgba8 => (2, 4),
                GridEncoding::Uint => (4, 8),
            };
            let rows = a
                .indices
                .len()
                .div_ceil(per_texel * DATA_TEXTURE_WIDTH as usize);
            assert_eq!(ix.height as usize, rows.max(1));
            // Only the texels the list fills: the last row's rest is not uploaded.
            assert_eq!(
                ix.bytes.len(),
                a.indices.len().div_ceil(per_texel) * texel_bytes
            );
        }
    }

    #[test]
    fn table_holds_the_cascades() {
        let grid = ClusterGrid::new(
            640,
            360,
            GridProjection::Perspective {
                tan_x: 1.0,
                tan_y: 0.6,
            },
            0.1,
            60.0,
            &GridConfig::default(),
        );
        let a = assign(&grid, &[], 60.0, &AssignLimits::default());
        let g = pack_grid(&grid, &a, GridEncoding::Rgba8);
        for (k, c) in grid.cascades.iter().enumerate() {
            let t = &g.bytes[k * 8..k * 8 + 8];
            assert_eq!(u16::from_be_bytes([t[0], t[1]]) as u32, c.tiles_x);
            assert_eq!(u16::from_be_bytes([t[2], t[3]]) as u32, c.tiles_y);
            assert_eq!(t[4] as u32, c.slices);
            assert_eq!(u32::from_be_bytes([0, t[5], t[6], t[7]]), c.first_cell);
        }
        // ES 3.0: two 32-bit texels a cascade (decoded as the shader does), then the cells'
        // starts and the end.
        let g = pack_grid(&grid, &a, GridEncoding::Uint);
        let word = |t: usize| u32::from_le_bytes(g.bytes[t * 4..t * 4 + 4].try_into().unwrap());
        for (k, c) in grid.cascades.iter().enumerate() {
            let (a, b) = (word(2 * k), word(2 * k + 1));
            let table = [a & 0xFFFF, a >> 16, b & 0xFF, b >> 8];
            assert_eq!(table, [c.tiles_x, c.tiles_y, c.slices, c.first_cell]);
        }
        assert_eq!(grid_fits_table(&grid), None);
        // One-pixel cells over a large frame: more cells than the table's 24-bit first cells
        // address (a texture of 32 768 rows would otherwise take them).
        let huge = ClusterGrid::new(
            8192,
            4096,
            GridProjection::Perspective {
                tan_x: 1.0,
                tan_y: 0.5,
            },
            0.1,
            60.0,
            &GridConfig {
                max_tiles: 8192,
                ..GridConfig::fixed(1.0)
            },
        );
        assert!(huge.total_cells >= MAX_TABLE_CELLS);
        let said = grid_fits_table(&huge).expect("refused");
        assert!(said.contains("cells"), "{said}");
        // The table, one texel a cell and the end: the rows' rest is left out.
        assert_eq!(g.bytes.len(), grid_texels(&grid) * 4);
        assert_eq!(
            g.height as usize,
            grid_texels(&grid).div_ceil(DATA_TEXTURE_WIDTH as usize)
        );
    }
}
