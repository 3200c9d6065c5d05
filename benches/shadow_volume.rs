//! Per-frame CPU cost of the shadow volumes' CPU path, as a frame whose caster moved rebuilds
//! them: face facing from the mesh's face planes against the light taken into object space,
//! the sides of every edge by its multiplicity, light and dark caps; on the largest suite model
//! (wingnut, 6090 triangles) and at scale (koala, 99 994 triangles, issue 18). No vertex is
//! transformed: the volumes are vertex numbers, drawn from the object-space positions. The GPU
//! path does the same in its `silhouettes` compute pass
//! (`softshadow render --set gpu_silhouettes=on --timings`).

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Mat4, Vec3};
use softshadow::geometry::shadow_volume::{is_open, shadow_volume};
use softshadow::geometry::silhouette::Caster;
use softshadow::scene::Mesh;

fn volumes(c: &mut Criterion) {
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models");
    let wingnut = Mesh::load_obj(&models.join("wingnut.obj")).unwrap();
    let koala = Mesh::load_obj(&models.join("koala.obj")).unwrap();
    // As scenes/scale/koala.toml places it: standing, 1.4 m tall, over the ground.
    let koala_model = Mat4::from_translation(Vec3::new(0.0, 0.7, 0.0))
        * Mat4::from_rotation_x(-std::f32::consts::FRAC_PI_2)
        * Mat4::from_scale(Vec3::splat(0.15));
    for (name, mesh, model, light) in [
        ("wingnut", &wingnut, Mat4::from_translation(Vec3::Y), Vec3::new(3.0, 9.0, 2.5)),
        ("koala", &koala, koala_model, Vec3::new(2.0, 7.0, 1.5)),
    ] {
        let caster = Caster { positions: &mesh.positions, triangles: &mesh.triangles, adjacency: &mesh.adjacency };
        let two_sided = is_open(&caster);
        let mut step = 0.0f32;
        c.bench_function(&format!("shadow volume, moving frame (facing, sides, caps), {name}"), |b| {
            b.iter(|| {
                step = (step + 1e-3) % 0.05; // moving, but staying where it was placed
                let model = Mat4::from_translation(Vec3::X * step) * model;
                shadow_volume(&caster, &mesh.planes.light_facing(&model, light), two_sided)
            })
        });
    }
}

criterion_group!(benches, volumes);
criterion_main!(benches);
