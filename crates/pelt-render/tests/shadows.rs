//! The lights' shadows: a furred mesh over a ground, drawn with its `ShadowMap` and without.
//! The oracles are geometric (rays against the ground plane, the mesh's vertices projected along
//! the light) and photometric (linear light of the same pixels with shadows on and off); they
//! share nothing with the shadow maps they check.

use crate::common;

use common::{BROWN_ROOT, BROWN_TIP, Rig, strand_textures};
use glam::{Mat4, Vec3, Vec4Swizzles as _};
use pelt_core::groom::Groom;
use pelt_core::light::{LightKind, LightSource};
use pelt_core::{Builtin, FurParams, FurStructure, GrowthDirection, fur::FurLength};
use pelt_render::{
    Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurLook, FurShading, FurView, GpuFur, Light, LightDirection,
    PlainMesh, ShadowCaster, ShadowMap, ShadowSettings, ground_mesh,
};

const SIZE_PX: u32 = 256;
const GROUND_Y: f32 = -1.05;
const GROUND_COLOUR: Vec3 = Vec3::new(0.5, 0.5, 0.5);

/// A sphere of radius 1 with fur `length` long, groomed by `groom`.
fn sphere_fur(layers: u32, length: f32, groom: Option<Groom>) -> FurStructure {
    let (mesh, _) = Builtin::Sphere.mesh();
    let params = FurParams { layers, length: FurLength::Constant(length), direction: GrowthDirection::default() };
    FurStructure::new_groomed(mesh, &params, groom).expect("groomed sphere")
}

struct Stage {
    rig: Rig,
    view: FurView,
    ground: PlainMesh,
    /// The key light's colour (grey).
    key: f32,
}

impl Stage {
    fn new() -> Self {
        let rig = Rig::new(SIZE_PX, SIZE_PX);
        let view = FurView::new(rig.device(), &rig.renderer);
        let ground = rig.plain(&ground_mesh(), GROUND_COLOUR);
        ground.prepare(
            rig.queue(),
            Mat4::from_translation(Vec3::Y * GROUND_Y) * Mat4::from_scale(Vec3::new(4.0, 1.0, 4.0)),
        );
        Self { rig, view, ground, key: 1.0 }
    }

    fn fur(&self, structure: &FurStructure) -> GpuFur {
        self.rig.fur(structure, &strand_textures(128, structure.layers, BROWN_ROOT, BROWN_TIP))
    }

    /// One frame from `camera` lit from `toward_light`, with the ground if `ground`, the fur if
    /// any, and a shadow map of `fur_depth` cast along the light if `shadows`; in linear RGB per
    /// pixel.
    fn render(
        &mut self,
        camera: &Camera,
        toward_light: Vec3,
        what: (Option<&GpuFur>, bool),
        shadows: Option<f32>,
        name: &str,
    ) -> Vec<Vec3> {
        let shadows = shadows.map(|fur_depth| (fur_depth, ShadowCaster::Directional { toward_light }));
        self.render_cast(camera, toward_light, what, shadows, name)
    }

    /// [`Stage::render`] with the shadow map cast by `caster`.
    fn render_cast(
        &mut self,
        camera: &Camera,
        toward_light: Vec3,
        (fur, ground): (Option<&GpuFur>, bool),
        shadows: Option<(f32, ShadowCaster)>,
        name: &str,
    ) -> Vec<Vec3> {
        let rig = &self.rig;
        let light = Light {
            direction: LightDirection::World(toward_light.normalize()),
            colour: Vec3::splat(self.key),
            ambient: 0.2,
        };
        self.view.prepare(rig.queue(), &camera.view_data(1.0, &light));
        let map = shadows.map(|(fur_depth, caster)| {
            let settings = ShadowSettings { size: 512, fur_depth, extinction: 0.6 };
            let mut map = ShadowMap::new(rig.device(), &rig.renderer, settings).expect("shadow map");
            map.prepare(rig.queue(), (&[(0, caster)], 1), (Vec3::ZERO, 1.6));
            map
        });
        self.frame(map.as_ref(), (fur, ground), name)
    }
}

