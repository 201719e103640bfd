//! Pelt in the browser: the bunny and the paper's try-on scene drawn with WebGPU, patted with
//! pointer events (several at once), with wind, the shipped presets, fur length and colour.
//!
//! [`model`] and [`presets`] hold the page's state and touch no browser API (tested natively);
//! on `wasm32` the GPU side (`gpu`) and the JavaScript interface (`web`, `PeltApp`) build on
//! them. `web/build.sh` builds the page into `web/dist/`.

#![warn(missing_docs)]

pub mod model;
pub mod presets;

#[cfg(target_arch = "wasm32")]
mod gpu;
// wasm-bindgen's generated glue (the exports and their ABI conversions) is unsafe code; the
// module's own code has none.
#[cfg(target_arch = "wasm32")]
#[allow(unsafe_code)]
mod web;

#[cfg(target_arch = "wasm32")]
pub use web::{PeltApp, preset_names, web_tile_px};
