//! Centred plateaus (issue 20) on lavapipe, against the GPU reference: the penumbra straddles the
//! hard edge with the physical width, the umbra shrinks and vanishes as the light grows, no
//! inner penumbra lightens what another caster or another part of the same caster blocks, the
//! physical size is the error-minimising one, and the centred form beats the papers' outer-only
//! form on every scene of the suite.

mod common;

use common::{
    HIDDEN_IN_THE_SPHERE, as_accurate_as, engine, error_minimising_scale, finish, l_shaped_slab, largest_difference,
    penumbra_pixels, plate_corner, reference, render_with, scene, sees_at_the_corner, sphere_with, suite_scene,
    terminator_error, thick_slab_s_inner_half, top_down,
};
use softshadow::Capture;
use softshadow::measure::{GROSS_ERROR, Metrics};
use softshadow::scene::Scene;

/// The papers' form at its best curve, as bench runs it.
const OUTER: &[(&str, &str)] = &[("penumbra", "0"), ("falloff", "0")];

/// A square plate of half size `half` at `height` under a light of `radius` straight above the
/// origin at `light_height`, seen from above around x = `x` (`view` m each way).
fn plate(half: f32, height: f32, light_height: f32, radius: f32, x: f32, view: f32) -> Scene {
    let object = format!(
        "[[object]]\nshape = \"plate\"\nsize = [{s}, 0.0, {s}]\nposition = [0.0, {height}, 0.0]\n",
        s = 2.0 * half
    );
    top_down(x, view, [0.0, light_height, 0.0], radius, &object)
}

/// The default plateau and the reference, `size`² each.
fn plateau_and_reference(s: &Scene, size: u32) -> (Capture, Capture) {
    let mut e = engine();
    let truth = reference(&mut e, s, size);
    let v = render_with(&mut e, s, "plateau", &[], size);
    finish(e);
    (v, truth)
}

/// V along the image's middle row.
fn row(c: &Capture) -> Vec<f32> {
    (0..c.width).map(|x| c.visibility_at(x, c.height / 2)).collect()
}

/// The plate's edge at x = 1.2 m (half size 1, 1 m up, the light 6 m up): W = D·h/(H − h) =
/// 0.2 m, seen 0.8 m across so the penumbra spans 32 of 128 px. Inside and outside, the widths
/// from the hard edge to where V leaves [0.02, 0.98] (the same thresholds on both images).
#[test]
fn a_straight_plate_edge_penumbra_straddles_the_hard_edge() {
    let s = plate(1.0, 1.0, 6.0, 0.5, 1.2, 0.4);
    let mut e = engine();
    let truth = row(&reference(&mut e, &s, 128));
    let v = row(&render_with(&mut e, &s, "plateau", &[], 128));
    let outer = row(&render_with(&mut e, &s, "plateau", OUTER, 128));
    finish(e);
    // Pixel x covers world 0.8 + (x + 0.5)·0.8/128: the hard edge falls between 63 and 64.
    let edge = 0.5 * (v[63] + v[64]);
    assert!((edge - 0.5).abs() <= 0.1, "V on the hard edge {edge}: {:?}", &v[56..72]);
    let truth_edge = 0.5 * (truth[63] + truth[64]);
    assert!((truth_edge - 0.5).abs() <= 0.1, "the reference's V on the hard edge {truth_edge}");
    let widths = |v: &[f32]| {
        let inner = (0..64).rev().take_while(|&x| v[x] >= 0.02).count();
        let outer = (64..128).take_while(|&x| v[x] <= 0.98).count();
        (inner as f32, outer as f32)
    };
    let ((inner, out), (truth_inner, truth_out)) = (widths(&v), widths(&truth));
    assert!(truth_inner >= 8.0 && truth_out >= 8.0, "the reference's penumbra: {truth_inner} + {truth_out} px");
    for (got, want, side) in [(inner, truth_inner, "inner"), (out, truth_out, "outer")] {
        assert!((got - want).abs() <= 0.2 * want, "{side} width {got} px, the reference's {want} px");
    }
    // The papers' form keeps the whole hard shadow dark: nothing inside the edge.
    assert!(widths(&outer).0 <= 1.0, "outer only: {:?}", widths(&outer));
}

