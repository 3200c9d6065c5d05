//! Shared by the GPU tests: every engine runs with validation (and synchronization validation)
//! on, and a test fails on any validation error, including objects left alive at exit.
#![allow(dead_code)] // each test binary uses a different subset of these helpers

pub mod c;
pub mod embedder;
pub mod xvfb;

use softshadow::gpu::{Context, ContextOptions};
use softshadow::measure::PENUMBRA;
use softshadow::scene::Scene;
use softshadow::technique::{Kind, Params, TECHNIQUES, find};
use softshadow::{Capture, Engine, FrameSettings};

pub fn engine() -> Engine {
    Engine::headless(&ContextOptions { validation: true, device: None })
        .expect("a Vulkan 1.3 device (lavapipe) with validation layers")
}

/// Destroys the engine and fails the test on any validation error.
pub fn finish(engine: Engine) {
    let errors = engine.finish();
    assert!(errors.is_empty(), "{} validation error(s):\n{}", errors.len(), errors.join("\n"));
}

/// A headless context on lavapipe with validation on, for tests below the engine.
pub fn context() -> Context {
    Context::headless(&ContextOptions { validation: true, device: None })
        .expect("a Vulkan 1.3 device (lavapipe) with validation layers")
}

/// Destroys the context and fails on any validation error, objects left alive included.
pub fn finish_context(mut ctx: Context) {
    ctx.destroy();
    let errors = ctx.validation_errors();
    assert!(errors.is_empty(), "{} validation error(s):\n{}", errors.len(), errors.join("\n"));
}

pub fn scene(text: &str) -> Scene {
    Scene::from_toml(text, "tests/inline.toml").expect("valid test scene")
}

/// The ground seen from straight above by an orthographic camera at (`x`, 12, 0) (image x =
/// world x, rows = world z, `half` metres each way), a light at `light` of `radius`, and
/// `objects` (their TOML).
pub fn top_down(x: f32, half: f32, light: [f32; 3], radius: f32, objects: &str) -> Scene {
    scene(&format!(
        "[camera]\nposition = [{x}, 12.0, 0.0]\ntarget = [{x}, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
         ortho_half_height = {half}\n[light]\nposition = [{}, {}, {}]\nradius = {radius}\n\
         [ground]\nheight = 0.0\n{objects}",
        light[0], light[1], light[2]
    ))
}

/// A scene of the suite in scenes/, by name.
pub fn suite_scene(name: &str) -> Scene {
    Scene::load(format!("{}/scenes/{name}.toml", env!("CARGO_MANIFEST_DIR"))).expect("a scene of the suite")
}

