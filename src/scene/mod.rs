//! Pure scene data: the TOML format of DESIGN.md §3, meshes and their edge adjacency.

mod file;
mod mesh;
pub mod primitives;
mod read;

use std::path::PathBuf;
use std::sync::Arc;

use glam::{EulerRot, Mat3, Mat4, Quat, Vec3};

use crate::error::{Error, Result};
use crate::geometry::Aabb;
pub use crate::geometry::Projection;
pub use crate::geometry::{Edge, EdgeAdjacency, NO_FACE};
pub use mesh::{MAX_TRIANGLES, Mesh, MeshId, Vertex};
pub use read::{MAX_OBJ_BYTES, MAX_OBJ_LINE, MAX_SCENE_BYTES};

/// How far from the origin any point of a scene may lie, in metres (a million kilometres):
/// room for a light 1e8 m away, while squared distances stay far inside f32's range. Scene
/// files and game loops are checked against it.
pub const MAX_COORDINATE: f32 = 1e9;

/// Where the camera is and how it projects.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub projection: Projection,
}

/// A spherical area light; radius 0 is a point light.
#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub position: Vec3,
    pub radius: f32,
    /// Where a spot frustum looks; `None`: the casters' centre.
    pub target: Option<Vec3>,
}

/// The receiver plane y = `height`, normal +Y, a square of side 2 × `half_size`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    pub height: f32,
    pub half_size: f32,
}

/// Position, rotation (right-handed Euler degrees, R = Rz·Ry·Rx) and scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    pub position: Vec3,
    pub rotation_deg: Vec3,
    pub scale: Vec3,
}

impl Default for Transform {
    fn default() -> Self {
        Transform { position: Vec3::ZERO, rotation_deg: Vec3::ZERO, scale: Vec3::ONE }
    }
}

impl Transform {
    pub fn matrix(&self) -> Mat4 {
        let r = self.rotation_deg.map(f32::to_radians);
        // X first, then Y, then Z: R = Rz·Ry·Rx.
        let rotation = Quat::from_euler(EulerRot::ZYX, r.z, r.y, r.x);
        Mat4::from_scale_rotation_translation(self.scale, rotation, self.position)
    }
}

/// One mesh instance in the scene.
#[derive(Clone, Debug)]
pub struct Object {
    pub name: String,
    pub mesh: Arc<Mesh>,
    pub transform: Transform,
    /// Linear RGB albedo.
    pub color: Vec3,
    pub casts: bool,
    pub receives: bool,
    /// The mesh tessellates a sphere of this radius about the object's origin (`shape =
    /// "sphere"`): techniques that can treat spheres exactly may.
    pub sphere_radius: Option<f32>,
}

impl Object {
    pub fn new(name: impl Into<String>, mesh: Arc<Mesh>) -> Self {
        Object {
            name: name.into(),
            mesh,
            transform: Transform::default(),
            color: Vec3::splat(0.8),
            casts: true,
            receives: true,
            sphere_radius: None,
        }
    }

    /// The exact sphere (world centre, radius) this object stands for, when it is one and its
    /// scale is uniform.
    pub fn sphere(&self) -> Option<(Vec3, f32)> {
        let s = self.transform.scale;
        let uniform = (s.x - s.y).abs() <= 1e-6 * s.x && (s.x - s.z).abs() <= 1e-6 * s.x;
        self.sphere_radius.filter(|_| uniform).map(|r| (self.transform.position, r * s.x))
    }

    /// World-space bounds of the transformed mesh.
    pub fn bounds(&self) -> Aabb {
        self.mesh.bounds.transformed(&self.transform.matrix())
    }

    /// The normal matrix (inverse transpose of the model's 3×3).
    pub fn normal_matrix(&self) -> Mat3 {
        Mat3::from_mat4(self.transform.matrix()).inverse().transpose()
    }
}

/// Image size and technique as the scene file gives them; the command line may override.
/// The technique and its knobs are text here: the frame settings check them.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub technique: String,
    /// `[render.params]`, in key order.
    pub params: Vec<KnobSetting>,
    /// The scene file these came from, and the line of `technique` in it: where an unknown
    /// technique or knob is reported.
    pub source: Option<PathBuf>,
    pub technique_line: Option<usize>,
}

/// One `[render.params]` entry: a knob's name and value as text, and its line in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct KnobSetting {
    pub key: String,
    pub value: String,
    pub line: Option<usize>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            width: 512,
            height: 512,
            technique: "shadow-map".into(),
            params: Vec::new(),
            source: None,
            technique_line: None,
        }
    }
}

/// Everything a frame shows: casters, receivers, one light, one camera.
#[derive(Clone, Debug)]
pub struct Scene {
    pub camera: Camera,
    pub light: Light,
    pub ground: Option<Ground>,
    pub objects: Vec<Object>,
    pub render: RenderSettings,
}