/// A thick slab (common::thick_slab_s_inner_half): the plateau's inner half, from the hard edge to V =
/// 0.02 up the middle column, within 20 % of the reference's, its bottom rim's, not its top
/// rim's (35 px against 26 with the partial silhouettes' inner sheets off).
#[test]
fn a_thick_slab_s_inner_half_is_its_bottom_rim_s() {
    thick_slab_s_inner_half("plateau", &[]);
}

/// A penumbra narrower than a texel: a plate 1 m up under a light of radius 1 mm 6 m up (W =
/// 0.4 mm at the hard edge, x = 1.2 m), seen 0.2 m across at 256², over a 16² texture (the
/// window is the footprint seen: 12.5 mm, 16 px a texel). Between an umbra texel and its lit
/// neighbour V is the curve once over the bilinear ramp of s, symmetric about ½ as the disk
/// profile is (mean ½ over the ramp), not the curve squared (mean 0.41 here), which a lit second
/// channel falling to the umbra with the first had made it.
#[test]
fn a_sub_texel_penumbra_ramps_once_between_texels() {
    let s = plate(1.0, 1.0, 6.0, 0.001, 1.2, 0.1);
    let coarse = [("texture_size", "16"), ("penumbra_texels", "0")];
    let mut e = engine();
    let v = row(&render_with(&mut e, &s, "plateau", &coarse, 256));
    finish(e);
    let ramp: Vec<f32> = v.iter().copied().filter(|v| (0.02..=0.98).contains(v)).collect();
    assert!(ramp.len() >= 8, "a texel's ramp across {} px: {v:?}", ramp.len());
    assert!(v.windows(2).all(|w| w[1] >= w[0] - 1e-3), "V rises across the edge: {v:?}");
    let mean = ramp.iter().sum::<f32>() / ramp.len() as f32;
    assert!((mean - 0.5).abs() <= 0.05, "mean V {mean} over the ramp: {ramp:?}");
}

/// A plate's corner (common::plate_corner): its hard shadow's corner sees the light cut by both
/// edges' lines, ¾ of it, where either sheet alone says ½, and around it the sides follow the
/// reference within 0.06.
#[test]
fn a_plate_corner_sees_three_quarters_of_the_light() {
    sees_at_the_corner(&plate_corner(), "plateau", &[], (0.03, 0.06));
}

/// An L-shaped slab's reflex corner (common::l_shaped_slab) sees about a quarter of the light,
/// where either sheet alone says ½, and around it the sides follow the reference within 0.06.
#[test]
fn an_l_shaped_slab_s_reflex_corner_sees_a_quarter_of_the_light() {
    sees_at_the_corner(&l_shaped_slab(), "plateau", &[], (0.03, 0.06));
}

