//! Pure math, no Vulkan: bounds, projections, convex clipping, light-frustum fitting and light
//! sampling.

mod bounds;
mod clip;
mod light_frustum;
mod light_samples;
pub mod plateau;
mod projection;
pub mod silhouette;
pub mod smoothie;

pub use bounds::Aabb;
pub use clip::{Hexahedron, intersection_points};
pub use light_frustum::{LightFrustum, fit_spot_frustum};
pub use light_samples::{Cap, cap_points, visible_cap};
pub use projection::{CameraProjection, Projection};