impl Stage {
    /// One frame from `camera` lit by `lights` (no environment), with the ground and `fur`,
    /// every shadowing light's maps made as hosts make them (`ShadowCaster::for_view`) if
    /// `shadows`; in linear RGB per pixel.
    fn render_lit(
        &mut self,
        camera: &Camera,
        lights: &[LightSource],
        fur: &GpuFur,
        shadows: bool,
        name: &str,
    ) -> Vec<Vec3> {
        let rig = &self.rig;
        let view_data = camera.view_data(1.0, &Light::default()).with_lights(lights, None);
        self.view.prepare(rig.queue(), &view_data);
        let bounds = (Vec3::ZERO, 1.6);
        let map = shadows.then(|| {
            let casters = ShadowCaster::for_view(&view_data, bounds);
            let views = casters.iter().map(|(_, caster)| caster.view_count()).sum();
            let settings = ShadowSettings { size: 512, fur_depth: 0.1, extinction: 0.6 };
            let mut map = ShadowMap::with_views(rig.device(), &rig.renderer, settings, views).expect("shadow map");
            assert_eq!(
                map.prepare(rig.queue(), (&casters, lights.len()), bounds),
                casters.len(),
                "every caster has its views"
            );
            map
        });
        self.frame(map.as_ref(), (Some(fur), true), name)
    }

    /// The frame through `self.view` shadowed by `map` (recorded first), with the ground and
    /// `fur` where asked; saved as `shadows-{name}.png`, returned in linear RGB per pixel.
    fn frame(&mut self, map: Option<&ShadowMap>, (fur, ground): (Option<&GpuFur>, bool), name: &str) -> Vec<Vec3> {
        let rig = &self.rig;
        self.view.set_shadows(map);
        let (view, plane) = (&self.view, &self.ground);
        let draw = |pass: &mut wgpu::RenderPass<'_>, view: &FurView| {
            if ground {
                rig.renderer.draw_plain(pass, view, plane);
            }
            if let Some(fur) = fur {
                rig.renderer.draw(pass, view, fur, &FurDrawSettings::ALL);
            }
        };
        let image = rig
            .headless
            .render_with(
                DEFAULT_BACKGROUND,
                |encoder| {
                    if let Some(map) = map {
                        map.record(encoder, draw);
                    }
                },
                |pass| draw(pass, view),
            )
            .expect("frame");
        image.save(common::out_dir().join(format!("shadows-{name}.png"))).expect("save");
        let linear = |c: u8| {
            let c = f32::from(c) / 255.0;
            if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
        };
        image.pixels().map(|p| Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))).collect()
    }
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Where each pixel's ray meets the ground plane (`None` off it).
fn ground_hits(camera: &Camera) -> Vec<Option<Vec3>> {
    let world_from_clip = camera.clip_from_world(1.0).inverse();
    (0..SIZE_PX * SIZE_PX)
        .map(|k| {
            let (x, y) = (k % SIZE_PX, k / SIZE_PX);
            let point = |z: f32| {
                let x_ndc = (x as f32 + 0.5) / SIZE_PX as f32 * 2.0 - 1.0;
                let y_ndc = 1.0 - (y as f32 + 0.5) / SIZE_PX as f32 * 2.0;
                let world = world_from_clip * glam::Vec4::new(x_ndc, y_ndc, z, 1.0);
                world.xyz() / world.w
            };
            let (near, far) = (point(0.0), point(1.0));
            let t = (near.y - GROUND_Y) / (near.y - far.y);
            let hit = near + (far - near) * t;
            (t > 0.0 && hit.x.abs() < 3.8 && hit.z.abs() < 3.8).then_some(hit)
        })
        .collect()
}

/// How far a ground point lies from the unit sphere's shadow along `toward_light` (0 inside
/// it): the distance from the sphere's centre to the ray from the point toward the light,
/// less the radius.
fn outside_sphere_shadow(point: Vec3, toward_light: Vec3) -> f32 {
    let l = toward_light.normalize();
    let along = (-point).dot(l);
    (-point - l * along).length() - 1.0
}

const SLANTED: Vec3 = Vec3::new(0.6, 1.0, 0.25);

fn ground_camera() -> Camera {
    Camera::orbit(Vec3::new(-0.6, GROUND_Y, 0.0), 200.0, 55.0, 7.0)
}

