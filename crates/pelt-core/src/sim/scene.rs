//! Scene scripts: wind that changes over time and touch strokes, in TOML, so a render can
//! reproduce an interaction frame by frame.
//!
//! ```toml
//! duration_secs = 6.0              # optional; default: the last key or stroke end
//!
//! [[wind]]                         # keyframes, sorted by time, linearly interpolated
//! time_secs = 0.0
//! direction = [1.0, 0.0, 0.0]      # any non-zero vector; directions are blended, then normalised
//! strength = 0.0
//! gust_strength = 0.5              # optional (default 0.5), 0..=1
//! jitter = 0.1                     # optional (default 0.1), 0..=1
//!
//! [[stroke]]                       # a touch: pressed at path[0], dragged along the path
//! start_secs = 1.0
//! end_secs = 2.0
//! radius = 0.8                     # world units
//! path = [[0.0, 5.0, 2.6], [0.0, 3.5, 2.6]]
//!
//! [[motion]]                       # rigid motion of the meshes, see `sim::motion`
//! time_secs = 0.0
//! translation = [0.0, 0.0, 0.0]
//! rotation_deg = [0.0, 0.0, 0.0]
//! ease = "in_out"
//!
//! [[collider]]                     # a collider on keyframed poses (see `sim::contact`)
//! shape = { kind = "sphere", radius = 0.5 }   # or capsule (radius, half_length), box
//!                                  # (half_extents), plane (local +Y up), mesh (path: a closed
//!                                  # mesh file beside the script, resolution = 32 cells of its
//!                                  # field along its longest side, scale = 1)
//! friction = 0.3                   # optional (default 0.3), 0..=1
//! appear_secs = 0.25               # optional: grows in over this after its first key
//! keys = [{ time_secs = 0.0, position = [0.0, 5.0, 2.0], rotation_deg = [0.0, 0.0, 0.0] }]
//!
//! [[grasp]]                        # a hand closes at path[0], moves along the path, lets go
//! start_secs = 1.0
//! end_secs = 3.0
//! radius = 0.5                     # strands rooted within this are gathered
//! hand_radius = 0.2                # optional (default 0): the hand's size (fingers, thumb,
//!                                  # palm about the grip), pushing the strands it does not hold
//! path = [[0.0, 5.2, 2.6], [0.0, 6.0, 2.6]]
//! close_secs = 0.3                 # optional, and spring_hz (2) and damping (0.35) likewise
//!
//! [[rain]]                         # a shower, see `wet::RainKey`
//! start_secs = 0.0
//! end_secs = 4.0
//! direction = [0.0, -1.0, 0.0]
//! rate = 0.4                       # wetness per second facing the rain, 0..=100
//!
//! [[water]]                        # water level keys, see `wet::WaterKey`
//! time_secs = 0.0
//! point = [0.0, -1.0, 0.0]
//! normal = [0.0, 1.0, 0.0]
//!
//! [[light]]                        # lights, keyed over time by name (see `light::LightSpec`)
//! name = "key"
//! time_secs = 0.0
//! kind = "directional"             # or "point", "spot"
//! azimuth_deg = 30.0
//! elevation_deg = 40.0
//! lux = 1.0
//!
//! [environment]                    # light from every direction (see `light::EnvironmentSpec`)
//! sky = [0.4, 0.45, 0.5]
//! ground = [0.15, 0.13, 0.1]       # or image = "studio.hdr"
//!
//! [camera]                         # optional: where `pelt render` looks from (unless --camera)
//! target = [2.8, 5.9, 0.2]         # optional: default the meshes' centre
//! azimuth_deg = 60.0               # around +Y from +Z toward +X
//! elevation_deg = 35.0
//! distance = 8.0                   # optional: default the meshes framed
//!
//! [[instance]]                     # a herd: one copy of the fur per table (see `sim::herd`)
//! position = [0.0, 0.0, 0.0]
//! heading_deg = 90.0
//! speed = 30.0
//! clip = "Walk"
//! time_offset_secs = 0.4
//!
//! [ground]                         # optional: a plane under the meshes that takes their shadow
//! height = -1.0                    # optional: default just under the meshes
//! size = 6.0                       # optional: side length; default 4 times the meshes' radius
//! colour = [0.35, 0.33, 0.3]       # optional: linear RGB
//! ```
//!
//! Stroke points are world positions, on or near the base surface, which keeps a script
//! independent of any camera. The touch begins at `path[0]` (it affects the roots within
//! `radius`); the pointer then moves along the polyline at one path segment per equal share of
//! the stroke's time. Wind settings not in a key (gust size and speed, seed, jitter rate) come
//! from the simulation's parameters.
//!
//! Drive it as `scene.apply(t, &mut sim)?; sim.advance_to(t);` every frame; with `[[motion]]`
//! keys, move the base with [`Scene::motion_at`] first (`Simulation::set_base_rotations`), and
//! draw the plain meshes with the same transform.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{EulerRot, Mat4, Quat, Vec3};

