//! pelt-render's tests on a real adapter (lavapipe in CI) in one binary
//! (one link for all of them); each module is one file of tests beside this one.

#[path = "common/mod.rs"]
mod common;

#[path = "collider_mesh.rs"]
mod collider_mesh;
#[path = "colliders.rs"]
mod colliders;
#[path = "driver.rs"]
mod driver;
#[path = "embed.rs"]
mod embed;
#[path = "fur_lights.rs"]
mod fur_lights;
#[path = "gpu.rs"]
mod gpu;
#[path = "groom.rs"]
mod groom;
#[path = "groom_shading.rs"]
mod groom_shading;
#[path = "herd.rs"]
mod herd;
#[path = "herd_steps.rs"]
mod herd_steps;
#[path = "host.rs"]
mod host;
#[path = "lean.rs"]
mod lean;
#[path = "lod.rs"]
mod lod;
#[path = "shadows.rs"]
mod shadows;
#[path = "simulation.rs"]
mod simulation;
#[path = "simulation_inputs.rs"]
mod simulation_inputs;
#[path = "skinning.rs"]
mod skinning;
#[path = "wet.rs"]
mod wet;
