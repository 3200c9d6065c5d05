//! `shadow-volume`: exact hard shadows by stencil counting (z-pass and z-fail), against the
//! shadow map and the ray tracer, at the extremes the papers warn of, and soft by accumulation.

mod common;

use common::{engine, finish, render_with, scene, suite_scene, top_down};
use glam::Vec3;
use softshadow::Capture;
use softshadow::geometry::shadow_volume::segment_meets_box;
use softshadow::geometry::{Aabb, CameraProjection};
use softshadow::measure::Metrics;

/// Pixels where `a` and `b` disagree on shadowed (V < ½) farther than one pixel from a shadow
/// edge of either, as "x,y a/b".
pub fn off_edge_mismatches(a: &Capture, b: &Capture) -> Vec<String> {
    let dark = |c: &Capture, x: i64, y: i64| {
        let (x, y) = (x.clamp(0, c.width as i64 - 1) as u32, y.clamp(0, c.height as i64 - 1) as u32);
        c.visibility_at(x, y) < 0.5
    };
    let edge = |c: &Capture, x: i64, y: i64| {
        let here = dark(c, x, y);
        (-1..=1).any(|dy| (-1..=1).any(|dx| dark(c, x + dx, y + dy) != here))
    };
    let mut out = Vec::new();
    for y in 0..b.height as i64 {
        for x in 0..b.width as i64 {
            if dark(a, x, y) != dark(b, x, y) && !edge(a, x, y) && !edge(b, x, y) {
                let (u, v) = (x as u32, y as u32);
                out.push(format!("{x},{y} {:.2}/{:.2}", a.visibility_at(u, v), b.visibility_at(u, v)));
            }
        }
    }
    out
}

fn assert_same_hard_shadow(a: &Capture, b: &Capture, what: &str) {
    let bad = off_edge_mismatches(a, b);
    assert!(bad.is_empty(), "{what}: {} px differ off the edges, first {:?}", bad.len(), &bad[..bad.len().min(6)]);
}

fn dark_pixels(c: &Capture) -> usize {
    c.visibility.iter().filter(|&&v| v < 32768).count()
}

const ZPASS: &[(&str, &str)] = &[("counting", "1")];
const ZFAIL: &[(&str, &str)] = &[("counting", "2")];

/// A perspective camera under a wide roof, the light above it: the eye is inside the roof's
/// volume.
fn camera_under_a_roof() -> softshadow::scene::Scene {
    scene(
        "[camera]\nposition = [0.0, 1.0, 0.0]\ntarget = [4.0, 0.0, 0.0]\nfov_y_deg = 60.0\n\
         [light]\nposition = [0.0, 8.0, 0.0]\nradius = 0.0\n[ground]\nheight = 0.0\nhalf_size = 10.0\n\
         [[object]]\nshape = \"plate\"\nsize = [4.0, 0.0, 4.0]\nposition = [0.0, 2.0, 0.0]\n",
    )
}

/// The bottomless cube (models/cube_no_bottom.obj) lit from above and from under its open
/// side, and a cube with a fin on one edge (three faces there), seen from above; the fin's OBJ
/// is written into `dir`.
fn open_and_non_manifold(dir: &std::path::Path) -> Vec<(String, softshadow::scene::Scene)> {
    let fin = dir.join("fin.obj");
    std::fs::write(
        &fin,
        "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\nv -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\n\
         v 0.5 0.5 0.5\nv -0.5 0.5 0.5\nv -0.5 1.0 0.5\nv 0.5 1.0 0.5\n\
         f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\nf 4 8 7\nf 4 7 3\nf 1 2 6\nf 1 6 5\n\
         f 8 7 10\nf 8 10 9\n",
    )
    .unwrap();
    let models = concat!(env!("CARGO_MANIFEST_DIR"), "/models/cube_no_bottom.obj");
    [(models, [2.0, 5.0, 1.0]), (models, [0.6, 0.3, 0.2]), (fin.to_str().unwrap(), [1.5, 4.0, -2.5])]
        .into_iter()
        .map(|(mesh, light)| {
            let object = format!("[[object]]\nshape = \"mesh\"\nmesh = \"{mesh}\"\nposition = [0.0, 1.2, 0.0]\n");
            (format!("{mesh} {light:?}"), top_down(0.0, 3.0, light, 0.0, &object))
        })
        .collect()
}

