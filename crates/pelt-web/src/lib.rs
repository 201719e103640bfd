//! Pelt in the browser: the bunny, the paper's try-on scene and the groomed Fox drawn with
//! WebGPU, patted, parted with a finger, grasped and sponged wet with pointer events (several at
//! once), with wind, the shipped presets, fur length and colour, and a key light dragged about,
//! casting shadows on the fur and on a ground.
//!
//! [`model`] and [`presets`] hold the page's state and [`page_gpu`] its frame on a GPU device;
//! none touches a browser API, so they are tested natively (the frame on lavapipe, against
//! `pelt render`'s look). On `wasm32` the canvas (`gpu`) and the JavaScript interface (`web`,
//! `PeltApp`) build on them. `web/build.sh` builds the page into `web/dist/`.

#![warn(missing_docs)]

pub mod herd;
pub mod light;
pub mod model;
pub mod orbit;
pub mod page_gpu;
pub mod presets;
pub mod scene;
pub mod tools;

#[cfg(target_arch = "wasm32")]
mod gpu;
// wasm-bindgen's generated glue (the exports and their ABI conversions) is unsafe code; the
// module's own code has none.
#[cfg(target_arch = "wasm32")]
#[allow(unsafe_code)]
mod web;

#[cfg(target_arch = "wasm32")]
pub use web::{PeltApp, preset_names, web_tile_px};
