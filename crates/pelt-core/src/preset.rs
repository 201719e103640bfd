//! Fur presets: everything about one fur in one TOML file.
//!
//! INTERFACE placeholder; the textures-and-presets issue fills it.
