//! SPIR-V compiled from `glsl/` by build.rs, one `&[u32]` per shader.
include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