/// The sphere scene (a sphere of radius 0.6 at (0, 1.3, 0)) with objects of its own before and
/// after, as TOML: a technique that builds for one caster or for several sees another scene,
/// the shadows are the same.
pub fn sphere_with(before: &str, after: &str) -> Scene {
    let path = format!("{}/scenes/sphere.toml", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("the sphere scene");
    scene(&format!("{before}\n{text}\n{after}"))
}

/// A box too small to matter, at the sphere's centre (see [`sphere_with`]): a second caster
/// that changes no shadow.
pub const HIDDEN_IN_THE_SPHERE: &str =
    "[[object]]\nshape = \"box\"\nsize = [0.05, 0.05, 0.05]\nposition = [0.0, 1.3, 0.0]\n";

/// How many pixels of `c` are in penumbra (V inside [`PENUMBRA`]).
pub fn penumbra_pixels(c: &Capture) -> usize {
    let (lo, hi) = PENUMBRA;
    c.visibility.iter().filter(|&&x| (lo..hi).contains(&(f64::from(x) / 65535.0))).count()
}

/// The largest difference of V between two captures of one size.
pub fn largest_difference(a: &Capture, b: &Capture) -> f32 {
    let v = |x: &u16| *x as f32 / 65535.0;
    a.visibility.iter().zip(&b.visibility).map(|(x, y)| (v(x) - v(y)).abs()).fold(0.0, f32::max)
}

/// `candidate` (named `what`) is as close to `truth` as `against`: penumbra RMSE within 0.002
/// and no more leaks. A coarser grid against a finer one, or a setting against the grid it
/// should match.
pub fn as_accurate_as(candidate: &Capture, against: &Capture, truth: &Capture, what: &str) {
    let [candidate, against] = [candidate, against].map(|v| softshadow::measure::Metrics::between(v, truth).unwrap());
    assert!(
        candidate.penumbra_rmse <= against.penumbra_rmse + 0.002,
        "{what}: penumbra RMSE {}, against {}",
        candidate.penumbra_rmse,
        against.penumbra_rmse
    );
    assert!(candidate.leak_rate <= against.leak_rate, "{what}: leaks {} vs {}", candidate.leak_rate, against.leak_rate);
}

/// The ground truth the accuracy bounds are stated against: the GPU reference with 256 light
/// samples (512² maps, which keeps lavapipe quick).
pub fn reference(e: &mut Engine, s: &Scene, size: u32) -> Capture {
    render_with(e, s, "reference", &[("samples", "256"), ("shadow_map_size", "512")], size)
}

/// Each technique's error against [`reference`] on `s` at 64², in order (one reference render).
pub fn against_reference(e: &mut Engine, s: &Scene, techniques: &[&str]) -> Vec<softshadow::measure::Metrics> {
    let truth = reference(e, s, 64);
    techniques
        .iter()
        .map(|t| softshadow::measure::Metrics::between(&render_with(e, s, t, &[], 64), &truth).expect("same size"))
        .collect()
}

/// Image size of the [`wall`] views.
pub const WALL_SIZE: u32 = 128;

/// A thin wall on the ground at x = 0 under a light at +x, seen from straight above (image x =
/// world x, rows = world z, 3 m across), everything scaled by `s`: its shadow runs to −x, and
/// the penumbra of its side edges widens with the distance from its foot, where it touches the
/// ground.
pub fn wall(s: f32, light_radius: f32) -> Scene {
    scene(&format!(
        "[camera]\nposition = [{cx}, {ch}, 0.0]\ntarget = [{cx}, 0.0, 0.0]\nup = [0.0, 0.0, -1.0]\n\
         ortho_half_height = {half}\n[light]\nposition = [{l}, {l}, 0.0]\nradius = {r}\n\
         [ground]\nheight = 0.0\nhalf_size = {g}\n\
         [[object]]\nshape = \"box\"\nsize = [{t}, {two}, {one}]\nposition = [0.0, {one}, 0.0]\n",
        cx = -s,
        ch = 10.0 * s,
        half = 1.5 * s,
        l = 3.0 * s,
        r = light_radius * s,
        g = 10.0 * s,
        t = 0.1 * s,
        two = 2.0 * s,
        one = s,
    ))
}

/// Pixel column of world x / scale in a [`wall`] view.
pub fn wall_column(x: f32) -> u32 {
    ((x + 2.5) / 3.0 * WALL_SIZE as f32) as u32
}

/// Penumbra pixels (0.02 < V < 0.98) down column `x` of a [`wall`] view, across the shadow's +z
/// side edge.
pub fn wall_edge_width(c: &Capture, x: u32) -> usize {
    (WALL_SIZE / 2..WALL_SIZE).filter(|&y| (0.02..0.98).contains(&c.visibility_at(x, y))).count()
}

/// Where a profile of (position, V) first rises through V = `level`, interpolated.
pub fn crossing(profile: &[(f32, f32)], level: f32) -> Option<f32> {
    profile.windows(2).find(|w| w[0].1 < level && w[1].1 >= level).map(|w| {
        let f = (level - w[0].1) / (w[1].1 - w[0].1);
        w[0].0 + f * (w[1].0 - w[0].0)
    })
}

/// Renders `technique` with knobs `sets` at `size`², and reads the frame back.
pub fn render_with(e: &mut Engine, s: &Scene, technique: &str, sets: &[(&str, &str)], size: u32) -> Capture {
    let mut frame = settings(s, size, size);
    frame.params = Params::defaults(find(technique).expect("a known technique"));
    frame.params.apply(sets.iter().copied()).expect("valid knobs");
    e.render_and_capture(s, &frame).expect("a rendered frame")
}

/// Every real-time technique at its defaults, then the smoothie and the shadow volumes on their
/// compute paths (`gpu_silhouettes = 1`).
pub fn realtime_runs() -> Vec<(&'static str, Params)> {
    let mut runs: Vec<(&str, Params)> =
        TECHNIQUES.iter().filter(|t| t.kind == Kind::Realtime).map(|t| (t.name, Params::defaults(t))).collect();
    for name in ["smoothie", "shadow-volume"] {
        let mut params = Params::defaults(find(name).unwrap());
        params.set("gpu_silhouettes", "1").unwrap();
        runs.push((name, params));
    }
    runs
}

pub fn settings(scene: &Scene, w: u32, h: u32) -> FrameSettings {
    let mut s = FrameSettings::from_scene(scene).expect("valid settings");
    s.width = w;
    s.height = h;
    s
}

/// Centroid (x, y) in pixels of the receiver pixels darker than V = 0.5.
pub fn shadow_centroid(c: &softshadow::Capture) -> Option<(f32, f32)> {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for y in 0..c.height {
        for x in 0..c.width {
            if c.visibility_at(x, y) < 0.5 {
                sx += x as f32;
                sy += y as f32;
                n += 1.0;
            }
        }
    }
    (n > 0.0).then(|| (sx / n, sy / n))
}

/// The CPU ray tracer with 256 shadow rays per pixel: the truth the lit-caster checks use
/// (exact on the caster's own faces, where a shadow map's self-comparisons are the suspect).
pub fn traced(e: &mut Engine, s: &Scene, size: u32) -> Capture {
    render_with(e, s, "raytrace", &[("samples", "256")], size)
}

/// Lit caster pixels a technique darkens: among the pixels where both renders see the same
/// facet (depths within 0.1 %, normals within cos 0.99) of a surface that casts and receives,
/// and `truth` sees fully lit (V ≥ 0.99), how many `v` gives V < 0.8.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LitCasters {
    /// Lit caster pixels compared.
    pub of: usize,
    /// Of those, the ones `v` darkens.
    pub darkened: usize,
    /// Darkened pixels away from any edge: all eight neighbours are lit caster pixels too (a
    /// pixel beside a silhouette, a shadow or the terminator may be darkened by the sampling of
    /// a map or a rasterizer, not by a wrong estimate).
    pub interior: usize,
}