/// The ground's shade with shadows over without, at the visible ground pixels (the fur and
/// sphere cover none of them: the frame with them and without shadows matches the bare ground).
fn ground_shade(stage: &mut Stage, fur: &GpuFur, fur_depth: f32, name: &str) -> Vec<(Vec3, f32)> {
    let camera = ground_camera();
    let bare = stage.render(&camera, SLANTED, (None, true), None, &format!("{name}-bare"));
    let off = stage.render(&camera, SLANTED, (Some(fur), true), None, &format!("{name}-off"));
    let on = stage.render(&camera, SLANTED, (Some(fur), true), Some(fur_depth), &format!("{name}-on"));
    ground_hits(&camera)
        .into_iter()
        .enumerate()
        .filter_map(|(k, hit)| {
            let hit = hit?;
            let visible = (off[k] - bare[k]).abs().max_element() < 1e-3 && luminance(bare[k]) > 1e-3;
            visible.then(|| (hit, luminance(on[k]) / luminance(off[k])))
        })
        .collect()
}

#[test]
fn the_ground_under_a_furred_sphere_is_darker_with_shadows() {
    let mut stage = Stage::new();
    let structure = sphere_fur(16, 0.15, None);
    let fur = stage.fur(&structure);
    let shade = ground_shade(&mut stage, &fur, 0.15, "ground");
    let inside: Vec<f32> =
        shade.iter().filter(|(hit, _)| outside_sphere_shadow(*hit, SLANTED) < -0.3).map(|&(_, s)| s).collect();
    let far: Vec<f32> =
        shade.iter().filter(|(hit, _)| outside_sphere_shadow(*hit, SLANTED) > 0.8).map(|&(_, s)| s).collect();
    assert!(
        inside.len() > 200 && far.len() > 2000,
        "{} shadowed and {} far ground pixels in view",
        inside.len(),
        far.len()
    );
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    assert!(mean(&inside) < 0.5, "the ground in the sphere's shadow keeps {:.2} of its light", mean(&inside));
    assert!(mean(&far) > 0.97, "the ground far from the sphere keeps only {:.2} of its light", mean(&far));
}

#[test]
fn a_furred_shadow_is_larger_and_softer_than_a_bald_one() {
    let mut stage = Stage::new();
    let length = 0.3;
    let furred = sphere_fur(16, length, None);
    let bald_groom = Groom { length: Some(vec![0.0; furred.mesh.positions.len()]), ..Groom::default() };
    let bald = sphere_fur(16, length, Some(bald_groom));
    let (furred_fur, bald_fur) = (stage.fur(&furred), stage.fur(&bald));
    let furred_shade = ground_shade(&mut stage, &furred_fur, length, "furred");
    let bald_shade = ground_shade(&mut stage, &bald_fur, length, "bald");
    assert_eq!(furred_shade.len(), bald_shade.len().min(furred_shade.len()), "the same ground pixels in view");
    // The ground past the sphere's own shadow, where only the fur can shade it.
    let ring = |shade: &[(Vec3, f32)]| -> Vec<f32> {
        shade
            .iter()
            .filter(|(hit, _)| (0.05..0.35).contains(&outside_sphere_shadow(*hit, SLANTED)))
            .map(|&(_, s)| s)
            .collect()
    };
    let (furred_ring, bald_ring) = (ring(&furred_shade), ring(&bald_shade));
    let shaded = |v: &[f32]| v.iter().filter(|&&s| s < 0.95).count();
    assert!(
        shaded(&furred_ring) > 2 * shaded(&bald_ring) + 50,
        "ground shaded just outside the sphere's shadow: {} pixels furred, {} bald (of {})",
        shaded(&furred_ring),
        shaded(&bald_ring),
        furred_ring.len()
    );
    // Softer: the furred shadow's edge is partly lit (neither full light nor the core's dark).
    let penumbra = |shade: &[(Vec3, f32)]| shade.iter().filter(|&&(_, s)| (0.6..0.95).contains(&s)).count() as f32;
    let umbra = |shade: &[(Vec3, f32)]| shade.iter().filter(|&&(_, s)| s < 0.6).count().max(1) as f32;
    let (furred_soft, bald_soft) =
        (penumbra(&furred_shade) / umbra(&furred_shade), penumbra(&bald_shade) / umbra(&bald_shade));
    assert!(furred_soft > 1.5 * bald_soft, "penumbra over umbra: furred {furred_soft:.2}, bald {bald_soft:.2}");
}

/// The fur's pixels just below the equator of the sphere's image, seen from the side and lit from
/// above: the key light's share of their summed light (the fill's taken away) with shadows over
/// without.
#[test]
fn fur_on_the_underside_is_darker_with_shadows_from_above() {
    underside_darker_with_shadows(false);
}