/// A plate of half size 0.5 m, 2 m up, under a light 8 m up: from under its centre the plate
/// covers the light while R/H ≤ a/h, so the umbra vanishes at R = a·H/h = 2 m. Seen at 45°
/// (orthographic), so that the plate hides none of the middle row, the ground along x.
#[test]
fn the_umbra_shrinks_as_the_light_grows_and_vanishes_at_the_right_radius() {
    let vanishing = 2.0;
    let mut e = engine();
    let mut last = usize::MAX;
    for radius in [0.4, 1.0, 1.6, 0.85 * vanishing, 1.15 * vanishing, 1.4 * vanishing] {
        let s = scene(&format!(
            "[camera]\nposition = [0.0, 8.0, 8.0]\ntarget = [0.0, 0.0, 0.0]\northo_half_height = 1.5\n\
             [light]\nposition = [0.0, 8.0, 0.0]\nradius = {radius}\n[ground]\nheight = 0.0\n\
             [[object]]\nshape = \"plate\"\nsize = [1.0, 0.0, 1.0]\nposition = [0.0, 2.0, 0.0]\n"
        ));
        let v = row(&render_with(&mut e, &s, "plateau", &[], 96));
        let truth = row(&reference(&mut e, &s, 96));
        let umbra = |v: &[f32]| v.iter().filter(|&&v| v < 0.005).count();
        let (got, want) = (umbra(&v), umbra(&truth));
        assert!(got <= last, "R {radius}: the umbra grew from {last} to {got} px");
        assert!(got.abs_diff(want) <= 2 + want / 5, "R {radius}: umbra {got} px, the reference's {want} px");
        let centre = 0.5 * (v[47] + v[48]);
        if radius < vanishing {
            assert!(got > 0 && centre < 0.005, "R {radius}: an umbra under the centre (V {centre})");
        } else {
            assert!(got == 0 && centre > 0.005, "R {radius}: no umbra left (V {centre} under the centre)");
        }
        last = got;
    }
    finish(e);
}

/// Two plates whose shadows overlap, the lower one smaller and sharper: where one blocks, the
/// other's inner penumbra must not lighten. Each pixel is no lighter than either plate's shadow
/// alone, and nowhere, within the hard shadows (of a point light at the light's centre) or
/// outside them, where two outer penumbrae cross and multiply, lighter than the reference + 0.05.
#[test]
fn overlapping_plates_never_leak_light() {
    let low = "[[object]]\nshape = \"plate\"\nsize = [1.2, 0.0, 1.2]\nposition = [0.5, 0.8, 0.3]\n";
    let high = "[[object]]\nshape = \"plate\"\nsize = [2.0, 0.0, 2.0]\nposition = [-0.4, 2.5, 0.0]\n";
    let at = |objects: &str, radius| top_down(0.0, 2.5, [0.3, 7.0, 0.2], radius, objects);
    let mut e = engine();
    let both = at(&format!("{low}{high}"), 0.6);
    let truth = reference(&mut e, &both, 96);
    let v = render_with(&mut e, &both, "plateau", &[], 96);
    let hard = render_with(&mut e, &at(&format!("{low}{high}"), 0.0), "plateau", &[], 96);
    let alone = [low, high].map(|o| render_with(&mut e, &at(o, 0.6), "plateau", &[], 96));
    finish(e);
    let (mut inside, mut lighter, mut crossing) = (0, 0, 0);
    // Where the ground is seen: the plates hide some of it, and only the ground is compared.
    let ground = (0..96 * 96).filter(|&i| v.surfaces.receives[i] && !v.surfaces.casts[i]);
    for (x, y) in ground.map(|i| ((i % 96) as u32, (i / 96) as u32)) {
        let got = v.visibility_at(x, y);
        let single = alone.iter().map(|c| c.visibility_at(x, y)).fold(1.0, f32::min);
        assert!(got <= single + 0.02, "({x}, {y}): V {got} over the single shadows' {single}");
        let too_light = got > truth.visibility_at(x, y) + 0.05;
        if hard.visibility_at(x, y) == 0.0 {
            inside += 1;
            lighter += usize::from(too_light);
        } else {
            crossing += usize::from(too_light);
        }
    }
    assert!(inside > 500, "the hard shadows cover {inside} px");
    assert_eq!(lighter, 0, "{lighter} of {inside} px inside the hard shadows lighter than the reference + 0.05");
    assert_eq!(crossing, 0, "{crossing} px outside the hard shadows lighter than the reference + 0.05");
}

