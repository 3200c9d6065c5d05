//! The library's error type: every failure names what is wrong, never a panic.

use std::path::PathBuf;

use ash::vk;

/// Result with the crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Everything that can go wrong, each variant saying what and where.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene file (or a mesh it names) is malformed; `what` names the key or line.
    #[error("{}: {what}", path.display())]
    Scene { path: PathBuf, what: String },
    /// A parameter given by the caller is out of range or unknown.
    #[error("{0}")]
    Invalid(String),
    /// No Vulkan loader, driver or suitable device.
    #[error("{0}")]
    NoDevice(String),
    /// No display to open a window on, or the window system refused one.
    #[error("{0}")]
    Window(String),
    /// A Vulkan call failed.
    #[error("Vulkan call {call} failed: {result}")]
    Vulkan { call: &'static str, result: vk::Result },
    /// GPU memory could not be allocated.
    #[error("GPU memory allocation failed: {0}")]
    Memory(#[from] gpu_allocator::AllocationError),
    /// A file could not be read or written. (The cause is part of the message, not a
    /// `source`, so that a report of the whole chain does not print it twice.)
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    /// An image could not be encoded.
    #[error("{}: {error}", path.display())]
    Image { path: PathBuf, error: image::ImageError },
}

impl Error {
    pub(crate) fn scene(path: impl Into<PathBuf>, what: impl Into<String>) -> Self {
        Error::Scene { path: path.into(), what: what.into() }
    }
}

/// Attaches the name of the failing Vulkan call to a `vk::Result`.
pub(crate) trait VkContext<T> {
    fn vk(self, call: &'static str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> Result<T> {
        self.map_err(|result| Error::Vulkan { call, result })
    }
}