use super::MAX_FORCE;
use super::contact::{Collider, ColliderKey, ColliderMesh, GraspParams, Shape};
use super::herd::{self, HerdInstance};
use super::motion::{self, MotionKey};
use super::simulation::{SimError, Simulation};
use crate::light::{self, Environment, EnvironmentError, EnvironmentSpec, LightSource, LightSpec};
use crate::mesh::{ImportOptions, Mesh};
use crate::wet::{self, RainKey, WaterKey, WetSources};

/// Errors from reading a scene; each names the file and, where it can, the key.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{}: cannot read the file: {source}", file.display())]
    Io {
        /// The scene file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not valid TOML or has unknown keys.
    #[error("{}: {message}", file.display())]
    Parse {
        /// The scene file.
        file: PathBuf,
        /// toml's message.
        message: String,
    },
    /// A value out of range.
    #[error("{}: {key}: {problem}", file.display())]
    Invalid {
        /// The scene file.
        file: PathBuf,
        /// The key.
        key: String,
        /// What is wrong with it.
        problem: String,
    },
}

/// Ids of a script's colliders (`[[collider]]` `i` is this plus `i`), apart from a host's.
pub const SCENE_COLLIDER_IDS: u32 = 0x5c00_0000;

/// One wind keyframe.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindKey {
    /// When this key applies (seconds of scene time).
    pub time_secs: f64,
    /// Direction the wind blows toward.
    pub direction: Vec3,
    /// Wind strength.
    pub strength: f32,
    /// Strength of travelling gusts, relative to `strength` (default 0.5).
    #[serde(default = "default_gust_strength")]
    pub gust_strength: f32,
    /// Fast random shake, relative to `strength` (default 0.1).
    #[serde(default = "default_jitter")]
    pub jitter: f32,
}

fn default_gust_strength() -> f32 {
    0.5
}

fn default_jitter() -> f32 {
    0.1
}

/// One touch stroke: pressed at `path[0]` at `start_secs`, dragged along `path`, released at
/// `end_secs`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stroke {
    /// When the touch presses (seconds of scene time).
    pub start_secs: f64,
    /// When it releases.
    pub end_secs: f64,
    /// Radius of the touch (world units).
    pub radius: f32,
    /// World points; the first is the hit point.
    pub path: Vec<Vec3>,
}

impl Stroke {
    /// The pointer position at `time_secs` (clamped to the stroke's span).
    #[must_use]
    pub fn point_at(&self, time_secs: f64) -> Vec3 {
        let segments = self.path.len() - 1;
        if segments == 0 {
            return self.path[0];
        }
        let fraction = ((time_secs - self.start_secs) / (self.end_secs - self.start_secs)).clamp(0.0, 1.0);
        let along = fraction * segments as f64;
        let k = (along.floor() as usize).min(segments - 1);
        let t = (along - k as f64) as f32;
        self.path[k] * (1.0 - t) + self.path[k + 1] * t
    }
}

/// One pose of a scripted collider.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneColliderKey {
    /// When (seconds of scene time).
    pub time_secs: f64,
    /// The collider's centre.
    pub position: Vec3,
    /// Turns about X, Y and Z in degrees (applied Y, X, Z, as `[[motion]]`).
    #[serde(default)]
    pub rotation_deg: Vec3,
}

