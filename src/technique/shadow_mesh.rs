//! The optional simplified shadow mesh per caster, the DDJ's "separate shadowing and drawing
//! models": the silhouette techniques find silhouettes on a simpler copy of each caster
//! ([`Mesh::shadow_mesh`]) while the camera still draws the full one. The error bound is in
//! texels of the light's view, so a technique sets it where a texel is what it can show.

use std::sync::Arc;

use glam::Vec3;

use super::knobs::{Knob, Params};
use crate::scene::{Mesh, Object};

/// Declared by each technique that casts from [`shadow_caster`].
pub const SHADOW_MESH_ERROR: Knob = Knob {
    name: "shadow_mesh_error",
    default: 0.0,
    min: 0.0,
    max: 64.0,
    integer: false,
    help: "silhouettes from a simplified caster straying at most this many texels of a 1024² light view fitted to it; 0: the full mesh",
};

/// [`SHADOW_MESH_ERROR`] for the silhouette techniques' soft shadows (plateau, smoothie): on by
/// default at one texel, which their penumbrae, many texels wide, cannot show. Fine meshes'
/// silhouettes zigzag at the scale of their triangles, and every turn costs cones, sheets and
/// smoothie corners (issue 18). Measured (bench, 512², lavapipe, one run, the full mesh → this):
/// the suite's penumbra RMSE unchanged to four places for both; on the scale scenes the plateau
/// frame 155 → 40 ms (hammer: 60k triangles, 1 250 in its shadow mesh), 117 → 62 (knot), 160 → 75
/// (koala: 100k, 7 952), the smoothie's 162 → 41, 131 → 83, 218 → 146 (its buffer 115 → 8, 70 →
/// 16, 132 → 40); penumbra RMSE within 0.002 for the plateau, 0.003–0.007 higher for the
/// smoothie (hammer 0.069 → 0.072, knot 0.061 → 0.068), whose shadow map keeps the full mesh.
/// `shadow_mesh_error=0` casts from the full mesh.
pub const SOFT_SHADOW_MESH_ERROR: Knob = Knob { default: 1.0, ..SHADOW_MESH_ERROR };

/// Texels across the light's view of one caster that [`SHADOW_MESH_ERROR`] counts in.
pub const LIGHT_VIEW_TEXELS: f32 = 1024.0;

/// The world distance at `o` that subtends `texels` texels of a [`LIGHT_VIEW_TEXELS`]² view
/// from `light` fitted to the caster's bounding sphere, at the sphere's point nearest the light
/// (where a texel is smallest, so the bound holds for the whole caster); `None` for a light
/// inside the sphere.
pub fn texels_at_caster(o: &Object, light: Vec3, texels: f32) -> Option<f32> {
    let b = o.bounds();
    let (centre, radius) = ((b.min + b.max) * 0.5, (b.max - b.min).length() * 0.5);
    let distance = (centre - light).length();
    (distance > radius).then(|| {
        let texel_angle = 2.0 * (radius / distance).asin() / LIGHT_VIEW_TEXELS;
        texels * texel_angle * (distance - radius)
    })
}

/// The mesh `o` casts from: with [`SHADOW_MESH_ERROR`] set, the simplified one within that
/// many texels (converted through the largest scale to the mesh's own units); otherwise its
/// own.
pub fn shadow_mesh(o: &Object, light: Vec3, params: &Params) -> Arc<Mesh> {
    let texels = params.get(&SHADOW_MESH_ERROR) as f32;
    match if texels > 0.0 { texels_at_caster(o, light, texels) } else { None } {
        Some(world) => o.mesh.shadow_mesh(world / o.transform.scale.abs().max_element()),
        None => o.mesh.clone(),
    }
}

/// `o` as its shadow is cast: a copy whose mesh is [`shadow_mesh`]'s.
pub fn shadow_caster(o: &Object, light: Vec3, params: &Params) -> Object {
    Object { mesh: shadow_mesh(o, light, params), ..o.clone() }
}
