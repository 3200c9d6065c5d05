//! Plateaus on lavapipe: the penumbra widens with height and vanishes at contact, the umbra is
//! dark, the error against the reference stays under measured bounds, and the numerical
//! extremes of Haines' construction (contact, equal and nested radii, low lights, casters above
//! the light, point and huge lights, tiny and huge scenes) give sane images.

mod common;

use common::{
    WALL_SIZE as SIZE, against_reference, engine, finish, render_with, scene, suite_scene, top_down, wall,
    wall_column as column, wall_edge_width as edge_width,
};
use softshadow::Capture;
use softshadow::measure::Metrics;
use softshadow::scene::Scene;

/// The wall's side edge stands at x = 0.05, 2.95 m short of the light's foot along x (the light
/// 0.5 m off the end face's plane, which faces away from it): at x on the ground behind it the
/// physical penumbra is W = 2R·(0.05 − x)/2.95 across (similar triangles along the shadow line),
/// growing from nothing at the wall's foot, and 0.02 < V < 0.98 holds over 0.9 W of the
/// straight-edge profile.
#[test]
fn the_penumbra_widens_with_height_vanishes_at_contact_and_keeps_a_dark_umbra() {
    let mut e = engine();
    let c = render_with(&mut e, &wall(1.0, 0.5), "plateau", &[], SIZE);
    let pixel = 3.0 / SIZE as f32;
    for x in [-0.15, -0.9, -1.8] {
        let (got, want) = (edge_width(&c, column(x)) as f32, 0.9 * 2.0 * 0.5 * (0.05 - x) / 2.95 / pixel);
        assert!((got - want).abs() <= 1.5, "{x} m behind the wall: {got} px of penumbra, physically {want:.1} px");
    }
    // Under the wall's shadow, well inside: the plateau's top, V = 0.
    assert_eq!(c.visibility_at(column(-1.0), SIZE / 2), 0.0);
    // Towards the light: lit.
    assert!(c.visibility_at(column(0.3), SIZE / 2) > 0.99);
    finish(e);
}

#[test]
fn the_picture_does_not_depend_on_the_scene_scale() {
    let mut e = engine();
    let widths: Vec<Vec<usize>> = [1.0, 1e-3, 1e4]
        .iter()
        .map(|&s| {
            let c = render_with(&mut e, &wall(s, 0.25), "plateau", &[], SIZE);
            [-0.15, -0.9, -1.8].iter().map(|&x| edge_width(&c, column(x))).collect()
        })
        .collect();
    for w in &widths[1..] {
        for (a, b) in w.iter().zip(&widths[0]) {
            assert!(a.abs_diff(*b) <= 1, "penumbra widths {widths:?} at scales 1, 1e-3, 1e4");
        }
    }
    finish(e);
}

#[test]
fn a_point_light_gives_the_hard_shadow_and_a_huge_light_stays_sane() {
    let mut e = engine();
    let point = wall(1.0, 0.0);
    let hard = render_with(&mut e, &point, "shadow-map", &[], SIZE);
    let plateau = render_with(&mut e, &point, "plateau", &[], SIZE);
    // No penumbra without a light size: no more in-between pixels than the hard shadow map's
    // own 2x2 bilinear edge.
    let soft = |c: &Capture| c.visibility.iter().filter(|&&v| v > 0 && v < 65535).count();
    assert!(soft(&plateau) <= soft(&hard) + SIZE as usize / 4, "{} vs {}", soft(&plateau), soft(&hard));
    let m = Metrics::between(&plateau, &hard).unwrap();
    // Two rasterisations of the same edge (projected polygon vs shadow map) differ by a pixel.
    assert!(m.rmse < 0.1, "{m:?}");
    // A light wider than the wall (radius 2 m): near the wall V follows the truth's, and the
    // light's side stays lit. (Further out, 1.8 m behind, the cones' 85° cap keeps an umbra
    // where the reference has V = 0.28.)
    let huge = render_with(&mut e, &wall(1.0, 2.0), "plateau", &[], SIZE);
    let truth = common::reference(&mut e, &wall(1.0, 2.0), SIZE);
    for x in [-0.3, -1.0] {
        let (v, t) = (huge.visibility_at(column(x), SIZE / 2), truth.visibility_at(column(x), SIZE / 2));
        assert!((v - t).abs() < 0.15, "{x} m behind the wall: V {v}, the reference's {t}");
    }
    assert!(huge.visibility_at(column(0.3), SIZE / 8) > 0.99);
    finish(e);
}

