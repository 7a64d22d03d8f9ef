//! What a grid is asked to be: [`GridConfig`] (cascades, cell footprint, first split, limits),
//! who picks the footprint ([`GridMode`]) and how tightly a light's cells are bounded
//! ([`Coverage`]).

/// Most depth cascades a grid has ([`GridConfig::cascades`]): far more than a depth range
/// needs (12 cover a 4096:1 range), and a bound on the per-cascade tables.
pub const MAX_CASCADES: u32 = 64;

/// The automatic grid's default CPU budget ([`GridMode::Auto`]): 5 % of the frame.
pub const DEFAULT_ASSIGN_BUDGET: f64 = 0.05;

/// Tunables of the grid.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GridConfig {
    /// Whether the clustered method picks the footprint itself every so often
    /// ([`GridMode::Auto`], the default) or always uses `footprint_px`.
    /// The grid itself is always built at `footprint_px`: the choice is the clustered method's.
    pub mode: GridMode,
    /// Number of depth cascades (Billeter uses 12), from 1 to 64 (0 counts as 1): the renderer
    /// refuses more, naming `grid.cascades`.
    pub cascades: u32,
    /// Target cell footprint in pixels (cells are about this wide, and `slice_depth` times as
    /// deep): the fixed mode's, and where the automatic mode starts.
    pub footprint_px: f64,
    /// Depth of a slice relative to a cell's width at its near end (1: cells about as deep as
    /// wide, Olsson's choice). Thinner slices tighten the lists where surfaces are seen at a
    /// grazing angle (a floor: a tile's fragments spread over many depths) at the cost of
    /// proportionally more cells. Values outside `1/16..=16` are clamped; a non-finite one is
    /// refused by the renderer (`ClusterGrid::new` reads it as 1). See docs/grid.md for what
    /// it buys.
    pub slice_depth: f64,
    /// Where the first cascade starts (perspective: depths nearer than it share the first
    /// slice); `None`: at the near plane, or 1/4096 of the far end for a tiny near plane. The
    /// automatic mode sets it a little before the nearest surface, so no slice is spent on the
    /// empty space in front of the camera.
    pub first_split: Option<f64>,
    /// Upper bound on slices per cascade (never above 255, what the ES 2.0 grid texture's byte
    /// holds).
    pub max_slices: u32,
    /// Upper bound on columns or rows of a cascade.
    pub max_tiles: u32,
    /// Knobs the benchmarks and tests measure the grid with; a game leaves them at their
    /// defaults.
    pub measure: GridMeasure,
}

/// The grid's measuring knobs ([`GridConfig::measure`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct GridMeasure {
    /// How tightly a light's cells are found (the default is the tight one; the other is kept
    /// to measure what it saves).
    pub coverage: Coverage,
    /// Minimum cell width in world units at a cascade's near end; `None`: no minimum, every
    /// cascade has cells of `footprint_px` (the grid starts at the first geometry, see
    /// [`GridConfig::first_split`], so near cascades are not wasted on empty space). The
    /// benchmarks' historical workload keeps its grid with it.
    pub min_cell_size: Option<f64>,
}

/// Who picks the cell footprint.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GridMode {
    /// The clustered method measures candidate footprints against a cost model calibrated on
    /// the device and switches with hysteresis (docs/grid.md).
    Auto {
        /// The largest share of the predicted frame time the CPU light assignment may take
        /// (0.05: 5 %). Among the candidate grids whose predicted assignment stays within it,
        /// the cheapest predicted frame wins; a finer grid that would save a little frame time
        /// for much more CPU is not taken (the CPU a game spends here is taken from its own
        /// work, and on a phone the GPU's frame does not pay it back). 1 (or more) leaves the
        /// frame time alone to decide; when no candidate fits, the one whose assignment takes
        /// the smallest share wins (the least CPU, not the most). A finite value from 0 up: the renderer refuses others naming
        /// `grid.assign_budget`.
        assign_budget: f64,
    },
    /// Always `footprint_px` (tests, and users who want one grid).
    Fixed,
}

impl Default for GridMode {
    fn default() -> Self {
        GridMode::Auto {
            assign_budget: DEFAULT_ASSIGN_BUDGET,
        }
    }
}

/// How the assignment bounds the cells a light's sphere reaches.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Coverage {
    /// Per slice, the sphere's cross-section over the slice's depths, and per row of cells the
    /// columns that cross-section reaches inside the row.
    #[default]
    SliceRows,
    /// One screen rectangle per cascade, every slice and row of it: the looser bound, kept
    /// as a yardstick for the bench and the tests.
    CascadeBox,
}

impl Default for GridConfig {
    fn default() -> Self {
        GridConfig {
            mode: GridMode::default(),
            cascades: 12,
            footprint_px: 64.0,
            slice_depth: 1.0,
            first_split: None,
            max_slices: 32,
            max_tiles: 256,
            measure: GridMeasure::default(),
        }
    }
}

impl GridConfig {
    /// The automatic mode's CPU budget ([`GridMode::Auto`]); the default one for a fixed grid,
    /// which has none.
    pub fn assign_budget(&self) -> f64 {
        match self.mode {
            GridMode::Auto { assign_budget } => assign_budget,
            GridMode::Fixed => DEFAULT_ASSIGN_BUDGET,
        }
    }

    /// Whether the clustered method picks the footprint itself.
    pub fn is_auto(&self) -> bool {
        matches!(self.mode, GridMode::Auto { .. })
    }

    /// A fixed grid of `footprint_px` with the other settings at their defaults.
    pub fn fixed(footprint_px: f64) -> Self {
        GridConfig {
            mode: GridMode::Fixed,
            footprint_px,
            ..GridConfig::default()
        }
    }

    /// A 2D tiling for tiled forward: one cascade, one slice, square tiles of `tile_px`.
    pub fn tiles(tile_px: f64) -> Self {
        GridConfig {
            mode: GridMode::Fixed,
            cascades: 1,
            footprint_px: tile_px,
            slice_depth: 1.0,
            first_split: None,
            max_slices: 1,
            max_tiles: 1024,
            measure: GridMeasure::default(),
        }
    }
}
