//! Bodies that wear furred garments and that fur collides with.
//!
//! - [`transfer_weights`]: a garment skinned to a body's rig from the body's closest surface.
//! - [`BodyCapsules`]: a skinned body as one capsule per bone, posed with its skeleton.
//! - [`MeshSdf`]: a plain (rigid) closed mesh as a baked signed distance field.
//! - [`walking_try_on`]: the try-on scene with a body that walks.

mod capsules;
mod sdf;
mod transfer;
mod walk;

pub use capsules::{BodyCapsules, BoneCapsule, Capsule};
pub use sdf::{MeshSdf, SdfError};
pub use transfer::{TransferError, TransferReport, closest_on_triangle, transfer_weights};
pub use walk::{BodyError, WalkingTryOn, walking_try_on};
