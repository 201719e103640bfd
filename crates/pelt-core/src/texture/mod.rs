//! Seeded shell and fin textures (PAPER-NOTES section 3).
//!
//! INTERFACE (fixed so the renderer can build against it; the textures issue fills the rest).

/// The generated textures of one fur, in the layout the renderer uploads directly.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FurTextures {
    /// Shell tiles are `size x size` texels and wrap seamlessly.
    pub size: u32,
    /// Number of shell slices: slice `k` is drawn on shell layer `k + 1` (`k = 0..L`).
    pub layers: u32,
    /// RGBA8, slice-major (`layers * size * size * 4` bytes): one upload as a 2D array texture.
    /// RGB is the strand colour (straight, not premultiplied), A its coverage.
    pub shell: Vec<u8>,
    /// The fin texture: the side view of the same strands, u along the edge, v up the strand
    /// (row 0 = tips, last row = roots).
    pub fin_width: u32,
    pub fin_height: u32,
    /// RGBA8, `fin_width * fin_height * 4` bytes.
    pub fin: Vec<u8>,
}
