//! GL-free CPU light assignment: the cascaded cluster grid (`grid`, with its hot-path lookup
//! tables), 2D screen tiles (`tiles`), per-frame light → cell assignment with a
//! counting sort (`assign`: which cells one light touches, spot lights' cones, the index list,
//! the overflow policy), the automatic grid that picks a frame's cell footprint (`auto_grid`),
//! and the texel layouts the shaders read (`pack`). Nothing here touches GL, so all of it is
//! unit-tested without a context.

pub mod assign;
pub mod auto_grid;
pub mod grid;
pub(crate) mod headroom;
pub(crate) mod min_max;
pub mod pack;
pub mod tiles;
pub mod view_light;
