//! Scenes from model files: glTF and OBJ geometry, materials, textures, samplers, lights and
//! cameras, rendered against oracles. One test program of one module per file, so that its
//! tests share their contexts and the shaders built on them: a software implementation
//! compiles each shader anew in every process (docs/testing.md).

#[path = "../common/mod.rs"]
mod common;

mod gltf_alpha_mask;
mod gltf_from_memory;
mod gltf_geometry;
mod gltf_lights_and_cameras;
mod gltf_malformed_files;
mod gltf_manners;
mod gltf_materials_and_renders;
mod gltf_samplers;
mod metallic_roughness;
mod npot_textures;
mod obj_map_options;
mod texcoord_range;
mod texel_quads;