/// The same with the fur model, whose coats have shadow pipelines of their own. Its lobes return
/// next to nothing of a light along the strands, so this fur is combed down.
#[test]
fn fur_model_fur_on_the_underside_is_darker_with_shadows_from_above() {
    underside_darker_with_shadows(true);
}

fn underside_darker_with_shadows(fur_model: bool) {
    let mut stage = Stage::new();
    let structure = if fur_model {
        let (mesh, _) = Builtin::Sphere.mesh();
        let direction = GrowthDirection { comb: -Vec3::Y, comb_blend: 0.6, ..GrowthDirection::default() };
        let params = FurParams { layers: 16, length: FurLength::Constant(0.2), direction };
        FurStructure::new_groomed(mesh, &params, None).expect("combed sphere")
    } else {
        sphere_fur(16, 0.2, None)
    };
    let fur = stage.fur(&structure);
    let look = FurLook { shading: FurShading { fur_model, ..FurShading::default() }, ..common::paper_look() };
    fur.prepare(stage.rig.queue(), &FurFrame { look, ..common::paper_frame() });
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 6.0);
    let name = if fur_model { "underside-fur-model" } else { "underside" };
    let off = stage.render(&camera, Vec3::Y, (Some(&fur), false), None, &format!("{name}-off"));
    let on = stage.render(&camera, Vec3::Y, (Some(&fur), false), Some(0.2), &format!("{name}-on"));
    let background = luminance(off[0]);
    let lower = |image: &[Vec3]| -> f32 {
        image
            .iter()
            .enumerate()
            // The band below the equator, where the key light still grazes the fur without shadows.
            .filter(|&(k, c)| {
                (SIZE_PX / 2 + 4..SIZE_PX / 2 + 40).contains(&(k as u32 / SIZE_PX))
                    && (luminance(*c) - background).abs() > 1e-3
            })
            .map(|(_, c)| luminance(*c))
            .sum()
    };
    // The band is mostly the fill's (the ambient term, or the fur model's environment): compare
    // the key light's share alone.
    stage.key = 0.0;
    let fill = lower(&stage.render(&camera, Vec3::Y, (Some(&fur), false), None, &format!("{name}-fill")));
    let (lit, shadowed) = (lower(&off) - fill, lower(&on) - fill);
    eprintln!("{name}: the key light's share of the band, {shadowed:.1} with shadows, {lit:.1} without");
    assert!(lit > 0.0, "the lower half shows lit fur");
    // 0.77 (Kajiya-Kay) and 0.80 (the fur model) on lavapipe; without the shadow, 1.
    assert!(shadowed < 0.9 * lit, "the underside's key light: {shadowed:.1} with shadows, {lit:.1} without");
}

/// The skin and roots of a plane of fur seen from above, lit from above: the shadows darken
/// them by the fur above them, less where the fur is sparse.
#[test]
fn the_root_darkening_falls_when_the_fur_is_sparse() {
    let mut stage = Stage::new();
    let (mesh, _) = Builtin::Plane.mesh();
    let params = FurParams { layers: 16, length: FurLength::Constant(0.15), direction: GrowthDirection::default() };
    let groom = |density: f32| Groom { density: Some(vec![density; mesh.positions.len()]), ..Groom::default() };
    let dense = FurStructure::new_groomed(mesh.clone(), &params, Some(groom(1.0))).expect("dense");
    let sparse = FurStructure::new_groomed(mesh.clone(), &params, Some(groom(0.25))).expect("sparse");
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 89.0, 3.5);
    let toward_light = Vec3::new(0.3, 1.0, 0.2);
    let mut darkening = |structure: &FurStructure, name: &str| {
        let fur = stage.fur(structure);
        let off = stage.render(&camera, toward_light, (Some(&fur), false), None, &format!("roots-{name}-off"));
        let on = stage.render(&camera, toward_light, (Some(&fur), false), Some(0.15), &format!("roots-{name}-on"));
        // The middle of the plane, well inside its edges.
        let centre = |image: &[Vec3]| -> f32 {
            image
                .iter()
                .enumerate()
                .filter(|&(k, _)| {
                    let (x, y) = (k as u32 % SIZE_PX, k as u32 / SIZE_PX);
                    x.abs_diff(SIZE_PX / 2) < SIZE_PX / 6 && y.abs_diff(SIZE_PX / 2) < SIZE_PX / 6
                })
                .map(|(_, c)| luminance(*c))
                .sum()
        };
        1.0 - centre(&on) / centre(&off)
    };
    let (dense_dark, sparse_dark) = (darkening(&dense, "dense"), darkening(&sparse, "sparse"));
    assert!(dense_dark > 0.05, "dense fur darkens its own roots by {dense_dark:.3}");
    assert!(sparse_dark < 0.7 * dense_dark, "darkening: sparse {sparse_dark:.3}, dense {dense_dark:.3}");
}

