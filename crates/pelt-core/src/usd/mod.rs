//! USD's text format (`.usda`), the subset Pelt writes and reads: hair as
//! `UsdGeomBasisCurves` and a base mesh as `UsdGeomMesh`, the interchange Blender, Houdini,
//! Maya and Omniverse share for strand grooms.
//!
//! No Rust crate both reads and writes USD within Pelt's toolchain (`openusd` needs a newer
//! Rust than Pelt builds with and reads only), so this module holds its own:
//!
//! - [`UsdaWriter`] (`write`) streams a layer to any `Write`: stage metadata, nested prims,
//!   attributes with metadata, arrays written item by item and time samples, so a large curve
//!   set is never formatted in memory first.
//! - [`read_curves`] (`read`, over the tokens of `lex`) reads a layer from a `BufRead` in one pass and keeps only what a
//!   strand groom needs: the stage's `upAxis` and `metersPerUnit`, every `BasisCurves` prim's
//!   counts, points (the default value, else the earliest time sample), basis, type, wrap and
//!   `primvars:displayColor` (and Pelt's own `primvars:pelt:lengthFactor` and
//!   `primvars:pelt:textureOffset`), each placed by its prims' `xformOp`s (`xform`); `curves` evaluates
//!   each basis. Other values are parsed and
//!   dropped; a curve set's points are held once, as `f32`.
//!
//! The grammar read: the `#usda 1.0` header; layer, prim and property metadata (`( ... )`, list
//! ops, doc strings, dictionaries); `def`, `over` and `class` prims with a type and children;
//! attributes (`custom`, `uniform`, array types, `.timeSamples`, `.connect`) and relationships;
//! variant sets (read past); values: numbers, `inf`/`nan`, strings (single, double and
//! triple-quoted), tokens, asset paths, prim paths, tuples, arrays and dictionaries; `#`
//! comments. A binary crate file (`.usdc`) or a `.usdz` archive is refused with a message that
//! says so.

mod curves;
mod lex;
mod read;
mod write;
mod xform;

use std::path::PathBuf;

pub use curves::{CurveBasis, CurveType, CurveWrap, Curves};
pub use read::{UsdCurves, read_curves, read_curves_from};
pub use write::{StageMetadata, UpAxis, UsdaWriter, format_f32};

/// Why a USD file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum UsdError {
    /// The file could not be opened or read.
    #[error("{}: cannot read: {error}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// The text does not follow USDA's grammar.
    #[error("{}:{line}: {problem}", file.display())]
    Syntax {
        /// The file.
        file: PathBuf,
        /// 1-based line.
        line: usize,
        /// What was expected or found.
        problem: String,
    },
    /// The file is valid text but not something Pelt can use (a binary crate file, a curve
    /// with too few points, counts that do not match the points).
    #[error("{}: {problem}", file.display())]
    Content {
        /// The file.
        file: PathBuf,
        /// What is wrong, naming the prim where there is one.
        problem: String,
    },
}
