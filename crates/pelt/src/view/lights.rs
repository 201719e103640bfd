//! The viewer's lights: the panel's Lights section (add, drag and remove suns and point lights;
//! the environment) and the studio they make. They start as Pelt's studio (its key light and
//! `sky-ground`); without lights the key light follows the camera. The first light is the key
//! light, the one that casts the shadows.

use glam::Vec3;
use pelt_core::light::{Environment, LightKind, LightSource, direction_from_angles};
use pelt_render::Studio;

use crate::light_args::LightArgs;

/// A new sun's illuminance: pi lux, so a white Lambertian surface facing it shows white.
const SUN_LUX: f32 = std::f32::consts::PI;

/// The lights and the environment the panel edits.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LightSettings {
    /// In physical units (at most `pelt_core::light::MAX_LIGHTS`); empty: the key light follows
    /// the camera.
    pub lights: Vec<LightSource>,
    /// The environment in place of the ambient, with its name (`sky-ground` or the image's).
    pub environment: Option<(String, Environment)>,
    /// `--environment`'s, to switch back to.
    given_environment: Option<(String, Environment)>,
}

impl LightSettings {
    /// `--light` and `--environment`.
    ///
    /// # Errors
    /// An environment image that cannot be read, named.
    pub fn from_args(args: &LightArgs) -> anyhow::Result<Self> {
        let name = args.environment.clone().unwrap_or_else(|| "sky-ground".to_owned());
        let environment = args.environment(None)?.map(|e| (name, e));
        Ok(Self { lights: args.lights_at(None, 0.0), environment: environment.clone(), given_environment: environment })
    }

    /// Pelt's studio with these lights.
    #[must_use]
    pub fn studio(&self) -> Studio {
        Studio::default().with_lights(&self.lights, self.environment.as_ref().map(|(_, e)| *e))
    }

    /// Adds a sun where the light that follows the camera now is (`toward_light`, world space),
    /// so adding it keeps the picture's light.
    pub fn add_sun(&mut self, toward_light: Vec3) {
        if self.lights.len() < pelt_core::light::MAX_LIGHTS {
            self.lights.push(LightSource::directional(toward_light, Vec3::ONE, SUN_LUX));
        }
    }

    /// Adds a white point light above and in front of `target`, `distance` from it, bright
    /// enough to give a sun's illuminance there.
    pub fn add_point(&mut self, target: Vec3, toward_camera: Vec3, distance: f32) {
        if self.lights.len() < pelt_core::light::MAX_LIGHTS {
            let offset = (toward_camera.normalize_or(Vec3::Z) + Vec3::Y).normalize_or(Vec3::Y) * distance;
            let candela = SUN_LUX * distance * distance;
            self.lights.push(LightSource {
                kind: LightKind::Point,
                position: target + offset,
                direction: Vec3::ZERO,
                intensity: Vec3::splat(candela),
                cos_inner: -1.0,
                cos_outer: -1.0,
                casts_shadows: true,
            });
        }
    }
}

/// Degrees the key light turns per point dragged (Ctrl+drag in the view).
const DRAG_DEG_PER_POINT: f32 = 0.4;

impl LightSettings {
    /// Turns the key light by a drag in the view (points; x right, y down): right turns it about
    /// the vertical, up raises it. Without lights a sun is added where the light that follows
    /// the camera is (`following`), so the drag starts from the picture's light. A point or spot
    /// key light stays where it is.
    pub fn drag_key(&mut self, drag: glam::Vec2, following: Vec3) {
        if self.lights.is_empty() {
            self.add_sun(following);
        }
        let Some(key) = self.lights.first_mut().filter(|l| l.kind == LightKind::Directional) else { return };
        let (azimuth, elevation) = angles_of(key.direction);
        let elevation = (elevation - drag.y * DRAG_DEG_PER_POINT).clamp(2.0, 89.0);
        key.direction = direction_from_angles(azimuth + drag.x * DRAG_DEG_PER_POINT, elevation);
    }
}

/// Where the panel's new lights go, from the viewer's camera.
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    /// Toward the light that follows the camera (world space): a new sun starts there.
    pub following: Vec3,
    /// A new point light goes above and in front of the target, `distance` from it.
    pub target: Vec3,
    pub toward_camera: Vec3,
    pub distance: f32,
}

impl Placement {
    /// For `camera`.
    #[must_use]
    pub fn of(camera: &super::camera::OrbitCamera) -> Self {
        let view = camera.camera().view_data(1.0, &pelt_render::Light::default());
        Self {
            following: view.light_direction_world,
            target: camera.target,
            toward_camera: camera.eye() - camera.target,
            distance: 0.5 * camera.distance,
        }
    }
}

/// Azimuth and elevation (degrees) of a unit direction, as `--light` takes them.
#[must_use]
pub fn angles_of(direction: Vec3) -> (f32, f32) {
    let d = direction.normalize_or(Vec3::Y);
    (d.x.atan2(d.z).to_degrees().rem_euclid(360.0), d.y.clamp(-1.0, 1.0).asin().to_degrees())
}

