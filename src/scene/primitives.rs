//! Procedural closed meshes centred on the origin, counter-clockwise seen from outside
//! ([`geometry::shapes`](crate::geometry::shapes) made into [`Mesh`]es).

use glam::Vec3;

use super::mesh::Mesh;
use crate::error::Result;
use crate::geometry::shapes;

/// A box of `size`; a zero `size.y` makes a plate: two back-to-back quads sharing their rim, a
/// closed surface of zero thickness (each rim edge has its two faces).
pub fn cuboid(size: Vec3) -> Result<Mesh> {
    let (p, tris) = shapes::cuboid(size);
    Mesh::new(if size.y == 0.0 { "plate" } else { "box" }, p, tris)
}

/// A UV sphere with welded poles.
pub fn sphere(radius: f32) -> Result<Mesh> {
    let (p, tris) = shapes::sphere(radius);
    Mesh::new("sphere", p, tris)
}

/// A capped cylinder along Y, centred on the origin.
pub fn cylinder(radius: f32, height: f32) -> Result<Mesh> {
    let (p, tris) = shapes::cylinder(radius, height);
    Mesh::new("cylinder", p, tris)
}

/// A trefoil knot tube of about `triangles` triangles in the unit sphere (see
/// [`shapes::torus_knot`]).
pub fn knot(triangles: u32) -> Result<Mesh> {
    let (p, tris) = shapes::torus_knot(triangles);
    Mesh::new("knot", p, tris)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Outward orientation: the signed volume (divergence theorem) is positive.
    fn signed_volume(mesh: &Mesh) -> f32 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn primitives_are_closed_and_outward() {
        for (mesh, volume) in [
            (cuboid(Vec3::new(1.0, 2.0, 3.0)).unwrap(), 6.0),
            (sphere(1.0).unwrap(), 4.0 / 3.0 * std::f32::consts::PI),
            (cylinder(0.5, 2.0).unwrap(), std::f32::consts::PI * 0.25 * 2.0),
            // The tube's volume: its cross-section along the centre line (length 31.9 before
            // the 1/3.4 fit into the unit sphere).
            (knot(20_000).unwrap(), std::f32::consts::PI * 0.16 * 31.9 / 3.4f32.powi(3)),
        ] {
            assert!(mesh.adjacency.is_closed(), "{}", mesh.name);
            let v = signed_volume(&mesh);
            assert!(v > 0.0 && (v - volume).abs() < 0.05 * volume, "{}: volume {v}, want {volume}", mesh.name);
        }
    }

    #[test]
    fn plate_is_a_closed_zero_volume_surface() {
        let plate = cuboid(Vec3::new(2.0, 0.0, 1.0)).unwrap();
        assert!(plate.adjacency.is_closed());
        assert_eq!(plate.adjacency.edges.len(), 6);
        assert!(signed_volume(&plate).abs() < 1e-6);
    }

    #[test]
    fn box_renders_faceted_and_sphere_smooth() {
        let (box_vertices, _) = cuboid(Vec3::ONE).unwrap().render_geometry();
        assert_eq!(box_vertices.len(), 24, "each corner split three ways");
        let sphere = sphere(1.0).unwrap();
        let (sphere_vertices, _) = sphere.render_geometry();
        assert_eq!(sphere_vertices.len(), sphere.positions.len(), "no crease on a sphere");
    }
}
