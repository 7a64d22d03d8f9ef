//! Pictures of the built-in scenes: each method against forward and the CPU oracle as lights
//! move, framebuffers (the renderer's and a game's), viewports, MSAA, tone maps, sRGB, suns,
//! the method table and the overflow policy. One test program of one module per
//! file, so that its tests share their contexts and the shaders built on them: a software
//! implementation compiles each shader anew in every process (docs/testing.md).

#[path = "../common/mod.rs"]
mod common;

mod animation;
mod background_alpha;
mod culled_vs_forward;
mod depth_bias;
mod directional_lights;
mod empty_scene;
mod front_faces;
mod game_draw_buffers;
mod game_framebuffer_checks;
mod grid_outgrown;
mod hdr_read_back;
mod invalid_options;
mod keep_framebuffer;
mod light_evals;
mod long_loops;
mod method_table;
mod msaa;
mod msaa_destinations;
mod overflow_warning;
mod picture_numerics;
mod plane_oracle;
mod single_sided;
mod srgb_framebuffer;
mod still_frames;
mod still_records;
mod tone_map;
mod unused_programs;
mod viewport_origin;
mod warm_up;