fn scratch(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("softshadow-volumes-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Under a point light both counting rules give the shadow map's hard shadow (and the ray
/// tracer's) except in a one-pixel band at the edges, on suite scenes with meshes, plates and
/// spheres.
#[test]
fn a_point_light_gives_the_shadow_maps_hard_shadow_but_at_the_edges() {
    let mut e = engine();
    for name in ["default", "two_boxes", "torus"] {
        let mut s = suite_scene(name);
        s.light.radius = 0.0;
        let map = render_with(&mut e, &s, "shadow-map", &[], 128);
        let ray = render_with(&mut e, &s, "raytrace", &[], 128);
        assert!(dark_pixels(&ray) > 200, "{name}: a shadow to compare");
        for sets in [&[][..], ZPASS, ZFAIL] {
            let v = render_with(&mut e, &s, "shadow-volume", sets, 128);
            assert_same_hard_shadow(&v, &map, &format!("{name} {sets:?} vs shadow-map"));
            assert_same_hard_shadow(&v, &ray, &format!("{name} {sets:?} vs raytrace"));
        }
    }
    finish(e);
}

/// A light grazing a 1 m box at 1°: the map's biases (slope-scaled, normal offset, huge at
/// grazing angles) move its shadow edges off the truth, peter-panning at the box's foot; the
/// volumes have no bias and match the ray tracer to the pixel (measured: RMSE 0.015 for the
/// 2048² map, 0.000 for the volumes).
#[test]
fn a_grazing_light_shows_no_acne_or_peter_panning() {
    let r = 1f32.to_radians();
    let box_ = "[[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [0.0, 0.5, 0.0]\nrotation_deg = [0.0, 20.0, 0.0]\n";
    let s = top_down(-2.0, 3.0, [8.0 * r.cos(), 0.05 + 8.0 * r.sin(), 0.0], 0.0, box_);
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 64);
    let map = render_with(&mut e, &s, "shadow-map", &[], 64);
    let vol = render_with(&mut e, &s, "shadow-volume", &[], 64);
    assert_same_hard_shadow(&vol, &ray, "volumes");
    let (m_map, m_vol) = (Metrics::between(&map, &ray).unwrap(), Metrics::between(&vol, &ray).unwrap());
    assert!(m_vol.rmse < 0.002 && m_map.rmse > 0.008, "volumes {m_vol:?} vs map {m_map:?}");
    finish(e);
}

/// A camera inside a shadow volume ([`camera_under_a_roof`]): z-pass starts counting at 0
/// instead of 1 and inverts the shadow; z-fail, and the engine's automatic choice, do not.
#[test]
fn a_camera_inside_a_shadow_volume_breaks_z_pass_not_z_fail() {
    let s = camera_under_a_roof();
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 64);
    assert!(dark_pixels(&ray) > 100 && dark_pixels(&ray) < 64 * 64 - 100, "shadow and light in view");
    let zfail = render_with(&mut e, &s, "shadow-volume", ZFAIL, 64);
    let auto = render_with(&mut e, &s, "shadow-volume", &[], 64);
    let zpass = render_with(&mut e, &s, "shadow-volume", ZPASS, 64);
    assert_same_hard_shadow(&zfail, &ray, "z-fail");
    assert_same_hard_shadow(&auto, &ray, "the automatic choice");
    let wrong = off_edge_mismatches(&zpass, &ray).len();
    assert!(wrong > 1000, "z-pass from inside a volume should be wrong almost everywhere: {wrong} px");
    finish(e);
}

