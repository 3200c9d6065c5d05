//! Edge adjacency of the shipped models: closed meshes have no boundary edges; the open cube
//! has the 8 edges around its missing bottom.

use std::path::Path;

use softshadow::scene::{Mesh, NO_FACE};

fn load(name: &str) -> Mesh {
    Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models").join(name)).unwrap()
}

#[test]
fn closed_models_have_no_boundary_edges() {
    for name in
        ["cube.obj", "sphere.obj", "spot_low_resolution.obj", "fish_low_resolution.obj", "torus.obj", "wingnut.obj"]
    {
        let mesh = load(name);
        let adj = &mesh.adjacency;
        assert!(adj.is_closed(), "{name}: {} boundary, {} non-manifold", adj.boundary, adj.non_manifold);
        // A closed triangle mesh has 3F/2 edges.
        assert_eq!(adj.edges.len() * 2, mesh.triangles.len() * 3, "{name}");
    }
}

#[test]
fn the_open_cube_has_eight_boundary_edges() {
    let mesh = load("cube_no_bottom.obj");
    assert_eq!(mesh.adjacency.boundary, 8);
    assert_eq!(mesh.adjacency.non_manifold, 0);
    assert_eq!(mesh.adjacency.edges.iter().filter(|e| e.faces[1] == NO_FACE).count(), 8);
}

#[test]
fn every_edge_lies_in_its_faces_in_their_winding() {
    let mesh = load("torus.obj");
    for e in &mesh.adjacency.edges {
        let t0 = mesh.triangles[e.faces[0] as usize];
        let k = t0.iter().position(|&v| v == e.vertices[0]).expect("edge vertex in its face");
        assert_eq!(t0[(k + 1) % 3], e.vertices[1], "vertices follow face 0's winding");
        let t1 = mesh.triangles[e.faces[1] as usize];
        assert!(t1.contains(&e.vertices[0]) && t1.contains(&e.vertices[1]));
    }
}