/// Silhouettes inside the hard shadow (the torus's far rim, the cow's legs and head under its
/// body) are not its boundary: no bright streak inside the reference's umbra.
#[test]
fn interior_folds_make_no_streaks_in_the_umbra() {
    let cow = scene(
        r#"
[camera]
position = [0.0, 6.0, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, -1.0]
ortho_half_height = 1.6
[light]
position = [0.6, 5.0, 0.4]
radius = 0.3
[ground]
height = 0.0
[[object]]
shape = "mesh"
mesh = "../models/spot_low_resolution.obj"
position = [0.0, 0.9, 0.0]
receives = false
"#,
    );
    let mut e = engine();
    for (name, s) in [("torus", suite_scene("torus")), ("cow", cow)] {
        let truth = reference(&mut e, &s, 96);
        let v = render_with(&mut e, &s, "plateau", &[], 96);
        let umbra: Vec<usize> = (0..truth.visibility.len()).filter(|&i| truth.visibility[i] == 0).collect();
        assert!(umbra.len() > 100, "{name}: the reference has an umbra ({} px)", umbra.len());
        let worst = umbra.iter().map(|&i| v.visibility[i]).max().unwrap() as f32 / 65535.0;
        assert!(worst <= 0.1, "{name}: V up to {worst} inside the reference's umbra");
    }
    finish(e);
}

/// The physical size is the right one: of the scales around it, the error against the reference
/// is least within [0.8, 1.25] of it on the plate and the sphere.
#[test]
fn the_physical_penumbra_size_minimises_the_error() {
    let scales = ["0.5", "0.65", "0.8", "1", "1.25", "1.6", "2"];
    let mut e = engine();
    for name in ["plate", "sphere"] {
        let best = error_minimising_scale(&mut e, name, ("plateau", "penumbra_scale", &[]), &scales);
        assert!(["0.8", "1", "1.25"].contains(&best), "{name}: least error at scale {best}");
    }
    finish(e);
}

