//! What `pelt render` and `pelt view` share about herds: where the members stand (`--herd N` or a
//! script's `[[instance]]`s).

use anyhow::bail;
use pelt_core::Mesh;
use pelt_core::anim::Rig;
use pelt_core::sim::Scene;
use pelt_core::sim::herd::{self, HerdInstance};

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