impl LitCasters {
    pub fn rate(&self) -> f64 {
        if self.of == 0 { 0.0 } else { self.darkened as f64 / self.of as f64 }
    }
}

pub fn lit_casters(v: &Capture, truth: &Capture) -> LitCasters {
    assert_eq!((v.width, v.height), (truth.width, truth.height), "same size");
    let lit: Vec<bool> = (0..v.visibility.len())
        .map(|i| same_caster_surface(v, truth, i) && truth.visibility[i] >= (0.99 * 65535.0) as u16)
        .collect();
    let (w, h) = (v.width as i64, v.height as i64);
    let mut m = LitCasters::default();
    for (i, _) in lit.iter().enumerate().filter(|(_, l)| **l) {
        m.of += 1;
        if v.visibility[i] >= (0.8 * 65535.0) as u16 {
            continue;
        }
        m.darkened += 1;
        let (x, y) = (i as i64 % w, i as i64 / w);
        let inside = |dx: i64, dy: i64| {
            let (nx, ny) = (x + dx, y + dy);
            (0..w).contains(&nx) && (0..h).contains(&ny) && lit[(ny * w + nx) as usize]
        };
        m.interior += usize::from((-1..=1).all(|dy| (-1..=1).all(|dx| inside(dx, dy))));
    }
    m
}

/// Pixel `i` shows the same caster surface in both captures: a caster in each, at the same depth
/// and facing the same way.
fn same_caster_surface(v: &Capture, truth: &Capture, i: usize) -> bool {
    let (a, b) = (&v.surfaces, &truth.surfaces);
    let (da, db) = (a.depth[i], b.depth[i]);
    a.casts[i] && b.casts[i] && (da - db).abs() <= 1e-3 * da.max(db) && a.normal[i].dot(b.normal[i]) >= 0.99
}

/// A caster's own terminator: its pixels where the reference is in penumbra (V in 0.02..0.98),
/// the RMSE of `v` against the reference over them, and how much darker than the reference `v`
/// is at most there.
pub fn terminator_error(v: &Capture, truth: &Capture) -> (usize, f64, f64) {
    assert_eq!((v.width, v.height), (truth.width, truth.height), "same size");
    let errors: Vec<f64> = (0..v.visibility.len())
        .filter(|&i| same_caster_surface(v, truth, i) && (1311..64224).contains(&truth.visibility[i]))
        .map(|i| (v.visibility[i] as f64 - truth.visibility[i] as f64) / 65535.0)
        .collect();
    let rmse = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len().max(1) as f64).sqrt();
    let darker = errors.iter().fold(0.0, |d: f64, e| d.max(-e));
    (errors.len(), rmse, darker)
}

