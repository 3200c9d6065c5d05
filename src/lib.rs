//! softshadow: real-time fake soft shadows with raw Vulkan.
//!
//! The frame (DESIGN.md §1): a camera prepass (depth + normal), a technique's passes ending in
//! the visibility image V (1 = light fully visible), and a composite (ambient + V·Lambert). Every
//! technique writes the same V for the same pixels, so they are interchangeable and comparable.
//!
//! ```no_run
//! use softshadow::{Engine, FrameSettings, gpu::ContextOptions, scene::Scene};
//! let mut scene = Scene::load("scenes/default.toml")?;
//! let settings = FrameSettings::from_scene(&scene)?;
//! let mut engine = Engine::headless(&ContextOptions::from_env())?;
//! for frame in 0..100 {
//!     scene.objects[0].transform.position.x = (frame as f32 * 0.05).sin();
//!     engine.render(&scene, &settings)?;
//! }
//! let capture = engine.render_and_capture(&scene, &settings)?;
//! capture.save_color("out/color.png".as_ref())?;
//! # Ok::<(), softshadow::Error>(())
//! ```

pub mod error;
pub mod ffi;
pub mod frame;
pub mod geometry;
pub mod gpu;
pub mod measure;
pub mod reference;
pub mod renderer;
pub mod scene;
mod shader_constants;
pub mod technique;

pub use error::{Error, Result};
pub use renderer::{
    AppWindow, Capture, CpuSpan, EmbeddedFrame, EmbedderCamera, EmbedderImage, Engine, FrameSettings, FrameTimings,
    Presented, Recorded, WindowOptions, WindowStats,
};

/// The device extensions an embedder enables on the device it creates for the engine
/// ([`Engine::from_handles`]).
pub fn required_device_extensions() -> &'static [&'static std::ffi::CStr] {
    gpu::required_device_extensions()
}

/// The Vulkan 1.0 features an embedder enables on the device it creates for the engine (set them
/// in `VkPhysicalDeviceFeatures`, and hand the same to [`gpu::EmbedderHandles`]).
pub fn required_core_features() -> ash::vk::PhysicalDeviceFeatures {
    gpu::required_core_features()
}

/// The Vulkan 1.3 features an embedder enables on the device it creates for the engine (chain
/// them into `VkDeviceCreateInfo`, and hand the same to [`gpu::EmbedderHandles`]).
pub fn required_device_features() -> ash::vk::PhysicalDeviceVulkan13Features<'static> {
    gpu::required_vulkan13_features()
}