/// A scripted collider's shape: [`Shape`]'s, with a mesh named by its file.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SceneShape {
    /// [`Shape::Sphere`].
    Sphere {
        /// World units.
        radius: f32,
    },
    /// [`Shape::Capsule`].
    Capsule {
        /// World units.
        radius: f32,
        /// Half the segment's length.
        half_length: f32,
    },
    /// [`Shape::Box`].
    Box {
        /// Half its size along the local axes.
        half_extents: Vec3,
    },
    /// [`Shape::Plane`].
    Plane,
    /// [`Shape::Mesh`]: a closed mesh file, baked when the script loads.
    Mesh {
        /// The mesh file (`.obj`, `.gltf`, `.glb`), relative to the script's folder.
        path: PathBuf,
        /// Cells of its distance field along its longest side (default 32).
        #[serde(default = "default_mesh_resolution")]
        resolution: usize,
        /// Uniform scale (default 1).
        #[serde(default = "default_mesh_scale")]
        scale: f32,
        /// The mesh and its field, once loaded ([`Scene::load`], [`Scene::from_toml_str`]).
        #[serde(skip)]
        baked: Option<Arc<ColliderMesh>>,
    },
}

fn default_mesh_resolution() -> usize {
    32
}

fn default_mesh_scale() -> f32 {
    1.0
}

/// Most cells a script's mesh field may have along its longest side (the bake's cost grows
/// with their cube).
const MAX_MESH_RESOLUTION: usize = 128;

impl SceneShape {
    /// The collider's shape; `None` for a mesh not loaded.
    #[must_use]
    pub fn shape(&self) -> Option<Shape> {
        Some(match self {
            Self::Sphere { radius } => Shape::Sphere { radius: *radius },
            Self::Capsule { radius, half_length } => Shape::Capsule { radius: *radius, half_length: *half_length },
            Self::Box { half_extents } => Shape::Box { half_extents: *half_extents },
            Self::Plane => Shape::Plane,
            Self::Mesh { scale, baked, .. } => Shape::Mesh { mesh: Arc::clone(baked.as_ref()?), scale: *scale },
        })
    }

    /// Loads and bakes a mesh shape's file, `path` relative to `folder`; the others are left.
    ///
    /// # Errors
    /// `(key, problem)`: the problem names the mesh file (it cannot be read, is not closed, ...).
    fn load(&mut self, folder: &Path) -> Result<(), (String, String)> {
        let Self::Mesh { path, resolution, baked, .. } = self else { return Ok(()) };
        let file = folder.join(&*path);
        if !(2..=MAX_MESH_RESOLUTION).contains(resolution) {
            return Err((
                "shape.resolution".into(),
                format!("must be between 2 and {MAX_MESH_RESOLUTION}, got {resolution}"),
            ));
        }
        let (mesh, _) =
            Mesh::load(&file, &ImportOptions::default()).map_err(|e| ("shape.path".into(), e.to_string()))?;
        let mesh = ColliderMesh::new(mesh, *resolution)
            .map_err(|e| ("shape.path".to_owned(), format!("{}: {e}", file.display())))?;
        *baked = Some(Arc::new(mesh));
        Ok(())
    }
}

/// A scripted collider (`[[collider]]`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneCollider {
    /// Its shape.
    pub shape: SceneShape,
    /// See [`Collider::friction`] (default 0.3).
    #[serde(default = "default_friction")]
    pub friction: f32,
    /// See [`Collider::appear_secs`] (default 0.25).
    #[serde(default = "default_appear_secs")]
    pub appear_secs: f32,
    /// Poses, sorted by time.
    pub keys: Vec<SceneColliderKey>,
}

fn default_friction() -> f32 {
    0.3
}

fn default_appear_secs() -> f32 {
    0.25
}

impl SceneCollider {
    /// The collider it describes, with `id`; `None` for a mesh not loaded.
    #[must_use]
    pub fn collider(&self, id: u32) -> Option<Collider> {
        let keys = self
            .keys
            .iter()
            .map(|k| {
                let r = k.rotation_deg * (std::f32::consts::PI / 180.0);
                ColliderKey {
                    time_secs: k.time_secs,
                    position: k.position,
                    rotation: Quat::from_euler(EulerRot::YXZ, r.y, r.x, r.z),
                }
            })
            .collect();
        Some(Collider {
            id,
            shape: self.shape.shape()?,
            keys,
            friction: self.friction,
            appear_secs: self.appear_secs,
            appeared_secs: None,
        })
    }
}

