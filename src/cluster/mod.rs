//! GL-free CPU light data: the texel layouts the shaders read (`pack`). The cluster grid and
//! light assignment live here too as they arrive; nothing in this module touches GL, so all of
//! it is unit-tested without a context.

pub mod pack;
