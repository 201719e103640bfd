//! What `pelt render` and `pelt view` share about herds: where the members stand (`--herd N` or a
//! script's `[[instance]]`s) and the ground they cover.

use anyhow::bail;
use glam::Vec3;
use pelt_core::anim::Rig;
use pelt_core::sim::Scene;
use pelt_core::sim::herd::{self, HerdInstance};
use pelt_core::{FurStructure, Mesh};

/// The herd to draw: `--herd N` (`count`) scattered, or the script's `[[instance]]`s; none for
/// one fur.
pub fn instances(
    count: Option<usize>,
    scene: Option<&Scene>,
    mesh: &Mesh,
    (rig, clip): (Option<&Rig>, Option<usize>),
) -> anyhow::Result<Vec<HerdInstance>> {
    let scripted = scene.map_or(&[][..], |s| &s.instance[..]);
    match count {
        Some(_) if !scripted.is_empty() => {
            bail!("--herd and the script's [[instance]] tables both place a herd: use one of them")
        }
        Some(count) => {
            // A body length and a half apart, each somewhere in its clip's first loop.
            let (low, high) = mesh.bounds();
            let spacing = 1.5 * (high - low).max_element();
            let phase = clip.and_then(|k| rig.map(|r| f64::from(r.animations()[k].duration_secs()))).unwrap_or(1.0);
            herd::scatter(count, spacing, phase, 0).map_err(|e| anyhow::anyhow!("--herd {count}: {e}"))
        }
        None => Ok(scripted.to_vec()),
    }
}

/// The box a herd covers between the times `secs` (every member's mesh at each, with the fur's
/// length about it); `None` for one fur.
pub fn extent(fur: &FurStructure, instances: &[HerdInstance], secs: &[f64]) -> Option<(Vec3, Vec3)> {
    if instances.is_empty() {
        return None;
    }
    let (low, high) = fur.mesh.bounds();
    let length = Vec3::splat(fur.lengths.iter().copied().fold(0.0, f32::max));
    let corners = [low, high, Vec3::new(low.x, low.y, high.z), Vec3::new(high.x, high.y, low.z)];
    Some(instances.iter().flat_map(|i| secs.iter().map(|&t| i.world_from_model(t))).fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), world| {
            // The fur's length about the sides and above; the ground under the feet.
            corners
                .iter()
                .map(|c| world.transform_point3(*c))
                .fold((lo, hi), |(lo, hi), p| (lo.min(p - length * Vec3::new(1.0, 0.0, 1.0)), hi.max(p + length)))
        },
    ))
}
