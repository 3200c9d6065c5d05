//! The scene file (TOML, metres, right-handed, +Y up) of DESIGN.md §3. Unknown keys, missing
//! files and nonsense numbers are errors that name the file and the key or line.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use serde::Deserialize;

use super::read::{MAX_SCENE_BYTES, clip_lines, read_limited};
use super::{
    Camera, Ground, KnobSetting, Light, MAX_COORDINATE, MAX_TRIANGLES, Mesh, Object, RenderSettings, Scene, Transform,
    primitives,
};
use crate::error::{Error, Result};
use crate::geometry::Projection;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: CameraFile,
    light: LightFile,
    ground: Option<GroundFile>,
    #[serde(default, rename = "object")]
    objects: Vec<ObjectFile>,
    #[serde(default)]
    render: RenderFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFile {
    position: Triple,
    target: Triple,
    up: Option<Triple>,
    fov_y_deg: Option<f32>,
    ortho_half_height: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightFile {
    position: Triple,
    radius: f32,
    target: Option<Triple>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GroundFile {
    #[serde(default)]
    height: f32,
    #[serde(default = "default_half_size")]
    half_size: f32,
}

fn default_half_size() -> f32 {
    10.0
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug)]
#[serde(rename_all = "lowercase")]
enum Shape {
    Box,
    Sphere,
    Cylinder,
    Plate,
    Mesh,
    /// A trefoil knot tube of `triangles` triangles in the unit sphere: a mesh whose size is a
    /// parameter, for cost against triangle count.
    Knot,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum Scale {
    Uniform(f32),
    PerAxis(Triple),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectFile {
    shape: Shape,
    name: Option<String>,
    size: Option<Triple>,
    radius: Option<f32>,
    height: Option<f32>,
    mesh: Option<String>,
    triangles: Option<u32>,
    #[serde(default)]
    position: Triple,
    #[serde(default)]
    rotation_deg: Triple,
    scale: Option<Scale>,
    color: Option<Triple>,
    #[serde(default = "yes")]
    casts: bool,
    #[serde(default = "yes")]
    receives: bool,
}

fn yes() -> bool {
    true
}

/// Three numbers, exactly: a fixed-size array would ignore extra elements.
#[derive(Deserialize, Clone, Copy, Default)]
#[serde(try_from = "Vec<f32>")]
struct Triple([f32; 3]);

impl TryFrom<Vec<f32>> for Triple {
    type Error = String;

    fn try_from(v: Vec<f32>) -> std::result::Result<Self, String> {
        <[f32; 3]>::try_from(v.as_slice()).map(Triple).map_err(|_| format!("expected 3 numbers, got {}", v.len()))
    }
}

impl From<Triple> for Vec3 {
    fn from(t: Triple) -> Vec3 {
        Vec3::from(t.0)
    }
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RenderFile {
    width: Option<u32>,
    height: Option<u32>,
    technique: Option<toml::Spanned<String>>,
    #[serde(default)]
    params: BTreeMap<toml::Spanned<String>, toml::Value>,
}

/// Albedos for objects that name no color: distinct, mid-bright, linear RGB.
/// The fewest triangles a knot is made of: 3 segments around by 3 rings along, twice.
const MIN_KNOT_TRIANGLES: u32 = 18;

const PALETTE: [[f32; 3]; 6] = [
    [0.80, 0.30, 0.25],
    [0.25, 0.50, 0.80],
    [0.85, 0.70, 0.25],
    [0.35, 0.70, 0.40],
    [0.65, 0.40, 0.75],
    [0.80, 0.80, 0.80],
];

pub(super) fn load(path: &Path) -> Result<Scene> {
    let bytes = read_limited(path, MAX_SCENE_BYTES, "scene file")?;
    let text = String::from_utf8(bytes).map_err(|e| Error::scene(path, format!("not UTF-8 text: {e}")))?;
    parse(&text, path)
}

pub(super) fn parse(text: &str, path: &Path) -> Result<Scene> {
    // toml's message names the line, the column and the offending key.
    let file: SceneFile =
        toml::from_str(text).map_err(|e| Error::scene(path, clip_lines(e.to_string().trim_end(), 200)))?;
    let err = |what: String| Error::scene(path, what);
    let finite = |key: &str, v: Triple| -> Result<Vec3> {
        let v = Vec3::from(v);
        if v.is_finite() { Ok(v) } else { Err(err(format!("`{key}` must be finite numbers, got {v}"))) }
    };

    let c = &file.camera;
    let projection = match (c.fov_y_deg, c.ortho_half_height) {
        (Some(fov_y_deg), None) => Projection::Perspective { fov_y_deg },
        (None, Some(half_height)) => Projection::Orthographic { half_height },
        (None, None) => return Err(err("[camera] needs `fov_y_deg` (perspective) or `ortho_half_height`".into())),
        (Some(_), Some(_)) => return Err(err("[camera] takes `fov_y_deg` or `ortho_half_height`, not both".into())),
    };
    let camera = Camera {
        position: finite("camera.position", c.position)?,
        target: finite("camera.target", c.target)?,
        up: finite("camera.up", c.up.unwrap_or(Triple([0.0, 1.0, 0.0])))?,
        projection,
    };
    let light = Light {
        position: finite("light.position", file.light.position)?,
        radius: file.light.radius,
        target: file.light.target.map(|t| finite("light.target", t)).transpose()?,
    };
    let ground = file.ground.map(|g| Ground { height: g.height, half_size: g.half_size });

    let base = path.parent().unwrap_or(Path::new("."));
    let objects = file
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let name = o.name.clone().unwrap_or_else(|| format!("{:?}", o.shape).to_lowercase());
            object(o, i, base).map_err(|what| err(format!("[[object]] {} ({name}): {what}", i + 1)))
        })
        .collect::<Result<Vec<_>>>()?;

    // The technique and its knobs are checked by the frame settings, which know the
    // techniques; the lines kept here let them name where a typo is.
    let line = |span: std::ops::Range<usize>| text[..span.start.min(text.len())].matches('\n').count() + 1;
    let defaults = RenderSettings::default();
    let technique_line = file.render.technique.as_ref().map(|t| line(t.span()));
    let render = RenderSettings {
        width: file.render.width.unwrap_or(defaults.width),
        height: file.render.height.unwrap_or(defaults.height),
        technique: file.render.technique.map_or(defaults.technique, toml::Spanned::into_inner),
        params: file
            .render
            .params
            .iter()
            .map(|(k, v)| {
                let value = match v {
                    toml::Value::Integer(n) => n.to_string(),
                    toml::Value::Float(x) => x.to_string(),
                    toml::Value::String(s) => s.clone(),
                    other => {
                        let k = k.get_ref();
                        let what =
                            format!("[render.params] `{k}` must be a number or a string, got {}", other.type_str());
                        return Err(err(what));
                    }
                };
                Ok(KnobSetting { key: k.get_ref().clone(), value, line: Some(line(k.span())) })
            })
            .collect::<Result<_>>()?,
        source: Some(path.to_path_buf()),
        technique_line,
    };

    let scene = Scene { camera, light, ground, objects, render };
    scene.validate().map_err(|e| err(e.to_string()))?;
    Ok(scene)
}

/// Builds one object; the error text is prefixed with the object's position in the file.
fn object(o: &ObjectFile, index: usize, base: &Path) -> std::result::Result<Object, String> {
    let unused = |keys: &[(&str, bool)]| -> std::result::Result<(), String> {
        match keys.iter().find(|(_, set)| *set) {
            Some((key, _)) => Err(format!("`{key}` does not apply to this shape")),
            None => Ok(()),
        }
    };
    let positive = |key: &str, v: Option<f32>| -> std::result::Result<f32, String> {
        let v = v.ok_or(format!("needs `{key}`"))?;
        if v > 0.0 && v <= MAX_COORDINATE {
            Ok(v)
        } else {
            Err(format!("`{key}` must lie in (0, {MAX_COORDINATE:e}] m, got {v}"))
        }
    };
    let (size, radius, height, mesh_key) = (o.size.is_some(), o.radius.is_some(), o.height.is_some(), o.mesh.is_some());
    let triangles = o.triangles.is_some();
    let mesh = match o.shape {
        Shape::Box | Shape::Plate => {
            unused(&[("radius", radius), ("height", height), ("mesh", mesh_key), ("triangles", triangles)])?;
            let s = Vec3::from(o.size.ok_or("needs `size = [x, y, z]`")?);
            // A plate may be infinitely thin; a box may not.
            let min_y = if o.shape == Shape::Plate { 0.0 } else { f32::MIN_POSITIVE };
            if !(s.max_element() <= MAX_COORDINATE && s.x > 0.0 && s.z > 0.0 && s.y >= min_y) {
                return Err(format!(
                    "`size` must be positive (a plate's y may be 0) and at most {MAX_COORDINATE:e} m, got {s}"
                ));
            }
            primitives::cuboid(s)
        }
        Shape::Sphere => {
            unused(&[("size", size), ("height", height), ("mesh", mesh_key), ("triangles", triangles)])?;
            primitives::sphere(positive("radius", o.radius)?)
        }
        Shape::Cylinder => {
            unused(&[("size", size), ("mesh", mesh_key), ("triangles", triangles)])?;
            primitives::cylinder(positive("radius", o.radius)?, positive("height", o.height)?)
        }
        Shape::Mesh => {
            unused(&[("size", size), ("radius", radius), ("height", height), ("triangles", triangles)])?;
            let rel = o.mesh.as_ref().ok_or("needs `mesh = \"path.obj\"`")?;
            Mesh::load_obj(&base.join(rel))
        }
        Shape::Knot => {
            unused(&[("size", size), ("radius", radius), ("height", height), ("mesh", mesh_key)])?;
            let n = o.triangles.ok_or("needs `triangles = N`")?;
            if !(MIN_KNOT_TRIANGLES..=MAX_TRIANGLES as u32).contains(&n) {
                return Err(format!("`triangles` must lie in {MIN_KNOT_TRIANGLES}..={MAX_TRIANGLES}, got {n}"));
            }
            primitives::knot(n)
        }
    }
    .map_err(|e| e.to_string())?;
    let scale = match o.scale {
        None => Vec3::ONE,
        Some(Scale::Uniform(s)) => Vec3::splat(s),
        Some(Scale::PerAxis(s)) => Vec3::from(s),
    };
    let transform = Transform { position: Vec3::from(o.position), rotation_deg: Vec3::from(o.rotation_deg), scale };
    let name = o.name.clone().unwrap_or_else(|| format!("{}{}", mesh.name, index + 1));
    Ok(Object {
        name,
        mesh: Arc::new(mesh),
        transform,
        color: o.color.map_or(Vec3::from(PALETTE[index % PALETTE.len()]), Vec3::from),
        casts: o.casts,
        receives: o.receives,
        sphere_radius: if o.shape == Shape::Sphere { o.radius } else { None },
    })
}
