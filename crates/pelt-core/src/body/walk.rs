//! The try-on with a body that walks: Cesium Man (a skinned glTF man with a walk cycle) wearing
//! the try-on skirt, scaled onto his hips and skinned to him by [`transfer_weights`].

use std::path::Path;

use glam::{Mat4, Vec2, Vec3};

use super::{BodyCapsules, TransferError, TransferReport, transfer_weights};
use crate::anim::Rig;
use crate::mesh::builtin::TRY_ON_GARMENT_OBJ;
use crate::mesh::{ImportOptions, Mesh, MeshError, MeshReport};

/// Cesium Man (Khronos glTF sample, CC BY 4.0; credits in `assets/CREDITS.md`).
const WALKING_BODY_GLB: &[u8] = include_bytes!("../../assets/meshes/CesiumMan.glb");

/// The skirt's height over the body's, and where its top sits (a fraction of the body's height
/// from the soles): a knee-length skirt from the waist.
const SKIRT_HEIGHT: f32 = 0.2;
const SKIRT_TOP: f32 = 0.62;
/// Room left between the skirt and the body at the hips, over the body's height.
const SKIRT_EASE: f32 = 0.015;
/// The farthest a skirt vertex may be from the body, over the body's height: the hem stands
/// off the legs by up to about 0.08 of it.
const MAX_TRANSFER_DISTANCE: f32 = 0.15;

/// Why the walking try-on cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum BodyError {
    /// A mesh failed to load.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// The body file has no skin or no clip.
    #[error("{0}: the body has no rig with an animation")]
    NoRig(String),
    /// The garment could not be skinned to the body.
    #[error("skinning the garment to the body: {0}")]
    Transfer(#[from] TransferError),
}

/// The walking try-on: a furred garment skinned to a body that walks.
#[derive(Clone, Debug)]
pub struct WalkingTryOn {
    /// The skirt, in the body's bind pose.
    pub garment: Mesh,
    /// What import did to the garment.
    pub garment_report: MeshReport,
    /// The garment's rig: the body's skeleton and walk, with transferred weights.
    pub garment_rig: Rig,
    /// What the weight transfer found.
    pub transfer: TransferReport,
    /// The body, drawn plain.
    pub body: Mesh,
    /// The body's rig and its walk clip (clip 0).
    pub body_rig: Rig,
    /// The body as capsules for the fur to collide with.
    pub capsules: BodyCapsules,
}

/// Loads the walking try-on (one embedded copy of its meshes).
///
/// # Errors
/// Only if `options` make the shipped meshes unusable.
pub fn walking_try_on(options: &ImportOptions) -> Result<WalkingTryOn, BodyError> {
    let name = "builtin:tryon/CesiumMan.glb";
    let (mut body, _, body_rig) = Mesh::from_gltf_slice_animated(WALKING_BODY_GLB, Path::new(name), options)?;
    let mut body_rig =
        body_rig.filter(|r| !r.animations().is_empty()).ok_or_else(|| BodyError::NoRig(name.to_owned()))?;
    // The file's mesh is Z-up; its rest pose is Y-up and walks toward +Z (as the still try-on
    // body faces): the skirt is fitted to that pose.
    body_rig.rebind_at_rest(&mut body, Mat4::IDENTITY);
    let (mut garment, garment_report) =
        Mesh::from_obj_str(TRY_ON_GARMENT_OBJ, Path::new("builtin:tryon/skirthelper.obj"), options)?;
    fit_skirt(&mut garment, &body);
    // What still pokes through the skirt at rest (the buttocks, the hip crease) goes under it.
    let radius = garment.bounding_sphere().1;
    crate::mesh::tuck_under(&mut body, &garment, 0.01 * radius, 0.1 * radius);
    let height = body.bounds().1.y - body.bounds().0.y;
    let (garment_rig, transfer) = transfer_weights(&body, &body_rig, &garment, MAX_TRANSFER_DISTANCE * height)?;
    let mut capsules = BodyCapsules::fit(&body, &body_rig);
    // The skirt's fur grows from outside every capsule.
    capsules.clear_of(&garment.positions, 0.005 * radius);
    Ok(WalkingTryOn { garment, garment_report, garment_rig, transfer, body, body_rig, capsules })
}