/// The scale among `scales` (values of `knob`, ascending, with `fixed` knobs set too) at which
/// `technique`'s penumbra RMSE against the reference is least on the suite scene `name`, at 96²:
/// what the issue-20 tests hold to lie within [0.8, 1.25] of the physical size.
pub fn error_minimising_scale(
    e: &mut Engine,
    name: &str,
    (technique, knob, fixed): (&str, &str, &[(&str, &str)]),
    scales: &[&'static str],
) -> &'static str {
    let s = suite_scene(name);
    let truth = reference(e, &s, 96);
    let errors: Vec<f64> = scales
        .iter()
        .map(|k| {
            let knobs: Vec<_> = fixed.iter().copied().chain([(knob, *k)]).collect();
            let v = render_with(e, &s, technique, &knobs, 96);
            softshadow::measure::Metrics::between(&v, &truth).unwrap().penumbra_rmse
        })
        .collect();
    eprintln!("{technique} on {name}: penumbra RMSE by {knob} {scales:?}: {errors:.4?}");
    let best = (0..scales.len()).min_by(|&a, &b| errors[a].total_cmp(&errors[b])).unwrap();
    scales[best]
}

/// Names of the GPU passes of every frame rendered since the last call.
pub fn passes_per_frame(e: &mut Engine) -> Vec<Vec<&'static str>> {
    e.flush().unwrap();
    e.take_timings().iter().map(|t| t.passes.iter().map(|p| p.name).collect()).collect()
}

/// `technique` with its silhouettes on the GPU (`gpu_silhouettes = 1`) drawing `s` at 64², five
/// frames with nothing changed: the settings, the first and last captures, each frame's passes.
pub fn static_compute_frames(
    e: &mut Engine,
    s: &Scene,
    technique: &str,
) -> (FrameSettings, Capture, Capture, Vec<Vec<&'static str>>) {
    let mut frame = settings(s, 64, 64);
    frame.params = Params::defaults(find(technique).expect("a known technique"));
    frame.params.set("gpu_silhouettes", "1").expect("a compute path");
    let first = e.render_and_capture(s, &frame).expect("a rendered frame");
    for _ in 0..3 {
        e.render(s, &frame).expect("a rendered frame");
    }
    let last = e.render_and_capture(s, &frame).expect("a rendered frame");
    let passes = passes_per_frame(e);
    (frame, first, last, passes)
}

/// A scene whose hard shadow turns a corner in the middle of a 128² view (between pixels 63 and
/// 64 both ways), and where the reference's V there must lie.
pub struct CornerScene {
    pub scene: Scene,
    pub truth: std::ops::RangeInclusive<f32>,
}

/// A thick slab (0.6 m wide, 1.3 m tall, from 1 m up) under a light of radius 0.5 m 5 m straight
/// above it: its sides, seen edge-on from x = ±0.3 m, turn their backs to the light's centre and
/// their faces to its rim. The silhouette from the centre is the top rim, whose inner half
/// alone would reach 0.43 m in from its hard edge (x = 0.556 m); but a point under the side's
/// plane (x < 0.3 m) sees only the light beyond it, for which the silhouette is the bottom rim,
/// lower, with the narrower penumbra: the truth's umbra begins 0.31 m in, at x = 0.25 m (the
/// ray from the light's rim past the bottom rim). Seen from above and aside at 128², the middle
/// column runs across the near side's penumbra: from the hard edge (V = ½) inward to V = 0.02,
/// `technique`'s inner half (with `sets`) must span within 20 % of the reference's.
pub fn thick_slab_s_inner_half(technique: &str, sets: &[(&str, &str)]) {
    let s = scene(
        "[camera]\nposition = [2.35, 2.0, 0.0]\ntarget = [0.35, 0.0, 0.0]\nfov_y_deg = 20.0\n\
         [light]\nposition = [0.0, 5.0, 0.0]\nradius = 0.5\n[ground]\nheight = 0.0\n\
         [[object]]\nshape = \"box\"\nsize = [0.6, 1.3, 4.0]\nposition = [0.0, 1.65, 0.0]\n",
    );
    let mut e = engine();
    let [v, truth] = [render_with(&mut e, &s, technique, sets, 128), reference(&mut e, &s, 128)];
    finish(e);
    // Up the middle column from the near (lit) ground: the hard edge, then the inner half.
    let column = |c: &Capture| (0..c.height).rev().map(|y| c.visibility_at(c.width / 2, y)).collect::<Vec<_>>();
    let inner = |v: &[f32]| {
        let edge = v.iter().position(|&v| v < 0.5).expect("a hard edge in view");
        v[edge..].iter().take_while(|&&v| v >= 0.02).count() as f32
    };
    let (got, want) = (inner(&column(&v)), inner(&column(&truth)));
    assert!(want >= 15.0, "the reference's inner half spans {want} px");
    assert!((got - want).abs() <= 0.2 * want, "{technique} {sets:?}: inner half {got} px, the reference's {want} px");
}

