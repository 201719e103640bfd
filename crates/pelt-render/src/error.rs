//! Everything that can go wrong in the renderer, with messages that say what to do.

/// Errors from creating a GPU, uploading fur or rendering a frame.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(
        "no GPU adapter found for backend {backend} ({source}). On Linux without a GPU install a software \
         driver: `apt-get install mesa-vulkan-drivers` (Vulkan via lavapipe) or `libegl1 libgl1-mesa-dri` (GL via \
         llvmpipe), then try `--backend vulkan` or `--backend gl`"
    )]
    NoAdapter { backend: String, source: wgpu::RequestAdapterError },
    #[error("the GPU adapter {adapter:?} refused to create a device: {source}")]
    NoDevice { adapter: String, source: wgpu::RequestDeviceError },
    #[error(
        "the GPU adapter {adapter:?} cannot read storage buffers in vertex shaders, which the unified fur \
         structure needs; try another backend (`--backend vulkan`)"
    )]
    NoVertexStorage { adapter: String },
    #[error("unknown backend {0:?}: choose vulkan, gl, metal, dx12 or auto")]
    UnknownBackend(String),
    #[error(
        "the {what} needs {bytes} bytes but this GPU allows at most {limit} bytes per buffer; use a smaller mesh or \
         fewer layers"
    )]
    TooLarge { what: &'static str, bytes: u64, limit: u64 },
    #[error("the GPU ran out of memory while {during}: {message}")]
    OutOfMemory { during: &'static str, message: String },
    #[error("GPU error while {during}: {message}")]
    Gpu { during: &'static str, message: String },
    #[error("got {got} shared vertex positions, but the structure has {expected} ((L + 1) * V)")]
    PositionCount { expected: usize, got: usize },
    #[error("invalid fur textures: {0}")]
    Textures(String),
    #[error("the fur has {fur} layers but its textures have {textures} shell slices")]
    LayerMismatch { fur: u32, textures: u32 },
    #[error("the target is {width}x{height}; both sides must be between 1 and {limit}")]
    TargetSize { width: u32, height: u32, limit: u32 },
    #[error("reading the frame back from the GPU failed: {0}")]
    Readback(String),
}
