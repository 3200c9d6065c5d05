//! CPU cost of loading-time mesh work on the largest shipped model: edge adjacency (built once
//! per mesh) and render geometry (crease-split normals).

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use softshadow::scene::{EdgeAdjacency, Mesh};

fn mesh(c: &mut Criterion) {
    let wingnut = Mesh::load_obj(&Path::new(env!("CARGO_MANIFEST_DIR")).join("models/wingnut.obj")).unwrap();
    c.bench_function("edge adjacency, wingnut (6090 triangles)", |b| {
        b.iter(|| EdgeAdjacency::build(black_box(&wingnut.triangles)))
    });
    c.bench_function("render geometry, wingnut", |b| b.iter(|| black_box(&wingnut).render_geometry()));
}

criterion_group!(benches, mesh);
criterion_main!(benches);
