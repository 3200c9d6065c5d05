//! Pure math, no Vulkan and no scene types: edge adjacency, procedural shapes, bounds, projections, convex clipping, light-frustum fitting, light
//! sampling, shadow volumes, and the classic systems' blobs, concentric planes and caster views.

pub mod adjacency;
mod bounds;
pub mod chains;
pub mod classic;
mod clip;
mod light_frustum;
mod light_samples;
pub mod plateau;
mod projection;
pub mod shadow_volume;
pub mod shapes;
pub mod silhouette;
pub mod smoothie;

pub use adjacency::{Edge, EdgeAdjacency, NO_FACE};
pub use bounds::{Aabb, any_two_meet};
pub use clip::{Hexahedron, intersection_points};
pub use light_frustum::{LightFrustum, SpotFit, fit_spot_frustum, nearer_light};
pub use light_samples::{Cap, LightPoint, light_points, point_like, visible_cap};
pub use projection::{CameraProjection, Projection};
