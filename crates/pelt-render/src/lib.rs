//! Pelt's wgpu renderer (filled by the renderer issue).
