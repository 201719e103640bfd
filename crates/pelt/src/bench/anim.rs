//! The walking Fox's per-frame CPU cost: posing the skinned base (what `pelt render` and `pelt
//! view` run every frame: `Rig::pose`, linear blend skinning of positions, normals and frames)
//! and the simulation following it (`set_base_rotations`, then `advance_to`).

use std::hint::black_box;
use std::time::Instant;

use pelt_core::FurStructure;
use pelt_core::anim::{Pose, Rig};
use pelt_core::sim::{SimParams, Simulation};

use super::report::AnimFigures;
use super::sim::SIM_RATE_HZ;

/// Poses `fur`'s mesh with `clip` of `rig` for `frames` frames at the simulation rate, as `pelt
/// render`'s frame loop does (the first frame untimed, restarting the simulation on its pose),
/// and times the pose and the simulation of each frame.
pub fn measure(
    fur: &FurStructure,
    rig: &Rig,
    clip: &str,
    params: &SimParams,
    frames: u32,
) -> anyhow::Result<AnimFigures> {
    let animation = rig.find_animation(clip).map_err(|e| anyhow::anyhow!("{clip}: {e}"))?;
    let mut simulation = Simulation::new(fur, params)?;
    let mut pose = Pose::default();
    let (mut pose_secs, mut sim_secs) = (0.0, 0.0);
    let frames = frames.max(1);
    for frame in 0..=frames {
        let time_secs = f64::from(frame) / f64::from(SIM_RATE_HZ);
        let started = Instant::now();
        rig.pose(&fur.mesh, Some(animation), time_secs, &mut pose);
        black_box(&pose);
        let posed = Instant::now();
        simulation.set_base_rotations(&pose.positions, &pose.rotations)?;
        if frame == 0 {
            simulation.restart();
        }
        simulation.advance_to(time_secs);
        black_box(simulation.positions());
        if frame > 0 {
            pose_secs += (posed - started).as_secs_f64();
            sim_secs += posed.elapsed().as_secs_f64();
        }
    }
    let per_frame = |secs: f64| secs * 1000.0 / f64::from(frames);
    Ok(AnimFigures {
        anim_clip: Some(clip.to_owned()),
        anim_pose_ms_per_frame: Some(per_frame(pose_secs)),
        anim_sim_ms_per_frame: Some(per_frame(sim_secs)),
        anim_cpu_ms_per_frame: Some(per_frame(pose_secs + sim_secs)),
        anim_unavailable_reason: None,
    })
}
