//! SPIR-V compiled from `glsl/` by build.rs: one [`Shader`] per file, named after its path.

/// One compiled shader.
#[derive(Debug)]
pub struct Shader {
    /// Where it came from under `glsl/`, for messages.
    pub path: &'static str,
    pub words: &'static [u32],
}

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