/// The Lights section, new lights placed by `placement`; true when anything changed.
pub fn lights_ui(ui: &mut egui::Ui, settings: &mut LightSettings, placement: &Placement) -> bool {
    let before = settings.clone();
    if settings.lights.is_empty() {
        ui.label("The key light follows the camera.");
    }
    let mut removed = None;
    for (index, light) in settings.lights.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            let kind = match light.kind {
                LightKind::Directional => "sun",
                LightKind::Point => "point",
                LightKind::Spot => "spot",
            };
            let role = if index == 0 { ", key: casts the shadows" } else { "" };
            ui.strong(format!("{} {kind}{role}", index + 1));
            if ui.small_button("remove").clicked() {
                removed = Some(index);
            }
        });
        light_ui(ui, index, light);
    }
    if let Some(index) = removed {
        settings.lights.remove(index);
    }
    ui.horizontal(|ui| {
        let room = settings.lights.len() < pelt_core::light::MAX_LIGHTS;
        if ui.add_enabled(room, egui::Button::new("add a sun")).clicked() {
            settings.add_sun(placement.following);
        }
        if ui.add_enabled(room, egui::Button::new("add a point light")).clicked() {
            settings.add_point(placement.target, placement.toward_camera, placement.distance);
        }
    });
    let mut sky = settings.environment.as_ref().is_some_and(|(name, _)| name == "sky-ground");
    if ui.checkbox(&mut sky, "sky-ground environment").on_hover_text("a pale sky over a dark ground").changed() {
        settings.environment = if sky {
            Some(("sky-ground".to_owned(), Studio::sky_ground()))
        } else {
            settings.given_environment.clone().filter(|(name, _)| name != "sky-ground")
        };
    }
    if let Some((name, _)) = &settings.environment
        && name != "sky-ground"
    {
        ui.label(format!("environment: {name}"));
    }
    *settings != before
}

/// One light's controls: a sun's angles, a point or spot light's position, and its colour and
/// intensity.
fn light_ui(ui: &mut egui::Ui, index: usize, light: &mut LightSource) {
    egui::Grid::new(("light", index)).num_columns(2).show(ui, |ui| {
        let strength = light.intensity.max_element().max(1e-6);
        let mut colour = (light.intensity / strength).to_array();
        let mut amount = strength;
        match light.kind {
            LightKind::Directional => {
                let (mut azimuth, mut elevation) = angles_of(light.direction);
                ui.label("azimuth, elevation");
                ui.horizontal(|ui| {
                    let a = ui.add(egui::DragValue::new(&mut azimuth).speed(1.0).suffix("°"));
                    let e = ui.add(egui::DragValue::new(&mut elevation).speed(0.5).range(-90.0..=90.0).suffix("°"));
                    if a.changed() || e.changed() {
                        light.direction = direction_from_angles(azimuth, elevation);
                    }
                });
                ui.end_row();
                ui.label("lux");
            }
            LightKind::Point | LightKind::Spot => {
                ui.label("position");
                ui.horizontal(|ui| {
                    for axis in 0..3 {
                        ui.add(egui::DragValue::new(&mut light.position[axis]).speed(0.01));
                    }
                });
                ui.end_row();
                ui.label("candela");
            }
        }
        ui.add(egui::DragValue::new(&mut amount).speed(0.05 * strength).range(0.0..=f32::MAX));
        ui.end_row();
        ui.label("colour");
        ui.color_edit_button_rgb(&mut colour);
        ui.end_row();
        let colour = Vec3::from_array(colour);
        if amount != strength || colour != light.intensity / strength {
            light.intensity = colour * amount;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angles_and_directions_agree_with_the_light_flag() {
        for (azimuth, elevation) in [(0.0, 0.0), (40.0, 35.0), (220.0, 60.0), (359.0, -20.0)] {
            let (a, e) = angles_of(direction_from_angles(azimuth, elevation));
            assert!((a - azimuth).abs() < 1e-3 && (e - elevation).abs() < 1e-3, "{azimuth},{elevation} -> {a},{e}");
        }
    }

    #[test]
    fn a_new_sun_keeps_the_following_light_and_lights_stop_at_the_limit() {
        let mut settings = LightSettings::default();
        let following = Vec3::new(-0.4, 0.7, 0.6).normalize();
        settings.add_sun(following);
        let camera = pelt_render::Camera::orbit(Vec3::ZERO, 0.0, 0.0, 2.0);
        let key = settings.studio().view_data(&camera, 1.0).light_direction_world;
        assert!(settings.lights[0].direction.distance(following) < 1e-6 && key.distance(following) < 1e-6, "{key}");
        for _ in 0..20 {
            settings.add_point(Vec3::ZERO, Vec3::Z, 2.0);
        }
        assert_eq!(settings.lights.len(), pelt_core::light::MAX_LIGHTS);
        let point = settings.lights[1];
        // A sun's illuminance at the target: I / d^2 = pi lux.
        let distance = point.position.length();
        assert!((point.intensity.x / (distance * distance) - SUN_LUX).abs() < 1e-3, "{point:?}");
    }

    #[test]
    fn a_drag_turns_the_key_light_from_the_following_one() {
        let mut settings = LightSettings::default();
        let following = direction_from_angles(30.0, 40.0);
        settings.drag_key(glam::Vec2::new(25.0, -25.0), following);
        let (azimuth, elevation) = angles_of(settings.lights[0].direction);
        assert!((azimuth - 40.0).abs() < 1e-3 && (elevation - 50.0).abs() < 1e-3, "{azimuth}, {elevation}");
        settings.drag_key(glam::Vec2::new(0.0, 1000.0), following);
        assert!((angles_of(settings.lights[0].direction).1 - 2.0).abs() < 1e-3, "held above the horizon");
        assert_eq!(settings.lights.len(), 1, "one key light, dragged");
    }
}