/// A point light above the sphere casts through a perspective view aimed at the scene
/// (`ShadowCaster::for_key_light`): on the ground its shadow is the sphere's silhouette seen
/// from the light, wider than a sun's from straight above. The oracle is the cone from the
/// light tangent to the sphere; a sun's shadow would leave the ring between the two lit.
#[test]
fn a_point_light_above_casts_the_spheres_shadow_wider_than_a_sun() {
    let mut stage = Stage::new();
    let (radius, light_height) = (1.02, 2.5);
    let fur = stage.fur(&sphere_fur(4, radius - 1.0, None));
    let point = LightSource {
        kind: LightKind::Point,
        position: Vec3::Y * light_height,
        ..LightSource::directional(Vec3::Y, Vec3::ONE, 1.0)
    };
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 55.0, 6.0);
    let view = camera.view_data(1.0, &Light::default()).with_lights(&[point], None);
    let caster = ShadowCaster::for_key_light(&view, (Vec3::ZERO, 1.6));
    assert!(matches!(caster, ShadowCaster::Spot { .. }), "{caster:?}");
    let bare = stage.render(&camera, Vec3::Y, (None, true), None, "point-ground");
    let lit = stage.render(&camera, Vec3::Y, (Some(&fur), true), None, "point-off");
    let shadowed = stage.render_cast(&camera, Vec3::Y, (Some(&fur), true), Some((0.02, caster)), "point-on");
    // Where the tangent cone meets the ground.
    let shadow_radius = (light_height - GROUND_Y) * (radius / light_height).asin().tan();
    let (mut ring, mut ring_dark, mut outside, mut outside_lit) = (0, 0, 0, 0);
    for (k, hit) in ground_hits(&camera).into_iter().enumerate() {
        // The ground in view: the sphere does not hide it.
        let Some(hit) = hit.filter(|_| (luminance(lit[k]) - luminance(bare[k])).abs() < 0.01) else { continue };
        let (d, ratio) = (hit.x.hypot(hit.z), luminance(shadowed[k]) / luminance(lit[k]).max(1e-6));
        if (1.15..0.85 * shadow_radius).contains(&d) {
            ring += 1;
            ring_dark += usize::from(ratio < 0.6);
        } else if d > 1.2 * shadow_radius {
            outside += 1;
            outside_lit += usize::from(ratio > 0.9);
        }
    }
    let report = format!(
        "shadow radius {shadow_radius:.2}: {ring_dark} of {ring} ring pixels dark, {outside_lit} of {outside} outside lit"
    );
    assert!(ring > 500 && outside > 2_000, "too few ground pixels: {report}");
    assert!(ring_dark * 10 > ring * 8, "the ring the point light shades is lit: {report}");
    assert!(outside_lit * 10 > outside * 9, "the ground past the shadow is dark: {report}");
}