/// The near plane (fitted just before the nearest surface, 5 m out) cuts the volume a box
/// throws towards the camera while the eye stays outside it: depth clamping keeps the volume
/// whole, so z-pass is right too.
#[test]
fn a_near_plane_cutting_a_volume_breaks_neither_rule() {
    let text = "[camera]\nposition = [8.0, 1.6, 0.0]\ntarget = [3.0, 0.4, 0.0]\nfov_y_deg = 45.0\n\
         [light]\nposition = [-10.0, 1.0, 0.0]\nradius = 0.0\n\
         [[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [0.0, 0.5, 0.0]\nreceives = false\n\
         [[object]]\nshape = \"box\"\nsize = [0.1, 0.8, 1.6]\nposition = [3.0, 0.4, 0.0]\ncasts = false\n\
         [[object]]\nshape = \"box\"\nsize = [0.1, 0.8, 0.6]\nposition = [3.0, 1.6, 0.0]\ncasts = false\n";
    let s = scene(text);
    // The near plane's centre lies in the box's shadow; the eye does not.
    let bounds = s.objects.iter().fold(Aabb::EMPTY, |b, o| b.union(&o.mesh.bounds.transformed(&o.transform.matrix())));
    let c = &s.camera;
    let cam = CameraProjection::new(c.position, c.target, c.up, c.projection, 1.0, &bounds).unwrap();
    let near_centre = cam.frustum.corners[..4].iter().copied().sum::<Vec3>() / 4.0;
    let caster = Aabb { min: Vec3::new(-0.5, 0.0, -0.5), max: Vec3::new(0.5, 1.0, 0.5) };
    assert!(segment_meets_box(s.light.position, near_centre, &caster), "near plane at {near_centre}");
    assert!(!segment_meets_box(s.light.position, c.position, &caster));
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 64);
    assert!(dark_pixels(&ray) > 100, "the shadowed wall is in view");
    for sets in [ZPASS, ZFAIL] {
        let v = render_with(&mut e, &s, "shadow-volume", sets, 64);
        assert_same_hard_shadow(&v, &ray, &format!("{sets:?}"));
    }
    finish(e);
}

/// 256 thin boxes stacked over one spot, seen from above.
fn stacked_boxes() -> softshadow::scene::Scene {
    let boxes: String = (0..256)
        .map(|k| {
            format!(
                "[[object]]\nshape = \"box\"\nsize = [1.0, 0.004, 1.0]\nposition = [0.0, {}, 0.0]\n",
                0.5 + 0.01 * k as f32
            )
        })
        .collect();
    top_down(0.0, 2.0, [0.0, 8.0, 0.0], 0.0, &boxes)
}

/// [`stacked_boxes`]: 256 volumes hold the ground under them, a count of 0 in 8 bits. Groups
/// of at most 127 keep it whole.
#[test]
fn counts_beyond_the_stencils_bits_stay_shadowed() {
    let s = stacked_boxes();
    let mut e = engine();
    for sets in [ZPASS, ZFAIL] {
        let v = render_with(&mut e, &s, "shadow-volume", sets, 64);
        // Beside the stack: the ground at (1.5, 0, 0) is lit; the top box sees the light.
        assert!(v.visibility_at(56, 32) > 0.99, "{sets:?}: beside the stack");
        assert!(v.visibility_at(32, 32) > 0.99, "{sets:?}: the top box");
    }
    // The ground under the stack, seen past the boxes from a low camera.
    let mut low = s.clone();
    low.camera.position = Vec3::new(0.0, 0.2, 4.0);
    low.camera.target = Vec3::new(0.0, 0.0, 0.0);
    low.camera.up = Vec3::Y;
    low.camera.projection = softshadow::geometry::Projection::Perspective { fov_y_deg: 40.0 };
    let ray = render_with(&mut e, &low, "raytrace", &[], 64);
    for sets in [ZPASS, ZFAIL] {
        let v = render_with(&mut e, &low, "shadow-volume", sets, 64);
        assert_same_hard_shadow(&v, &ray, &format!("{sets:?} from low"));
    }
    finish(e);
}

/// A post whose top is 4 m above the light: the volume of the part above the light points up
/// and away, never onto the ground; the ray tracer agrees everywhere but at the edges.
#[test]
fn a_caster_reaching_above_the_light() {
    let post = "[[object]]\nshape = \"box\"\nsize = [0.3, 6.0, 0.3]\nposition = [0.0, 3.0, 0.0]\n";
    let s = top_down(0.0, 4.0, [2.0, 2.0, 0.0], 0.0, post);
    let mut e = engine();
    let ray = render_with(&mut e, &s, "raytrace", &[], 64);
    for sets in [&[][..], ZPASS, ZFAIL] {
        assert_same_hard_shadow(&render_with(&mut e, &s, "shadow-volume", sets, 64), &ray, &format!("{sets:?}"));
    }
    finish(e);
}

/// The same hard shadow at a millimetre and at ten kilometres: nothing depends on the scale.
#[test]
fn scene_scales_from_a_millimetre_to_ten_kilometres() {
    let mut e = engine();
    let one = render_with(&mut e, &common::wall(1.0, 0.0), "shadow-volume", &[], 64);
    assert!(dark_pixels(&one) > 300);
    for scale in [1e-3, 1e4] {
        let s = common::wall(scale, 0.0);
        for sets in [ZPASS, ZFAIL] {
            let v = render_with(&mut e, &s, "shadow-volume", sets, 64);
            assert_same_hard_shadow(&v, &one, &format!("scale {scale} {sets:?}"));
        }
    }
    finish(e);
}

