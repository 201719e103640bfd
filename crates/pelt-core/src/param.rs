//! The error for a parameter outside its range, shared by every module that validates preset
//! keys (textures, colour, simulation); it sits below them all.

/// A parameter outside its allowed range: its preset key and what is allowed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{key}: {problem}")]
pub struct ParamError {
    /// The key as written in a preset, e.g. `simulation.stability`.
    pub key: String,
    /// What is wrong and the allowed range.
    pub problem: String,
}