impl Scene {
    /// Loads a scene file; meshes resolve relative to its folder.
    pub fn load(path: impl AsRef<std::path::Path>) -> Result<Scene> {
        file::load(path.as_ref())
    }

    /// Parses scene text; `path` names the file in messages and anchors mesh paths.
    pub fn from_toml(text: &str, path: impl AsRef<std::path::Path>) -> Result<Scene> {
        file::parse(text, path.as_ref())
    }

    /// Checks what a game loop may have changed since loading: every number finite and within
    /// [`MAX_COORDINATE`], sizes positive, the camera well defined, the light above the ground.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: String| Err(Error::Invalid(what));
        let c = &self.camera;
        let mut points = vec![
            ("camera.position", c.position),
            ("camera.target", c.target),
            ("camera.up", c.up),
            ("light.position", self.light.position),
        ];
        points.extend(self.light.target.map(|t| ("light.target", t)));
        for (name, v) in points {
            if !(v.is_finite() && v.abs().max_element() <= MAX_COORDINATE) {
                return bad(format!("`{name}` must be finite numbers within ±{MAX_COORDINATE:e} m, got {v}"));
            }
        }
        let forward = c.target - c.position;
        if forward.length_squared() == 0.0 {
            return bad("camera.position and camera.target coincide".into());
        }
        if c.up.length_squared() == 0.0 {
            return bad("camera.up has zero length".into());
        }
        if forward.normalize().cross(c.up.normalize()).length() < 1e-4 {
            return bad("camera.up is parallel to the view direction".into());
        }
        match c.projection {
            Projection::Perspective { fov_y_deg } if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) => {
                return bad(format!("camera.fov_y_deg must lie in (0, 180), got {fov_y_deg}"));
            }
            Projection::Orthographic { half_height } if !(half_height > 0.0 && half_height.is_finite()) => {
                return bad(format!("camera.ortho_half_height must be positive, got {half_height}"));
            }
            _ => {}
        }
        let l = &self.light;
        if !(l.radius >= 0.0 && l.radius.is_finite()) {
            return bad(format!("light.radius must be zero or positive, got {}", l.radius));
        }
        if l.radius > MAX_COORDINATE {
            return bad(format!("`light.radius` must be at most {MAX_COORDINATE:e} m, got {}", l.radius));
        }
        if let Some(g) = &self.ground {
            if !(g.height.is_finite() && g.height.abs() <= MAX_COORDINATE) {
                return bad(format!(
                    "`ground.height` must be a finite number within ±{MAX_COORDINATE:e} m, got {}",
                    g.height
                ));
            }
            if !(g.half_size > 0.0 && g.half_size <= MAX_COORDINATE) {
                return bad(format!("`ground.half_size` must lie in (0, {MAX_COORDINATE:e}] m, got {}", g.half_size));
            }
            if l.position.y - l.radius <= g.height {
                return bad(format!(
                    "the light (centre y = {}, radius {}) is inside the ground (y = {})",
                    l.position.y, l.radius, g.height
                ));
            }
        }
        for (i, o) in self.objects.iter().enumerate() {
            let t = &o.transform;
            let object = |what: String| bad(format!("[[object]] {} ({}): {what}", i + 1, o.name));
            for (key, v) in [("position", t.position), ("rotation_deg", t.rotation_deg)] {
                if !(v.is_finite() && v.abs().max_element() <= MAX_COORDINATE) {
                    return object(format!("`{key}` must be finite numbers within ±{MAX_COORDINATE:e}, got {v}"));
                }
            }
            // An albedo: the fraction of light reflected.
            if !(o.color.cmpge(Vec3::ZERO).all() && o.color.cmple(Vec3::ONE).all()) {
                return object(format!("`color` must lie in [0, 1], got {}", o.color));
            }
            if !(t.scale.is_finite() && t.scale.cmpgt(Vec3::ZERO).all()) {
                return object(format!("`scale` must be positive, got {}", t.scale));
            }
            let bounds = o.bounds();
            let reach = bounds.min.abs().max(bounds.max.abs()).max_element();
            if reach > MAX_COORDINATE {
                return object(format!(
                    "reaches {reach:e} m from the origin (position {}, scale {}): the limit is ±{MAX_COORDINATE:e} m",
                    t.position, t.scale
                ));
            }
        }
        if self.render.width == 0 || self.render.height == 0 {
            return bad(format!("render size {}x{} is empty", self.render.width, self.render.height));
        }
        Ok(())
    }
}

impl Ground {
    pub fn bounds(&self) -> Aabb {
        let h = self.half_size;
        Aabb { min: Vec3::new(-h, self.height, -h), max: Vec3::new(h, self.height, h) }
    }
}
