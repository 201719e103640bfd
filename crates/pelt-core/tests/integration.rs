//! pelt-core's integration tests in one binary
//! (one link for all of them); each module is one file of tests beside this one.

#[path = "common/mod.rs"]
mod common;

#[path = "anim.rs"]
mod anim;
#[path = "brush.rs"]
mod brush;
#[path = "export.rs"]
mod export;
#[path = "export_morph.rs"]
mod export_morph;
#[path = "grasp_hand.rs"]
mod grasp_hand;
#[path = "groom.rs"]
mod groom;
#[path = "herd.rs"]
mod herd;
#[path = "import.rs"]
mod import;
#[path = "lights.rs"]
mod lights;
#[path = "module_order.rs"]
mod module_order;
#[path = "presets.rs"]
mod presets;
#[path = "reference.rs"]
mod reference;
#[path = "regroom.rs"]
mod regroom;
#[path = "sim.rs"]
mod sim;
#[path = "sim_collider_mesh.rs"]
mod sim_collider_mesh;
#[path = "sim_contact.rs"]
mod sim_contact;
#[path = "sim_external.rs"]
mod sim_external;
#[path = "sim_oracle.rs"]
mod sim_oracle;
#[path = "stepper.rs"]
mod stepper;
#[path = "textures.rs"]
mod textures;
#[path = "usd.rs"]
mod usd;
#[path = "wet.rs"]
mod wet;