/// A plate's corner (half size 1, 1 m up, the light 6 m up, radius 0.5): its hard shadow's
/// corner at (1.2, 0) sees the light cut by both edges' lines, ¾ of it, where either edge alone
/// says ½ (the footprint is 0.2 m across, 0.8 m seen: 32 px of 128).
pub fn plate_corner() -> CornerScene {
    let object = "[[object]]\nshape = \"plate\"\nsize = [2.0, 0.0, 2.0]\nposition = [0.0, 1.0, -1.0]\n";
    CornerScene { scene: top_down(1.2, 0.4, [0.0, 6.0, 0.0], 0.5, object), truth: 0.70..=0.80 }
}

/// An L-shaped slab (two 2 × 1 m arms, 2 cm thick), 1 m up: its outline's one reflex vertex at
/// the origin, the light 6 m up at (−2.5, −2.5) (radius 0.5), so that its hard shadow's reflex
/// corner falls at (0.5, 0.5), in the quadrant the slab leaves open, seen from above 0.4 m each
/// way. The corner sees about a quarter of the light (a right angle seen a little obliquely),
/// where either edge alone says ½.
pub fn l_shaped_slab() -> CornerScene {
    use glam::Vec3;
    // The outline anticlockwise in (x, z), the reflex vertex (1, 1) moved to the origin; each
    // triangle wound so that its normal points along `out` (Mesh::new welds equal positions).
    let outline =
        [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)].map(|(x, z)| (x - 1.0, z - 1.0));
    let vertex = |(x, z): (f32, f32), y: f32| Vec3::new(x, y, z);
    let mut positions = Vec::new();
    let mut face = |p: [Vec3; 3], out: Vec3| {
        let flip = (p[1] - p[0]).cross(p[2] - p[0]).dot(out) < 0.0;
        positions.extend(if flip { [p[0], p[2], p[1]] } else { p });
    };
    for k in 1..outline.len() - 1 {
        let [a, b, c] = [outline[0], outline[k], outline[k + 1]];
        face([a, b, c].map(|q| vertex(q, 0.01)), Vec3::Y);
        face([a, b, c].map(|q| vertex(q, -0.01)), -Vec3::Y);
    }
    for k in 0..outline.len() {
        let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
        let out = Vec3::new(b.1 - a.1, 0.0, a.0 - b.0);
        face([vertex(a, 0.01), vertex(b, 0.01), vertex(b, -0.01)], out);
        face([vertex(a, 0.01), vertex(b, -0.01), vertex(a, -0.01)], out);
    }
    let triangles = (0..positions.len() as u32 / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect();
    let slab = softshadow::scene::Mesh::new("L-shaped slab", positions, triangles).expect("a closed slab");
    // A box placed where the slab goes, its mesh then swapped for the slab's.
    let mut s = scene(
        "[camera]\nposition = [0.5, 12.0, 0.5]\ntarget = [0.5, 0.0, 0.5]\nup = [0.0, 0.0, -1.0]\n\
         ortho_half_height = 0.4\n[light]\nposition = [-2.5, 6.0, -2.5]\nradius = 0.5\n[ground]\nheight = 0.0\n\
         [[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [0.0, 1.0, 0.0]\n",
    );
    s.objects[0].mesh = std::sync::Arc::new(slab);
    CornerScene { scene: s, truth: 0.15..=0.35 }
}

/// `technique` (with `sets`) at `c`'s corner within `near` of the reference (the mean of the
/// four pixels about it), the reference's V there in `c.truth`, and every pixel within
/// `everywhere` of the reference.
pub fn sees_at_the_corner(c: &CornerScene, technique: &str, sets: &[(&str, &str)], (near, everywhere): (f32, f32)) {
    let mut e = engine();
    let reference = reference(&mut e, &c.scene, 128);
    let v = render_with(&mut e, &c.scene, technique, sets, 128);
    finish(e);
    let around = |c: &Capture| {
        [(63, 63), (64, 63), (63, 64), (64, 64)].map(|(x, y)| c.visibility_at(x, y)).iter().sum::<f32>() / 4.0
    };
    let (corner, truth_corner) = (around(&v), around(&reference));
    assert!(c.truth.contains(&truth_corner), "the reference's V at the corner {truth_corner}");
    assert!(
        (corner - truth_corner).abs() <= near,
        "{technique} {sets:?}: V at the corner {corner}, the reference's {truth_corner}"
    );
    let worst = largest_difference(&v, &reference);
    assert!(worst <= everywhere, "{technique} {sets:?}: V up to {worst} off the reference");
}