/// Whether the segment from `point` to `light` passes within `radius` of the origin.
fn segment_meets_sphere(point: Vec3, light: Vec3, radius: f32) -> bool {
    let d = light - point;
    let t = ((-point).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (point + d * t).length() < radius
}

/// Two suns, each casting: the ground in the second's shadow alone is darker than with the
/// second casting none, and the ground in neither shadow keeps its light. Only the key light
/// (light 0) cast shadows once: then the second sun's shadow is missing.
#[test]
fn a_second_light_casts_its_own_shadow() {
    let mut stage = Stage::new();
    let fur = stage.fur(&sphere_fur(8, 0.1, None));
    // Low suns on either side, seen from high above: both shadows reach out from under the sphere.
    let (first, second) = (Vec3::new(1.2, 1.0, 0.3), Vec3::new(-1.2, 1.0, -0.4));
    let suns = [LightSource::directional(first, Vec3::ONE, 1.5), LightSource::directional(second, Vec3::ONE, 1.5)];
    let camera = Camera::orbit(Vec3::new(0.0, GROUND_Y, 0.0), 20.0, 70.0, 7.0);
    let both = stage.render_lit(&camera, &suns, &fur, true, "two-suns-on");
    let first_only = [suns[0], LightSource { casts_shadows: false, ..suns[1] }];
    let one = stage.render_lit(&camera, &first_only, &fur, true, "two-suns-first");
    let (mut second_shadow, mut second_dark, mut open, mut open_same) = (0, 0, 0, 0);
    for (k, hit) in ground_hits(&camera).into_iter().enumerate() {
        // Ground the furred sphere does not hide from the camera.
        let Some(hit) = hit.filter(|hit| !segment_meets_sphere(*hit, camera.eye, 1.15)) else { continue };
        let (a, b) = (outside_sphere_shadow(hit, first), outside_sphere_shadow(hit, second));
        let ratio = luminance(both[k]) / luminance(one[k]).max(1e-6);
        if a > 0.5 && b < -0.3 {
            second_shadow += 1;
            second_dark += usize::from(ratio < 0.7);
        } else if a > 0.5 && b > 0.5 {
            open += 1;
            open_same += usize::from((ratio - 1.0).abs() < 0.03);
        }
    }
    let report = format!(
        "{second_dark} of {second_shadow} pixels in the second shadow darker, {open_same} of {open} open ground the same"
    );
    assert!(second_shadow > 200 && open > 2_000, "too few ground pixels: {report}");
    assert!(second_dark * 10 > second_shadow * 8, "the second sun casts no shadow: {report}");
    assert!(open_same * 10 > open * 9, "the ground in neither shadow changed: {report}");
}

/// A point light among the casters (inside the scene's bounds) casts through a cube of six
/// views: the ground is dark where the segment to the light meets the sphere and lit where it
/// passes clear, on every face the ground is seen through (the side faces behind the sphere,
/// the one below the light). Cast as one sun's view from where it stands, as it once was, the
/// shadow behind the sphere falls in the wrong place.
#[test]
fn a_point_light_among_the_casters_shadows_every_side_through_its_cube() {
    let mut stage = Stage::new();
    let fur = stage.fur(&sphere_fur(8, 0.05, None));
    let position = Vec3::new(1.45, -0.3, 0.0);
    let bulb = LightSource { kind: LightKind::Point, position, ..LightSource::directional(Vec3::Y, Vec3::ONE, 3.0) };
    let camera = Camera::orbit(Vec3::new(0.0, GROUND_Y, 0.0), 150.0, 60.0, 7.0);
    let view = camera.view_data(1.0, &Light::default()).with_lights(&[bulb], None);
    assert_eq!(ShadowCaster::for_view(&view, (Vec3::ZERO, 1.6)), vec![(0, ShadowCaster::Point { position })]);
    let on = stage.render_lit(&camera, &[bulb], &fur, true, "cube-on");
    let off = stage.render_lit(&camera, &[bulb], &fur, false, "cube-off");
    let (mut dark, mut dark_ok, mut clear, mut clear_ok) = (0, 0, 0, 0);
    let mut faces = [0usize; 2];
    for (k, hit) in ground_hits(&camera).into_iter().enumerate() {
        // Ground the furred sphere does not hide from the camera, lit enough to measure.
        let Some(hit) = hit.filter(|hit| !segment_meets_sphere(*hit, camera.eye, 1.15)) else { continue };
        if luminance(off[k]) < 0.02 || (hit - position).length() > 3.5 {
            continue;
        }
        let ratio = luminance(on[k]) / luminance(off[k]);
        let d = (hit - position).abs();
        if segment_meets_sphere(hit, position, 0.9) {
            dark += 1;
            dark_ok += usize::from(ratio < 0.3);
            faces[usize::from(d.y > d.x.max(d.z))] += 1;
        } else if !segment_meets_sphere(hit, position, 1.25) {
            clear += 1;
            clear_ok += usize::from(ratio > 0.9);
        }
    }
    let report = format!(
        "{dark_ok} of {dark} shadowed pixels dark ({} by the side faces, {} below), {clear_ok} of {clear} clear pixels lit",
        faces[0], faces[1]
    );
    assert!(dark > 300 && clear > 1_000, "too few ground pixels: {report}");
    assert!(dark_ok * 10 > dark * 8, "the sphere's shadow from the point light is missing: {report}");
    assert!(clear_ok * 10 > clear * 9, "ground the light reaches is dark: {report}");
}
