//! The only Vulkan plumbing: context (own or the embedder's handles), memory, targets (own or
//! wrapped), barriers, pipelines, shaders, timestamps, frames, readback and the swapchain. Nothing here knows
//! about shadows.

mod barrier;
mod context;
mod debug;
mod device;
mod frames;
mod guard;
mod memory;
mod pipeline;
pub mod reflect;
mod render;
pub mod shaders;
mod swapchain;
mod target;
mod timestamps;
mod upload;

pub use barrier::{Access, BufferAccess, buffer_barrier, copy_to_host, transition};
pub use context::{Context, ContextOptions, DeviceInfo, EmbedderHandles, Ownership, UploadMark};
pub use device::{
    CreateSurface, DeviceFilter, required_core_features, required_device_extensions, required_vulkan13_features,
};
pub use frames::{FRAMES_IN_FLIGHT, Frame, FrameRing, Semaphores};
pub use guard::{Destroy, Guard};
pub use memory::{Buffer, PerFrame};
pub use pipeline::{Blend, DepthState, Descriptor, Fullscreen, Pipeline, PipelineDesc, Variants, VertexInput};
pub use reflect::Binding;
pub use render::{
    Attachment, DRAW_COMMAND_BYTES, RenderPass, copy_buffer, dispatch, draw_fullscreen, draw_generated, draw_indexed,
    draw_indirect, draw_vertices, fullscreen, update_buffer,
};
pub use swapchain::{Acquired, NativeWindow, PresentMode, Swapchain, SwapchainRequest, is_srgb};
pub use target::{Target, TargetDesc, ensure};
pub use timestamps::{Milestones, PassTime, PassTimer};
pub use upload::{Uploads, copy_to_buffer, copy_to_target, upload, upload_in};
