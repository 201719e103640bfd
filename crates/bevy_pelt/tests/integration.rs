//! bevy_pelt's tests through Bevy on a real adapter in one binary
//! (one link for all of them); each module is one file of tests beside this one.

#[path = "common/mod.rs"]
mod common;

#[path = "environment.rs"]
mod environment;
#[path = "herd.rs"]
mod herd;
#[path = "interaction.rs"]
mod interaction;
#[path = "lights.rs"]
mod lights;
#[path = "passes.rs"]
mod passes;
#[path = "render.rs"]
mod render;