/// On every scene of the suite: within the registry's bound of the hard shadow, more accurate
/// than the outer-only form in the penumbra and overall, and leaking hardly more light than it:
/// at most 0.25 % of the pixels more. Strictly no more is not met: where the truth's penumbra is
/// a pixel or two wide (near contact, the low light's box), V = ½ on a hard edge rasterised a
/// pixel off the reference's (its 512² maps) counts as a leak where the outer-only V = 0 counts
/// as too dark (low_light at 64²: 0.0194 against 0.0176).
#[test]
fn the_centred_form_beats_the_outer_only_form_on_every_suite_scene() {
    let bound = softshadow::technique::find("plateau").unwrap().error_bound.expect("plateau claims a bound");
    let mut e = engine();
    let mut scenes: Vec<_> = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes"))
        .unwrap()
        .map(|f| f.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml")) // not scenes/scale/
        .collect();
    scenes.sort();
    assert_eq!(scenes.len(), 10, "the suite's ten scenes");
    for path in scenes {
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        let s = Scene::load(&path).unwrap();
        let truth = reference(&mut e, &s, 64);
        let mut metrics = |sets: &[(&str, &str)], technique| {
            Metrics::between(&render_with(&mut e, &s, technique, sets, 64), &truth).unwrap()
        };
        let (centred, outer, hard) = (metrics(&[], "plateau"), metrics(OUTER, "plateau"), metrics(&[], "shadow-map"));
        eprintln!(
            "{name}: RMSE centred {:.4} outer {:.4} hard {:.4}; penumbra {:.4} vs {:.4}; leaks {:.4} vs {:.4}",
            centred.rmse,
            outer.rmse,
            hard.rmse,
            centred.penumbra_rmse,
            outer.penumbra_rmse,
            centred.leak_rate,
            outer.leak_rate
        );
        assert!(centred.rmse <= hard.rmse + bound, "{name}: RMSE {} over the bound", centred.rmse);
        assert!(centred.rmse < outer.rmse, "{name}: RMSE {} vs outer only {}", centred.rmse, outer.rmse);
        assert!(centred.penumbra_rmse < outer.penumbra_rmse, "{name}: penumbra RMSE");
        assert!(
            centred.leak_rate <= outer.leak_rate + 0.0025,
            "{name}: leaks {} vs {}",
            centred.leak_rate,
            outer.leak_rate
        );
    }
    finish(e);
}

/// A caster's own terminator is soft: the part of the light behind a convex caster's tangent
/// plane is hidden, and the rest is not, so on the sphere (which nothing else shadows) V where
/// the reference is in penumbra is the visible fraction of the light, not the hard 0 or 1 of
/// the light's centre.
#[test]
fn a_convex_casters_terminator_follows_the_light_above_its_tangent_plane() {
    let (v, truth) = plateau_and_reference(&suite_scene("sphere"), 128);
    let (pixels, rmse, darker) = terminator_error(&v, &truth);
    eprintln!("RMSE {rmse:.4}, at most {darker:.4} darker, over the sphere's {pixels} terminator pixels");
    assert!(pixels >= 30, "{pixels} sphere pixels in the reference's penumbra");
    assert!(rmse <= 0.05, "RMSE {rmse} over the sphere's {pixels} terminator pixels");
    assert!(darker <= GROSS_ERROR, "{darker} darker than the truth on the terminator");
}

/// Two bars at different heights whose shadows cross like a +, under a light off to the side so
/// that the ground by the crossing is seen: near it, outside both hard shadows, each bar blocks
/// its own part of the light, and the visibilities multiply (Chan & Durand Fig. 10), which the
/// darkest alone (Haines' min) is lighter than. Where both single shadows are in penumbra and neither hard shadow falls, V is
/// within 0.05 of the reference, and nowhere lighter than it by more.
#[test]
fn crossing_outer_penumbrae_of_two_casters_multiply() {
    let low = "[[object]]\nshape = \"plate\"\nsize = [0.6, 0.0, 3.0]\nposition = [-0.5, 1.0, 0.0]\n";
    let high = "[[object]]\nshape = \"plate\"\nsize = [3.0, 0.0, 0.6]\nposition = [0.0, 2.0, -0.5]\n";
    let at = |objects: &str, radius| top_down(0.3, 0.8, [-2.5, 6.0, -2.5], radius, objects);
    let both = format!("{low}{high}");
    let mut e = engine();
    let truth = reference(&mut e, &at(&both, 0.5), 96);
    let v = render_with(&mut e, &at(&both, 0.5), "plateau", &[], 96);
    let hard = render_with(&mut e, &at(&both, 0.0), "plateau", &[], 96);
    let alone = [low, high].map(|o| render_with(&mut e, &at(o, 0.5), "plateau", &[], 96));
    finish(e);
    let crossing: Vec<(u32, u32)> = (0..96 * 96)
        .map(|i| (i % 96, i / 96))
        .filter(|&(x, y)| hard.visibility_at(x, y) == 1.0 && alone.iter().all(|c| c.visibility_at(x, y) < 0.9))
        .collect();
    assert!(crossing.len() >= 20, "{} px where the outer penumbrae cross", crossing.len());
    let errors: Vec<f32> = crossing.iter().map(|&(x, y)| v.visibility_at(x, y) - truth.visibility_at(x, y)).collect();
    let rmse = (errors.iter().map(|e| e * e).sum::<f32>() / errors.len() as f32).sqrt();
    let lightest = errors.iter().copied().fold(f32::MIN, f32::max);
    eprintln!("{} crossing px: RMSE {rmse}, lightest {lightest} over the reference", crossing.len());
    assert!(rmse <= 0.05, "RMSE {rmse} against the reference where the penumbrae cross");
    assert!(lightest <= 0.05, "up to {lightest} lighter than the reference where the penumbrae cross");
}

/// Where one caster's hard shadow ends inside another's umbra (the suite's overlapping plates:
/// the low plate's edge under the high plate's shadow, at x = 0.147 m), the texels on either
/// side belong to different casters: no lit seam may run along it. Seen through a 2° lens, a
/// plateau texel spans a pixel or so; on the ground inside the reference's umbra, V stays
/// under 0.05.
#[test]
fn abutting_hard_shadows_leave_no_seam_in_the_umbra() {
    let overlap = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/overlap.toml")).unwrap();
    let objects = &overlap[overlap.find("[[object]]").unwrap()..overlap.find("[render]").unwrap()];
    let s = scene(&format!(
        "[camera]\nposition = [0.0, 6.0, 5.0]\ntarget = [0.147, 0.0, 0.72]\nfov_y_deg = 2.0\n\
         [light]\nposition = [0.5, 8.0, 0.5]\nradius = 0.6\n[ground]\nheight = 0.0\n{objects}"
    ));
    let (v, truth) = plateau_and_reference(&s, 96);
    let (a, b) = (&v.surfaces, &truth.surfaces);
    let umbra: Vec<usize> = (0..v.visibility.len())
        .filter(|&i| a.receives[i] && !a.casts[i] && b.receives[i] && !b.casts[i] && truth.visibility[i] == 0)
        .collect();
    assert!(umbra.len() > 4000, "the reference's umbra on the ground: {} px", umbra.len());
    let worst = umbra.iter().map(|&i| v.visibility[i]).max().unwrap() as f32 / 65535.0;
    assert!(worst <= 0.05, "V up to {worst} on the ground inside the reference's umbra");
}

/// One caster's plateau texture has one channel (penumbra.frag writes it in r whatever the
/// caster's number), several casters' two: the sphere alone, after an object that casts nothing
/// (the sphere caster number 2, whose channel would be g), and with a second caster hidden
/// inside it give the same V, centred and outer only.
#[test]
fn one_caster_s_texture_reads_as_the_channels_do() {
    let far_away =
        "[[object]]\nshape = \"box\"\ncasts = false\nsize = [0.1, 0.1, 0.1]\nposition = [40.0, 0.05, 40.0]\n";
    let scenes = [sphere_with("", ""), sphere_with(far_away, ""), sphere_with("", HIDDEN_IN_THE_SPHERE)];
    let mut e = engine();
    for sets in [&[][..], OUTER] {
        let [a, b, c] = scenes.each_ref().map(|s| render_with(&mut e, s, "plateau", sets, 128));
        let penumbra = penumbra_pixels(&a);
        let (second, channels) = (largest_difference(&a, &b), largest_difference(&a, &c));
        eprintln!("{sets:?}: {penumbra} penumbra px; caster number 2: {second}, two channels: {channels}");
        assert!(penumbra > 100, "a penumbra to compare: {penumbra} px");
        assert!(second <= 0.002 && channels <= 0.002, "V differs: {second} (number 2), {channels} (channels)");
    }
    finish(e);
}

/// Sized to its penumbra (`penumbra_texels`): a plate 1 m up under a light of radius 0.5 at 6 m
/// casts a penumbra 0.2 m wide, 85 texels of the 1024² texture over its 2.4 m shadow, so the
/// textures are halved twice, and the centred penumbra, smooth across its width, stays where the
/// full texture puts it against the reference.
#[test]
fn a_wide_penumbra_keeps_its_accuracy_on_a_quarter_of_the_texture() {
    let s = plate(1.0, 1.0, 6.0, 0.5, 0.0, 1.5);
    let mut e = engine();
    let truth = reference(&mut e, &s, 128);
    let sized = render_with(&mut e, &s, "plateau", &[], 128);
    let full = render_with(&mut e, &s, "plateau", &[("penumbra_texels", "0")], 128);
    let quarter = render_with(&mut e, &s, "plateau", &[("penumbra_texels", "0"), ("texture_size", "256")], 128);
    finish(e);
    assert_eq!(largest_difference(&sized, &quarter), 0.0, "a quarter of the texture, as asked for outright");
    as_accurate_as(&sized, &full, &truth, "a quarter of the texture against the whole");
}