/// A 1 m box on the ground, a light 6 m away at `elevation` degrees (at 1° the box's top is
/// above the light), seen from above.
fn low_light(elevation: f32) -> Scene {
    let e = elevation.to_radians();
    scene(&format!(
        r#"
[camera]
position = [-3.0, 12.0, 0.0]
target = [-3.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
ortho_half_height = 4.0
[light]
position = [{}, {}, 0.0]
radius = 0.2
[ground]
height = 0.0
half_size = 400.0
[[object]]
shape = "box"
size = [1.0, 1.0, 1.0]
position = [0.0, 0.5, 0.0]
"#,
        6.0 * e.cos(),
        0.1 + 6.0 * e.sin()
    ))
}

#[test]
fn low_lights_stretch_the_shadow_without_breaking() {
    let mut e = engine();
    for elevation in [30.0, 5.0, 1.0] {
        let c = render_with(&mut e, &low_light(elevation), "plateau", &[], 64);
        // The shadow falls away from the light (−x): dark somewhere there (x < −1 m, past the
        // box, where the umbra of the centred penumbra ends), lit on the light's side.
        let dark = (0..48).any(|x| c.visibility_at(x, 32) < 0.05);
        assert!(dark, "{elevation}°: no shadow behind the box");
        assert!(c.visibility_at(60, 32) > 0.99, "{elevation}°: the light's side must be lit");
    }
    finish(e);
}

#[test]
fn a_caster_reaching_above_the_light_casts_no_anti_shadow() {
    // A tall post (0.3 m square, 6 m) whose top is 4 m above the light (2 m up at x = 2): the part
    // above casts nothing (clipped at w = 0), and the shadow of the part below runs to the
    // horizon along −x, inside the wedge from the light's foot through the post's corners
    // (0.15, ±0.15): |z| ≤ 0.15·(2 − x)/1.85. Seen from above, 8 px per metre: column 8·(x + 4),
    // row 8·(z + 4). Were the part above drawn, its anti-shadow would land on the light's side
    // (x ≥ 2 + 1.85·2/4 ≈ 2.9 for the post's top), or the clip would smear it across the light.
    let post = "[[object]]\nshape = \"box\"\nsize = [0.3, 6.0, 0.3]\nposition = [0.0, 3.0, 0.0]\n";
    let s = top_down(0.0, 4.0, [2.0, 2.0, 0.0], 0.1, post);
    let mut e = engine();
    let c = render_with(&mut e, &s, "plateau", &[], 64);
    let world = |i: u32| (i as f32 + 0.5) / 8.0 - 4.0;
    let wedge = |x: f32| 0.15 * (2.0 - x) / 1.85;
    // A pixel of margin: the hard edge's rasterisation (texture texels, the view's pixels).
    let margin = 1.0 / 8.0;
    let (mut dark, mut lit, mut stopped, mut stray) = (0, 0, Vec::new(), Vec::new());
    for col in 0..64 {
        let x = world(col);
        for row in 0..64 {
            let (z, v) = (world(row), c.visibility_at(col, row));
            let at = format!("({x:.2}, {z:.2}) V = {v:.2}");
            if x < -0.15 - margin && z.abs() < wedge(x) - margin {
                // Behind the post, inside the wedge: dark all the way to the image's edge.
                dark += 1;
                if v >= 0.05 {
                    stopped.push(at);
                }
            } else if x > 0.15 + margin || z.abs() > wedge(x) + margin {
                // The light's side of the post and beside the wedge: lit, no anti-shadow.
                lit += 1;
                if v <= 0.99 {
                    stray.push(at);
                }
            }
        }
    }
    assert!(dark >= 60 && lit >= 3000, "the checks cover the shadow and its surroundings: {dark} dark, {lit} lit px");
    let first = |p: &Vec<String>| p[..p.len().min(4)].join(", ");
    assert!(
        stopped.is_empty() && stray.is_empty(),
        "{} of {dark} px in the wedge lit, first [{}]; {} of {lit} px outside it shadowed, first [{}]",
        stopped.len(),
        first(&stopped),
        stray.len(),
        first(&stray)
    );
    finish(e);
}

#[test]
fn nested_and_equal_cone_radii_stay_sane() {
    // A vertical pole under a light straight above: its foot's cone (radius 0) lies inside its
    // top's cone, so those sides have no outer tangent. A plate parallel to the ground: all radii
    // equal, every sheet a flat quad.
    let pole = top_down(
        0.0,
        2.0,
        [0.0, 8.0, 0.0],
        0.5,
        "[[object]]\nshape = \"cylinder\"\nradius = 0.05\nheight = 3.0\nposition = [0.0, 1.5, 0.0]\nreceives = false\n",
    );
    let mut e = engine();
    let c = render_with(&mut e, &pole, "plateau", &[], 64);
    assert!(c.visibility_at(4, 4) > 0.99, "far from the pole: lit");
    let plate = suite_scene("plate");
    let p = render_with(&mut e, &plate, "plateau", &[], 64);
    assert!(p.visibility.contains(&0) && p.visibility.iter().any(|&v| v > 0 && v < 65535));
    finish(e);
}

/// RMSE bounds against the reference (N = 256), about 1.45 times what lavapipe measured at 64²
/// with the centred default (plate 0.0053, sphere 0.0186; the hard shadow map: 0.0454, 0.0427;
/// the outer-only form at its old narrow size: 0.0404, 0.0384).
const BOUNDS: [(&str, f64); 2] = [("plate", 0.008), ("sphere", 0.027)];

#[test]
fn the_error_against_the_reference_stays_under_its_bounds() {
    let mut e = engine();
    for (name, bound) in BOUNDS {
        let [plateau, hard] =
            <[_; 2]>::try_from(against_reference(&mut e, &suite_scene(name), &["plateau", "shadow-map"]))
                .expect("two techniques");
        eprintln!("{name}: plateau RMSE {:.4} (hard {:.4})", plateau.rmse, hard.rmse);
        assert!(plateau.rmse < bound, "{name}: plateau RMSE {} over {bound}", plateau.rmse);
        assert!(plateau.rmse < hard.rmse, "{name}: the plateau should beat the hard shadow");
    }
    finish(e);
}

/// Issue 18: corner wedges give the picture of Haines' whole cones, within 1/255 but for a few
/// pixels (at most 0.2%) where a silhouette passes from the hard shadow's boundary to inside it
/// (the cow's legs in `default`: there whole cones let their inner penumbra through, up to 0.3
/// lighter, the reference mostly 0), on suite scenes of one and of several casters, smooth and
/// faceted, with a low light and an open mesh.
#[test]
fn corner_wedges_give_the_picture_of_whole_cones() {
    let mut e = engine();
    for name in ["default", "sphere", "torus", "overlap", "low_light", "open_mesh", "wingnut"] {
        let s = suite_scene(name);
        let size = 128;
        let wedges = render_with(&mut e, &s, "plateau", &[], size);
        let whole = render_with(&mut e, &s, "plateau", &[("cones", "0")], size);
        let (mut off, mut worst) = (0, 0.0f32);
        for y in 0..size {
            for x in 0..size {
                let d = (wedges.visibility_at(x, y) - whole.visibility_at(x, y)).abs();
                (off, worst) = (off + (d > 1.0 / 255.0) as u32, worst.max(d));
            }
        }
        assert!(off * 500 <= size * size && worst <= 0.35, "{name}: {off} pixels differ, by up to {worst}");
    }
    finish(e);
}

#[test]
fn open_meshes_and_off_plane_receivers() {
    // An open box (no bottom): its sides follow the shadow's outline, boundary edges too. Under it, a receiver that casts nothing, off the plane: unshadowed by default, shadowed by
    // the projected light map with off_plane = 1.
    let objects = r#"
[[object]]
shape = "mesh"
mesh = "../models/cube_no_bottom.obj"
position = [-1.5, 2.5, 0.0]
receives = false
[[object]]
shape = "box"
size = [1.0, 0.2, 1.0]
position = [1.5, 2.0, 0.0]
receives = false
[[object]]
shape = "box"
size = [2.0, 0.2, 2.0]
position = [1.5, 0.4, 0.0]
casts = false
"#;
    let s = top_down(0.0, 3.0, [0.0, 9.0, 0.0], 0.3, objects);
    let mut e = engine();
    let plain = render_with(&mut e, &s, "plateau", &[], 64);
    // The open box's shadow on the ground, where the box does not hide it (x = −2.8).
    assert_eq!(plain.visibility_at(2, 32), 0.0, "the open mesh casts an umbra");
    assert!(plain.visibility_at(4, 60) > 0.99 && plain.visibility_at(60, 4) > 0.99);
    // The slab 0.4 m up is off the plane: unshadowed, then under the light map (x = 2.25, past
    // the small box that hides the middle of its shadow).
    let slab = (56, 32);
    assert_eq!(plain.visibility_at(slab.0, slab.1), 1.0);
    let mapped = render_with(&mut e, &s, "plateau", &[("off_plane", "1")], 64);
    assert!(mapped.visibility_at(slab.0, slab.1) < 0.05, "{}", mapped.visibility_at(slab.0, slab.1));
    finish(e);
}

/// Issue 18: the plateau texture holds the exact t of its primitives. Outer only, linear falloff
/// and whole cones, V on the ground is the texture's t; it must match a CPU evaluation of the
/// whole cones and the exact bilinear patches (min over all, each evaluated everywhere, not only
/// inside what the GPU draws of it), within 1/255, on a tilted box (twisted sheets) seen from
/// above, away from the hard edge's texels and from the box itself.
#[test]
fn the_plateau_texture_holds_the_exact_t_of_whole_cones_and_patches() {
    use glam::{Vec2, Vec3};
    use softshadow::geometry::plateau::{
        Penumbra, PenumbraSize, PlateauLight, ReceiverPlane, plateau_edges, plateau_sides,
    };
    use softshadow::geometry::silhouette::{Caster, EdgeSource};
    let (size, half) = (128u32, 1.6f32);
    let objects = "[[object]]\nshape = \"box\"\nsize = [1.0, 0.1, 0.8]\nposition = [0.0, 1.2, 0.0]\nrotation_deg = [25.0, 0.0, 10.0]\n";
    let s = top_down(0.0, half, [1.0, 6.0, 0.5], 1.0, objects);
    let mut e = engine();
    let c = render_with(&mut e, &s, "plateau", &[("penumbra", "0"), ("falloff", "0"), ("cones", "0")], size);
    finish(e);

    let o = &s.objects[0];
    let (mesh, model) = (&o.mesh, o.transform.matrix());
    let (plane, light) = (ReceiverPlane::ground(0.0), s.light.position);
    let plateau_light = PlateauLight {
        position: light,
        radius: s.light.radius,
        size: PenumbraSize::Physical { scale: 1.0 },
        penumbra: Penumbra::Outer,
        wedges: false,
    };
    let caster = Caster { positions: &mesh.positions, triangles: &mesh.triangles, adjacency: &mesh.adjacency };
    let edges = plateau_edges(&caster, &mesh.planes.light_facing(&model, light), EdgeSource::Silhouettes);
    let sides = plateau_sides(&plane, &plateau_light, &caster, &model, &edges, EdgeSource::Silhouettes, 1.0);
    assert!(
        sides.cones.len() >= 16 && sides.sheets.len() >= 6,
        "{} wedges, {} sheets",
        sides.cones.len(),
        sides.sheets.len()
    );
    let exact = |p: Vec2| {
        let cones = sides.cones.iter().map(|w| w.t_at(p));
        let sheets = sides.sheets.iter().filter_map(|s| s.at(p).map(|(t, _)| t));
        cones.chain(sheets).fold(1.0f32, f32::min)
    };
    // Triangles in the plane: projected from the light (the hard shadow), and straight down
    // (what the camera sees of the box instead of the ground).
    let triangles = |to: &dyn Fn(Vec3) -> Vec2| -> Vec<[Vec2; 3]> {
        mesh.triangles.iter().map(|t| t.map(|v| to(model.transform_point3(mesh.positions[v as usize])))).collect()
    };
    let inside = |tris: &[[Vec2; 3]], p: Vec2| {
        tris.iter().any(|t| {
            let w = [0, 1, 2].map(|k| (t[(k + 1) % 3] - t[k]).perp_dot(p - t[k]));
            w.iter().all(|w| *w >= 0.0) || w.iter().all(|w| *w <= 0.0)
        })
    };
    let shadow = triangles(&|p| plane.project(light, p).unwrap());
    let box_seen = triangles(&|p| Vec2::new(p.x, p.z));
    let pixel = 2.0 * half / size as f32;
    // Image x is world x, rows world z, from −half.
    let ground = |x: f32, y: f32| Vec2::new(-half + (x + 0.5) * pixel, -half + (y + 0.5) * pixel);
    let (mut worst, mut compared, mut penumbra) = (0.0f32, 0, 0);
    for y in 0..size {
        for x in 0..size {
            let p = ground(x as f32, y as f32);
            // Two pixels off the hard edge and the box's outline: the texture's bilinear
            // lookup there mixes in the mask's t = 0.
            let near = [(-2.0, 0.0), (2.0, 0.0), (0.0, -2.0), (0.0, 2.0), (0.0, 0.0)]
                .map(|(dx, dy)| p + Vec2::new(dx, dy) * pixel);
            if near.iter().any(|q| inside(&shadow, *q) || inside(&box_seen, *q)) {
                continue;
            }
            let (got, want) = (c.visibility_at(x, y), exact(p));
            worst = worst.max((got - want).abs());
            compared += 1;
            penumbra += (want < 0.99) as u32;
        }
    }
    assert!(penumbra > 500 && compared > penumbra, "{penumbra} penumbra pixels of {compared}");
    assert!(worst <= 1.0 / 255.0, "V differs from the exact t by up to {worst} ({penumbra} penumbra pixels)");
}