/// A scripted grasp (`[[grasp]]`): the hand closes at `path[0]` at `start_secs`, the grip moves
/// along `path` until `end_secs`, then lets go.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneGrasp {
    /// When the hand closes.
    pub start_secs: f64,
    /// When it lets go.
    pub end_secs: f64,
    /// Strands rooted within this distance of `path[0]` are gathered.
    pub radius: f32,
    /// The size of the hand about the grip (fingers, thumb and palm, see
    /// [`Grasp::hand`](super::contact::Grasp::hand)) that pushes the strands it does not hold
    /// (default 0: none).
    #[serde(default)]
    pub hand_radius: f32,
    /// World points of the grip, at one segment per equal share of the hold.
    pub path: Vec<Vec3>,
    /// See [`GraspParams::close_secs`].
    #[serde(default = "default_close_secs")]
    pub close_secs: f32,
    /// See [`GraspParams::spring_hz`].
    #[serde(default = "default_spring_hz")]
    pub spring_hz: f32,
    /// See [`GraspParams::damping`].
    #[serde(default = "default_grasp_damping")]
    pub damping: f32,
}

fn default_close_secs() -> f32 {
    GraspParams::default().close_secs
}

fn default_spring_hz() -> f32 {
    GraspParams::default().spring_hz
}

fn default_grasp_damping() -> f32 {
    GraspParams::default().damping
}

impl SceneGrasp {
    /// Its closing and spring-back.
    #[must_use]
    pub fn params(&self) -> GraspParams {
        GraspParams { close_secs: self.close_secs, spring_hz: self.spring_hz, damping: self.damping }
    }

    /// The grip at `time_secs` (clamped to the hold).
    #[must_use]
    pub fn grip_at(&self, time_secs: f64) -> Vec3 {
        Stroke { start_secs: self.start_secs, end_secs: self.end_secs, radius: self.radius, path: self.path.clone() }
            .point_at(time_secs)
    }
}

/// The camera a scene is seen from (`[camera]`): an orbit about `target`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneCamera {
    /// The point looked at; default the centre of the meshes.
    #[serde(default)]
    pub target: Option<Vec3>,
    /// Turn around +Y from +Z toward +X, degrees.
    pub azimuth_deg: f32,
    /// Lift toward +Y, degrees, -89 to 89.
    pub elevation_deg: f32,
    /// From the target, world units; default: the meshes framed.
    #[serde(default)]
    pub distance: Option<f32>,
}

/// The ground of a scene (`[ground]`): a square plane, level in y, under the meshes.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneGround {
    /// Its y; default just under the meshes.
    #[serde(default)]
    pub height: Option<f32>,
    /// Its side length; default four times the meshes' bounding radius.
    #[serde(default)]
    pub size: Option<f32>,
    /// Linear RGB, each 0 to 1; default a warm grey.
    #[serde(default)]
    pub colour: Option<Vec3>,
}

/// A parsed, validated scene script.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Length of the scene; default the last keyframe or stroke end.
    #[serde(default)]
    pub duration_secs: Option<f64>,
    /// Wind keyframes, sorted by time.
    #[serde(default)]
    pub wind: Vec<WindKey>,
    /// Touch strokes.
    #[serde(default, rename = "stroke")]
    pub strokes: Vec<Stroke>,
    /// Rigid motion keyframes of the meshes, sorted by time.
    #[serde(default)]
    pub motion: Vec<MotionKey>,
    /// Colliders on keyframed poses.
    #[serde(default, rename = "collider")]
    pub colliders: Vec<SceneCollider>,
    /// Grasps.
    #[serde(default, rename = "grasp")]
    pub grasps: Vec<SceneGrasp>,
    /// Showers.
    #[serde(default)]
    pub rain: Vec<RainKey>,
    /// Water level keyframes, sorted by time.
    #[serde(default)]
    pub water: Vec<WaterKey>,
    /// The camera; default: the host's own.
    #[serde(default)]
    pub camera: Option<SceneCamera>,
    /// A ground under the meshes; default none (unless the host draws one).
    #[serde(default)]
    pub ground: Option<SceneGround>,
    /// Light keys: each unnamed table a light, each name's tables one light over time.
    #[serde(default)]
    pub light: Vec<LightSpec>,
    /// The environment's table; default: the host's own.
    #[serde(default)]
    pub environment: Option<EnvironmentSpec>,
    /// A herd: one copy of the fur per table, each placed and phased on its own; none draws the
    /// one fur as usual.
    #[serde(default)]
    pub instance: Vec<HerdInstance>,
    /// The environment the table describes, loaded with the script.
    #[serde(skip)]
    pub environment_light: Option<Environment>,
}

