//! Pure math, no Vulkan: bounds, projections, convex clipping and light-frustum fitting.

mod bounds;
mod clip;
mod light_frustum;
mod projection;

pub use bounds::Aabb;
pub use clip::{Hexahedron, intersection_points};
pub use light_frustum::{LightFrustum, fit_spot_frustum};
pub use projection::{CameraProjection, Projection};
