//! GL-free CPU light assignment: the cascaded cluster grid (`grid`) and its hot-path lookups
//! (`depth_lookup`), 2D screen tiles (`tiles`), which cells one light touches (`cells`, with spot lights'
//! cones in `cone`),
//! per-frame light → cell assignment with a counting sort (`assign`), and the texel layouts
//! the shaders read (`pack`). Nothing here touches GL, so all of it is unit-tested without a
//! context.

pub mod assign;
mod assign_bands;
mod assign_chunks;
pub mod auto;
mod auto_costs;
mod auto_search;
pub mod cells;
mod cone;
mod depth_lookup;
pub mod grid;
pub mod index_list;
mod overflow;
pub mod pack;
pub mod pack_grid;
pub mod tiles;

#[cfg(test)]
mod assign_paths_tests;
#[cfg(test)]
mod assign_tests;