impl Scene {
    /// Reads and validates a scene file.
    ///
    /// # Errors
    /// [`SceneError`] naming the file, and the key for bad values.
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let text =
            std::fs::read_to_string(path).map_err(|source| SceneError::Io { file: path.to_path_buf(), source })?;
        Self::from_toml_str(&text, path)
    }

    /// Parses and validates scene text; `name` stands in for the file name in errors.
    ///
    /// # Errors
    /// [`SceneError::Parse`] for TOML or type errors (the message shows the key and line),
    /// [`SceneError::Invalid`] for values out of range.
    pub fn from_toml_str(text: &str, name: &Path) -> Result<Self, SceneError> {
        let mut scene: Self = toml::from_str(text).map_err(|e| SceneError::Parse {
            file: name.to_path_buf(),
            message: e.to_string().trim_end().to_owned(),
        })?;
        let folder = name.parent().unwrap_or(Path::new(""));
        for (i, collider) in scene.colliders.iter_mut().enumerate() {
            collider.shape.load(folder).map_err(|(key, problem)| SceneError::Invalid {
                file: name.to_path_buf(),
                key: format!("collider[{i}].{key}"),
                problem,
            })?;
        }
        scene.validate().map_err(|(key, problem)| SceneError::Invalid { file: name.to_path_buf(), key, problem })?;
        if let Some(spec) = &scene.environment {
            let environment = Environment::from_spec(spec, folder).map_err(|error| match error {
                EnvironmentError::Invalid { key, problem } => {
                    SceneError::Invalid { file: name.to_path_buf(), key, problem }
                }
                image @ EnvironmentError::Image { .. } => SceneError::Invalid {
                    file: name.to_path_buf(),
                    key: "environment.image".into(),
                    problem: image.to_string(),
                },
            })?;
            scene.environment_light = Some(environment);
        }
        Ok(scene)
    }

    fn validate(&self) -> Result<(), (String, String)> {
        let finite_time = |key: String, value: f64| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err((key, format!("must be finite and at least 0, got {value}")))
            }
        };
        let range = |key: String, value: f32, low: f32, high: f32| {
            if value.is_finite() && (low..=high).contains(&value) {
                Ok(())
            } else {
                Err((key, format!("must be between {low} and {high}, got {value}")))
            }
        };
        if let Some(duration) = self.duration_secs {
            finite_time("duration_secs".into(), duration)?;
        }
        for (i, key) in self.wind.iter().enumerate() {
            finite_time(format!("wind[{i}].time_secs"), key.time_secs)?;
            if i > 0 && key.time_secs < self.wind[i - 1].time_secs {
                return Err((format!("wind[{i}].time_secs"), "keyframes must be sorted by time".into()));
            }
            if !key.direction.is_finite() || key.direction.length_squared() == 0.0 {
                return Err((
                    format!("wind[{i}].direction"),
                    format!("must be a finite non-zero vector, got {}", key.direction),
                ));
            }
            range(format!("wind[{i}].strength"), key.strength, 0.0, MAX_FORCE)?;
            range(format!("wind[{i}].gust_strength"), key.gust_strength, 0.0, 1.0)?;
            range(format!("wind[{i}].jitter"), key.jitter, 0.0, 1.0)?;
        }
        motion::validate(&self.motion)?;
        light::validate_keys(&self.light)?;
        wet::validate(&self.rain, &self.water)?;
        herd::validate(&self.instance)?;
        for (i, stroke) in self.strokes.iter().enumerate() {
            finite_time(format!("stroke[{i}].start_secs"), stroke.start_secs)?;
            finite_time(format!("stroke[{i}].end_secs"), stroke.end_secs)?;
            if stroke.end_secs <= stroke.start_secs {
                return Err((format!("stroke[{i}].end_secs"), "must be later than start_secs".into()));
            }
            range(format!("stroke[{i}].radius"), stroke.radius, f32::MIN_POSITIVE, f32::MAX)?;
            if stroke.path.is_empty() {
                return Err((format!("stroke[{i}].path"), "needs at least one point".into()));
            }
            if let Some(k) = stroke.path.iter().position(|p| !p.is_finite()) {
                return Err((format!("stroke[{i}].path[{k}]"), "must be finite".into()));
            }
        }
        for (i, collider) in self.colliders.iter().enumerate() {
            if collider.keys.iter().any(|k| !k.rotation_deg.is_finite()) {
                let k = collider.keys.iter().position(|k| !k.rotation_deg.is_finite()).unwrap_or(0);
                return Err((format!("collider[{i}].keys[{k}].rotation_deg"), "must be finite".into()));
            }
            collider
                .collider(i as u32)
                .ok_or_else(|| ("shape".to_owned(), "the mesh is not loaded".to_owned()))?
                .validate()
                .map_err(|(key, problem)| (format!("collider[{i}].{key}"), problem))?;
        }
        for (i, grasp) in self.grasps.iter().enumerate() {
            finite_time(format!("grasp[{i}].start_secs"), grasp.start_secs)?;
            finite_time(format!("grasp[{i}].end_secs"), grasp.end_secs)?;
            if grasp.end_secs <= grasp.start_secs {
                return Err((format!("grasp[{i}].end_secs"), "must be later than start_secs".into()));
            }
            range(format!("grasp[{i}].radius"), grasp.radius, f32::MIN_POSITIVE, f32::MAX)?;
            range(format!("grasp[{i}].hand_radius"), grasp.hand_radius, 0.0, f32::MAX)?;
            if grasp.path.is_empty() {
                return Err((format!("grasp[{i}].path"), "needs at least one point".into()));
            }
            if let Some(k) = grasp.path.iter().position(|p| !p.is_finite()) {
                return Err((format!("grasp[{i}].path[{k}]"), "must be finite".into()));
            }
            grasp.params().validate().map_err(|(key, problem)| (format!("grasp[{i}].{key}"), problem))?;
        }
        if let Some(camera) = &self.camera {
            if camera.target.is_some_and(|t| !t.is_finite()) {
                return Err(("camera.target".into(), "must be finite".into()));
            }
            range("camera.azimuth_deg".into(), camera.azimuth_deg, -3600.0, 3600.0)?;
            range("camera.elevation_deg".into(), camera.elevation_deg, -89.0, 89.0)?;
            if let Some(distance) = camera.distance {
                range("camera.distance".into(), distance, f32::MIN_POSITIVE, f32::MAX)?;
            }
        }
        if let Some(ground) = &self.ground {
            if ground.height.is_some_and(|h| !h.is_finite()) {
                return Err(("ground.height".into(), "must be finite".into()));
            }
            if let Some(size) = ground.size {
                range("ground.size".into(), size, f32::MIN_POSITIVE, f32::MAX)?;
            }
            if let Some(colour) = ground.colour {
                for (k, c) in colour.to_array().into_iter().enumerate() {
                    range(format!("ground.colour[{k}]"), c, 0.0, 1.0)?;
                }
            }
        }
        Ok(())
    }

    /// The scene's length: `duration_secs`, else the last keyframe or stroke end.
    #[must_use]
    pub fn duration_secs(&self) -> f64 {
        self.duration_secs.unwrap_or_else(|| {
            let wind = self.wind.last().map_or(0.0, |k| k.time_secs);
            let motion = self.motion.last().map_or(0.0, |k| k.time_secs);
            let water = self.water.last().map_or(0.0, |k| k.time_secs);
            let rain = self.rain.iter().map(|r| r.end_secs).fold(0.0, f64::max);
            let lights = self.light.iter().map(|k| k.time_secs).fold(0.0, f64::max);
            let keys = self.colliders.iter().filter_map(|c| c.keys.last()).map(|k| k.time_secs);
            let grasps = self.grasps.iter().map(|g| g.end_secs);
            self.strokes
                .iter()
                .map(|s| s.end_secs)
                .chain(keys)
                .chain(grasps)
                .fold(wind.max(motion).max(water).max(rain).max(lights), f64::max)
        })
    }

    /// The wind keyframe blended for `time_secs` (held before the first and after the last).
    #[must_use]
    pub fn wind_at(&self, time_secs: f64) -> Option<WindKey> {
        let after = self.wind.iter().position(|k| k.time_secs > time_secs);
        match after {
            None => self.wind.last().cloned(),
            Some(0) => self.wind.first().cloned(),
            Some(i) => {
                let (a, b) = (&self.wind[i - 1], &self.wind[i]);
                let t = ((time_secs - a.time_secs) / (b.time_secs - a.time_secs)) as f32;
                let lerp = |x: f32, y: f32| x * (1.0 - t) + y * t;
                let blended = a.direction.normalize() * (1.0 - t) + b.direction.normalize() * t;
                Some(WindKey {
                    time_secs,
                    // Opposite directions meet at zero halfway; keep the earlier one there.
                    direction: blended.try_normalize().unwrap_or(a.direction),
                    strength: lerp(a.strength, b.strength),
                    gust_strength: lerp(a.gust_strength, b.gust_strength),
                    jitter: lerp(a.jitter, b.jitter),
                })
            }
        }
    }

    /// The meshes' rigid transform at `time_secs` (`None` when the scene has no motion keys).
    #[must_use]
    pub fn motion_at(&self, time_secs: f64) -> Option<Mat4> {
        motion::motion_at(&self.motion, time_secs)
    }

    /// What wets the fur: the scene's rain and water keys.
    #[must_use]
    pub fn wet_sources(&self) -> WetSources<'_> {
        WetSources { rain: &self.rain, water: &self.water }
    }

    /// The stroke active at `time_secs` (the last one listed, where several overlap).
    #[must_use]
    pub fn stroke_at(&self, time_secs: f64) -> Option<&Stroke> {
        self.strokes.iter().rev().find(|s| (s.start_secs..s.end_secs).contains(&time_secs))
    }

    /// The script's lights at `time_secs` (none when it has no `[[light]]`).
    #[must_use]
    pub fn lights_at(&self, time_secs: f64) -> Vec<LightSource> {
        light::lights_at(&self.light, time_secs)
    }

    /// Sets the simulation's wind and touch for `time_secs`: begins, drags and ends touches as
    /// the strokes say. Call it before `sim.advance_to(time_secs)` on every frame.
    ///
    /// # Errors
    /// [`SimError`] if the blended wind fails validation (it cannot for a validated scene and
    /// valid simulation parameters).
    pub fn apply(&self, time_secs: f64, sim: &mut Simulation) -> Result<(), SimError> {
        if let Some(key) = self.wind_at(time_secs) {
            let mut wind = sim.params().wind.clone();
            wind.direction = key.direction;
            wind.strength = key.strength;
            wind.gust_strength = key.gust_strength;
            wind.jitter = key.jitter;
            sim.set_wind(&wind)?;
        }
        let held = sim.touch().filter(|t| t.released_at_secs.is_none()).map(|t| (t.point, t.radius));
        match self.stroke_at(time_secs) {
            Some(stroke) => {
                if held != Some((stroke.path[0], stroke.radius)) {
                    sim.touch_begin(stroke.path[0], stroke.radius)?;
                }
                sim.touch_drag(stroke.point_at(time_secs))?;
            }
            None => {
                let ours = held.is_some_and(|(p, r)| self.strokes.iter().any(|s| s.path[0] == p && s.radius == r));
                if ours {
                    sim.touch_end();
                }
            }
        }
        if !self.colliders.is_empty() {
            let ours = SCENE_COLLIDER_IDS..SCENE_COLLIDER_IDS + self.colliders.len() as u32;
            let mut colliders: Vec<Collider> = self
                .colliders
                .iter()
                .enumerate()
                .filter_map(|(i, c)| c.collider(SCENE_COLLIDER_IDS + i as u32))
                .collect();
            // A host's colliders (the viewer's ball, a walking body's capsules) stay, joined by id.
            colliders.extend(sim.colliders().iter().filter(|c| !ours.contains(&c.id)).cloned());
            if sim.colliders() != colliders.as_slice() {
                sim.set_colliders(&colliders)?;
            }
        }
        self.apply_grasps(time_secs, sim)
    }

    /// Closes, moves and opens the grasps for `time_secs`, as if every earlier frame was played:
    /// the latest grasp begun by then holds, or springs back from its release.
    fn apply_grasps(&self, time_secs: f64, sim: &mut Simulation) -> Result<(), SimError> {
        let Some(grasp) = self.grasps.iter().rev().find(|g| g.start_secs <= time_secs) else { return Ok(()) };
        let ours = sim.grasp().is_some_and(|g| {
            g.point == grasp.path[0] && g.radius == grasp.radius && g.closed_at_secs == grasp.start_secs
        });
        if !ours {
            if time_secs >= grasp.end_secs + f64::from(grasp.params().settle_secs()) {
                return Ok(());
            }
            sim.grasp_begin(grasp.path[0], grasp.radius, grasp.hand_radius, grasp.params(), grasp.start_secs)?;
        }
        sim.grasp_move(grasp.grip_at(time_secs))?;
        if time_secs >= grasp.end_secs {
            sim.grasp_end(grasp.end_secs);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ground_is_read_and_checked() {
        let text = "[ground]\nheight = -1.5\ncolour = [0.2, 0.3, 0.4]\n";
        let scene = Scene::from_toml_str(text, Path::new("a.toml")).expect("a valid ground");
        let ground = scene.ground.expect("the ground is kept");
        assert_eq!((ground.height, ground.size, ground.colour), (Some(-1.5), None, Some(Vec3::new(0.2, 0.3, 0.4))));
        assert_eq!(
            Scene::from_toml_str("[ground]\n", Path::new("a.toml")).expect("all optional").ground,
            Some(SceneGround::default())
        );
        for (bad, key) in [
            ("size = 0.0", "ground.size"),
            ("colour = [0.2, 1.5, 0.1]", "ground.colour[1]"),
            ("height = nan", "ground.height"),
        ] {
            let error =
                Scene::from_toml_str(&format!("[ground]\n{bad}\n"), Path::new("g.toml")).expect_err(bad).to_string();
            assert!(error.contains("g.toml") && error.contains(key), "{error}");
        }
    }

    #[test]
    fn a_camera_is_read_and_checked() {
        let text = "[camera]\ntarget = [1.0, 2.0, 3.0]\nazimuth_deg = 60.0\nelevation_deg = 30.0\n";
        let scene = Scene::from_toml_str(text, Path::new("a.toml")).expect("a valid camera");
        let camera = scene.camera.expect("the camera is kept");
        assert_eq!((camera.target, camera.azimuth_deg, camera.distance), (Some(Vec3::new(1.0, 2.0, 3.0)), 60.0, None));
        let bad = "[camera]\nazimuth_deg = 0.0\nelevation_deg = 95.0\n";
        let error = Scene::from_toml_str(bad, Path::new("b.toml")).unwrap_err().to_string();
        assert!(error.contains("b.toml") && error.contains("camera.elevation_deg"), "{error}");
        let bad = "[camera]\nazimuth_deg = 0.0\nelevation_deg = 5.0\ndistance = 0.0\n";
        let error = Scene::from_toml_str(bad, Path::new("c.toml")).unwrap_err().to_string();
        assert!(error.contains("camera.distance"), "{error}");
    }

    /// A script's colliders leave a host's (the viewer's ball) in place, joined by id, so the
    /// host's collider neither vanishes nor grows in again every frame.
    #[test]
    fn a_scripts_colliders_keep_the_hosts() {
        use crate::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
        use crate::mesh::builtin::Builtin;
        use crate::sim::contact::Shape;
        let text = "[[collider]]\nshape = { kind = \"sphere\", radius = 0.2 }\n\
                    keys = [{ time_secs = 0.0, position = [0.0, 2.0, 0.0] }]\n";
        let scene = Scene::from_toml_str(text, Path::new("s.toml")).expect("a valid scene");
        let (mesh, _) = Builtin::Sphere.mesh();
        let params = FurParams { layers: 4, length: FurLength::Constant(0.1), direction: GrowthDirection::default() };
        let fur = FurStructure::new(mesh, &params).expect("fur");
        let mut sim = Simulation::new(&fur, &crate::sim::SimParams::default()).expect("simulation");
        let ball = Collider::at(7, Shape::Sphere { radius: 0.3 }, 0.0, Vec3::new(0.0, 1.0, 0.0), glam::Quat::IDENTITY);
        sim.set_colliders(&[ball]).expect("the host's ball");
        sim.advance_to(0.1);
        let appeared = sim.colliders()[0].appeared_secs;
        for time_secs in [0.2, 0.3] {
            scene.apply(time_secs, &mut sim).expect("apply");
            sim.advance_to(time_secs);
        }
        let ids: Vec<u32> = sim.colliders().iter().map(|c| c.id).collect();
        assert_eq!(ids, vec![SCENE_COLLIDER_IDS, 7]);
        assert_eq!(sim.colliders()[1].appeared_secs, appeared, "the ball did not appear again");
    }
}