/// [`open_and_non_manifold`] meshes: boundary and non-manifold edges, every triangle
/// blocking from its lit side. With the light below the open side, only the inside faces block.
#[test]
fn open_and_non_manifold_meshes() {
    let dir = scratch("open");
    let mut e = engine();
    for (what, s) in open_and_non_manifold(&dir) {
        let adjacency = &s.objects[0].mesh.adjacency;
        assert!(adjacency.boundary + adjacency.non_manifold > 0, "{what} is open or non-manifold");
        let ray = render_with(&mut e, &s, "raytrace", &[], 64);
        assert!(dark_pixels(&ray) > 50, "{what}: a shadow");
        for sets in [ZPASS, ZFAIL] {
            let v = render_with(&mut e, &s, "shadow-volume", sets, 64);
            assert_same_hard_shadow(&v, &ray, &format!("{what} {sets:?}"));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    finish(e);
}

/// The volumes built by the compute pass (`gpu_silhouettes = 1`) count as the CPU's do: V the
/// same to 1/255 everywhere, on the scenes above (suite meshes, open and non-manifold meshes,
/// the eye in a volume, counts beyond the stencil's bits in groups), both counting rules, and
/// accumulated from 16 points.
#[test]
fn volumes_built_on_the_gpu_count_as_the_cpus() {
    let dir = scratch("gpu");
    let mut scenes = open_and_non_manifold(&dir);
    for name in ["default", "two_boxes", "torus"] {
        let mut s = suite_scene(name);
        s.light.radius = 0.0;
        scenes.push((name.to_string(), s));
    }
    scenes.push(("the eye in a volume".to_string(), camera_under_a_roof()));
    scenes.push(("256 stacked boxes".to_string(), stacked_boxes()));
    let soft = [("samples", "16")];
    let mut e = engine();
    for (what, s) in &scenes {
        for sets in [ZPASS, ZFAIL, &soft[..]] {
            let cpu = render_with(&mut e, s, "shadow-volume", sets, 64);
            let gpu_sets: Vec<_> = sets.iter().copied().chain([("gpu_silhouettes", "1")]).collect();
            let gpu = render_with(&mut e, s, "shadow-volume", &gpu_sets, 64);
            let worst = cpu.visibility.iter().zip(&gpu.visibility).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
            assert!(worst <= 65535 / 255, "{what} {sets:?}: V differs by {:.4}", worst as f64 / 65535.0);
            assert!(dark_pixels(&cpu) > 0, "{what}: a shadow to compare");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    finish(e);
}

/// Soft by accumulation: N hard shadows from the reference's points, weighted by solid angle,
/// converge to the truth (the CPU ray tracer) as the reference does. Measured RMSE on the wall
/// with a light as wide as it (radius 1 m): 0.185, 0.043, 0.014 at N = 1, 16, 64, both
/// techniques alike; the reference itself at N = 256: 0.0053.
#[test]
fn accumulation_converges_to_the_truth() {
    let mut e = engine();
    let s = common::wall(1.0, 1.0);
    let truth = render_with(&mut e, &s, "raytrace", &[], 64);
    for technique in ["shadow-volume", "planar"] {
        let rmse: Vec<f64> = ["1", "16", "64"]
            .iter()
            .map(|n| Metrics::between(&render_with(&mut e, &s, technique, &[("samples", n)], 64), &truth).unwrap().rmse)
            .collect();
        assert!(rmse[2] < rmse[1] && rmse[1] < rmse[0], "{technique}: {rmse:?}");
        assert!(rmse[0] > 0.15 && rmse[1] < 0.05 && rmse[2] < 0.017, "{technique}: {rmse:?}");
    }
    finish(e);
}

/// The timings name the papers' passes: the GPU path times its `silhouettes` compute pass
/// apart from the stencil fill (`volumes`, `caps`), the CPU path reports its silhouette work as
/// a CPU span of that name, taken out of the `technique` span, not added to it.
#[test]
fn silhouettes_are_timed_apart_from_the_fill() {
    let mut s = suite_scene("two_boxes");
    s.light.radius = 0.0;
    let mut e = engine();
    for (gpu, counting) in [("0", "2"), ("1", "2"), ("1", "1")] {
        let sets = [("gpu_silhouettes", gpu), ("counting", counting)];
        for _ in 0..2 {
            // The light moves: the compute path builds its volumes again every frame.
            s.light.position.x += 0.01;
            render_with(&mut e, &s, "shadow-volume", &sets, 64);
        }
        e.flush().unwrap();
        let t = e.take_timings().pop().unwrap();
        let passes: Vec<_> = t.passes.iter().map(|p| p.name).collect();
        let mut expected = vec!["prepass", "volumes", "caps", "accumulate", "resolve", "composite"];
        if counting == "1" {
            expected.retain(|p| *p != "caps");
        }
        if gpu == "1" {
            expected.insert(1, "silhouettes");
        }
        assert_eq!(passes, expected, "{sets:?}");
        assert!(t.passes.iter().all(|p| p.ms > 0.0 && p.ms.is_finite()), "{t:?}");
        let cpu: Vec<_> = t.cpu.iter().map(|c| c.name).collect();
        let at = cpu.iter().position(|n| *n == "technique").expect("a technique span");
        assert_eq!(cpu[at - 1] == "silhouettes", gpu == "0", "{sets:?}: {cpu:?}");
        assert_eq!(cpu.iter().filter(|n| **n == "silhouettes").count(), (gpu == "0") as usize, "{cpu:?}");
        assert!(t.cpu.iter().all(|c| c.ms >= 0.0), "{t:?}");
    }
    finish(e);
}

/// A 20k-triangle knot over the ground, seen from above, under a point light; `receives` says
/// whether the knot takes shadows itself.
fn knot(receives: bool) -> softshadow::scene::Scene {
    let knot = format!(
        "[[object]]\nshape = \"knot\"\ntriangles = 20000\nposition = [0.0, 1.2, 0.0]\nscale = 0.8\nreceives = {receives}\n"
    );
    top_down(0.0, 2.0, KNOT_LIGHT, 0.0, &knot)
}

const KNOT_LIGHT: [f32; 3] = [1.0, 8.0, 0.5];

/// `shadow_mesh_error` (issue 18): a caster that receives no shadow casts its volumes from the
/// simplified mesh. Its hard shadow on the ground strays from the full mesh's by no more than
/// the stated texels of the light's view, carried down to the ground; the volumes stay closed
/// (sides, caps and nesting bound from the one simplified mesh), so z-pass and z-fail count
/// alike off the edges and the GPU path as the CPU's; a caster that receives keeps its own mesh
/// (a simplified light cap would stand over its lit side), so its image does not change.
#[test]
fn a_simplified_shadow_mesh_keeps_the_volumes_closed_and_within_its_error() {
    use softshadow::technique::shadow_mesh::texels_at_caster;
    let size = 256;
    let s = knot(false);
    let mut e = engine();
    let full = render_with(&mut e, &s, "shadow-volume", ZPASS, size);
    let full_dark = |x: i64, y: i64| {
        let (x, y) = (x.clamp(0, size as i64 - 1) as u32, y.clamp(0, size as i64 - 1) as u32);
        full.visibility_at(x, y) < 0.5
    };
    // World metres per screen pixel (an orthographic half height of 2 m), and how much farther
    // from the light the ground is than the caster's nearest point, with a margin for the
    // light's slant.
    let pixel = 4.0 / size as f32;
    let o = &s.objects[0];
    let light = Vec3::from(KNOT_LIGHT);
    let b = o.bounds();
    let nearest = ((b.min + b.max) * 0.5 - light).length() - (b.max - b.min).length() * 0.5;
    let to_ground = 1.25 * light.y / nearest;
    // Larger errors open this knot, and the full mesh casts (Mesh::shadow_mesh).
    for texels in [1.0f32, 4.0] {
        let band = (texels_at_caster(o, light, texels).unwrap() * to_ground / pixel).ceil() as i64 + 1;
        let knob = texels.to_string();
        let zpass = render_with(&mut e, &s, "shadow-volume", &[ZPASS[0], ("shadow_mesh_error", &knob)], size);
        let mut strays = 0;
        for y in 0..size as i64 {
            for x in 0..size as i64 {
                let here = full_dark(x, y);
                if (zpass.visibility_at(x as u32, y as u32) < 0.5) == here {
                    continue;
                }
                strays += 1;
                let near_outline = (-band..=band).any(|dy| (-band..=band).any(|dx| full_dark(x + dx, y + dy) != here));
                assert!(near_outline, "{texels} texels: {x},{y} strays beyond {band} px of the full outline");
            }
        }
        assert!(texels < 4.0 || strays > 0, "the simplified mesh casts: its outline differs somewhere");
        let zfail = render_with(&mut e, &s, "shadow-volume", &[ZFAIL[0], ("shadow_mesh_error", &knob)], size);
        assert_same_hard_shadow(&zfail, &zpass, &format!("{texels} texels, z-fail vs z-pass"));
        for counting in [ZPASS[0], ZFAIL[0]] {
            let cpu = if counting == ZPASS[0] { &zpass } else { &zfail };
            let sets = [counting, ("shadow_mesh_error", &knob), ("gpu_silhouettes", "1")];
            let gpu = render_with(&mut e, &s, "shadow-volume", &sets, size);
            let worst = cpu.visibility.iter().zip(&gpu.visibility).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
            assert!(worst <= 65535 / 255, "{texels} texels {counting:?}: GPU differs by {worst}");
        }
    }
    let receiving = knot(true);
    let own = render_with(&mut e, &receiving, "shadow-volume", &[], size);
    let kept = render_with(&mut e, &receiving, "shadow-volume", &[("shadow_mesh_error", "4")], size);
    assert_eq!(own.visibility, kept.visibility, "a receiving caster casts from its own mesh");
    finish(e);
}

/// The compute path (`gpu_silhouettes = 1`) under one light point keeps its volumes while
/// nothing moves: a static scene records no silhouette pass after its first frame, and draws
/// the same shadow from the kept volumes; a moved caster or light builds them again, and the
/// image follows (as the CPU path's).
#[test]
fn the_compute_path_builds_volumes_only_when_something_moved() {
    let mut s = suite_scene("two_boxes");
    s.light.radius = 0.0;
    let mut e = engine();
    let (frame, first, still, static_frames) = common::static_compute_frames(&mut e, &s, "shadow-volume");
    assert!(static_frames[0].contains(&"silhouettes"), "{static_frames:?}");
    assert!(static_frames[1..].iter().all(|p| !p.contains(&"silhouettes")), "{static_frames:?}");
    assert!(static_frames.iter().all(|p| p.contains(&"volumes")), "{static_frames:?}");
    assert_eq!(still.visibility, first.visibility, "the kept volumes cast the first frame's shadow");
    let caster = s.objects.iter().position(|o| o.casts).unwrap();
    s.objects[caster].transform.position.x += 0.3;
    let moved = e.render_and_capture(&s, &frame).unwrap();
    e.render(&s, &frame).unwrap();
    s.light.position.z += 0.5;
    let lit_anew = e.render_and_capture(&s, &frame).unwrap();
    let moving_frames = common::passes_per_frame(&mut e);
    let built: Vec<bool> = moving_frames.iter().map(|p| p.contains(&"silhouettes")).collect();
    assert_eq!(built, [true, false, true], "{moving_frames:?}");
    let mut cpu_light = s.clone();
    cpu_light.light.position.z -= 0.5;
    for (gpu, scene) in [(&moved, &cpu_light), (&lit_anew, &s)] {
        let cpu = render_with(&mut e, scene, "shadow-volume", &[], 64);
        assert_eq!(gpu.visibility, cpu.visibility, "the rebuilt volumes are the moved scene's");
    }
    assert!(moved.visibility != first.visibility && lit_anew.visibility != moved.visibility);
    finish(e);
}

/// The CPU path writes a frame slot's volume vertices again only when what they hold changed:
/// a light moved from side to side, frame after frame (the boxes' silhouettes change with it),
/// casts each frame the shadow a fresh engine draws for that light.
#[test]
fn kept_volume_vertices_follow_every_move() {
    let mut s = suite_scene("two_boxes");
    s.light.radius = 0.0;
    let rest = s.light.position;
    let lit_from = |side: usize| {
        let mut moved = s.clone();
        moved.light.position = rest + Vec3::X * [-2.0, 2.0][side];
        moved
    };
    let mut fresh = engine();
    let truth: Vec<Capture> =
        (0..2).map(|side| render_with(&mut fresh, &lit_from(side), "shadow-volume", &[], 64)).collect();
    finish(fresh);
    assert!(truth[0].visibility != truth[1].visibility);
    let mut e = engine();
    for (k, side) in [0, 0, 0, 1, 1, 0, 1, 0, 0].into_iter().enumerate() {
        let v = render_with(&mut e, &lit_from(side), "shadow-volume", &[], 64);
        assert!(v.visibility == truth[side].visibility, "frame {k}: not the shadow of that light");
    }
    finish(e);
}