/// Scales and moves the skirt onto the body: its height a fixed share of the body's, its top at
/// the waist, centred on the hips, and wide enough that the hips stay `SKIRT_EASE` inside it.
fn fit_skirt(garment: &mut Mesh, body: &Mesh) {
    let (body_lo, body_hi) = body.bounds();
    let height = body_hi.y - body_lo.y;
    let (skirt_lo, skirt_hi) = garment.bounds();
    let vertical = SKIRT_HEIGHT * height / (skirt_hi.y - skirt_lo.y);
    let top = body_lo.y + SKIRT_TOP * height;
    let bottom = top - SKIRT_HEIGHT * height;
    // The body's hips and thighs: its vertices in the skirt's band, the hands (far from the
    // middle) left out.
    let band: Vec<Vec3> = body
        .positions
        .iter()
        .copied()
        .filter(|p| p.y > bottom && p.y < top && Vec2::new(p.x, p.z).length() < 0.15 * height)
        .collect();
    let centre = band.iter().copied().sum::<Vec3>() / band.len().max(1) as f32;
    let skirt_centre = garment.positions.iter().copied().sum::<Vec3>() / garment.vertex_count() as f32;
    // Horizontal scale: the smallest that keeps every hip vertex inside the skirt's ring at its height.
    let (lo_x, hi_x) =
        band.iter().fold((0.0_f32, 0.0_f32), |(lo, hi), p| (lo.min(p.x - centre.x), hi.max(p.x - centre.x)));
    let (lo_z, hi_z) =
        band.iter().fold((0.0_f32, 0.0_f32), |(lo, hi), p| (lo.min(p.z - centre.z), hi.max(p.z - centre.z)));
    let (skirt_lo_x, skirt_hi_x) = (skirt_lo.x - skirt_centre.x, skirt_hi.x - skirt_centre.x);
    let (skirt_lo_z, skirt_hi_z) = (skirt_lo.z - skirt_centre.z, skirt_hi.z - skirt_centre.z);
    let ease = SKIRT_EASE * height;
    let sx = ((hi_x + ease) / skirt_hi_x).max((lo_x - ease) / skirt_lo_x);
    let sz = ((hi_z + ease) / skirt_hi_z).max((lo_z - ease) / skirt_lo_z);
    let scale = Vec3::new(sx, vertical, sz);
    let place = Mat4::from_translation(Vec3::new(centre.x, top, centre.z))
        * Mat4::from_scale(scale)
        * Mat4::from_translation(-Vec3::new(skirt_centre.x, skirt_hi.y, skirt_centre.z));
    garment.transform(place);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_walking_try_on_skins_the_skirt_to_the_legs_and_keeps_it_on_them() {
        let scene = walking_try_on(&ImportOptions::default()).expect("walking try-on");
        let height = scene.body.bounds().1.y - scene.body.bounds().0.y;
        let report = &scene.transfer;
        assert_eq!(report.vertices, scene.garment.vertex_count());
        // The skirt sits on the hips and stands off the thighs at the hem: the range the docs give.
        assert!(report.distance_range.1 < 0.05 * height, "{report}");
        assert!(report.blended > 0, "the hem between the legs blends both legs: {report}");
        // Walking, the skirt's vertices stay near the walking body: the thighs carry it.
        let mut body_pose = crate::anim::Pose::default();
        let mut skirt_pose = crate::anim::Pose::default();
        for k in 0..8 {
            let t = f64::from(k) * 0.25;
            scene.body_rig.pose(&scene.body, Some(0), t, &mut body_pose);
            scene.garment_rig.pose(&scene.garment, Some(0), t, &mut skirt_pose);
            let posed_body = Mesh { positions: body_pose.positions.clone(), ..scene.body.clone() };
            let farthest = skirt_pose
                .positions
                .iter()
                .map(|&p| super::super::transfer::closest_on_mesh(&posed_body, p).map_or(f32::INFINITY, |c| c.2))
                .fold(0.0, f32::max);
            assert!(farthest < 0.08 * height, "at {t} s a skirt vertex is {farthest} from the body");
        }
    }
}
