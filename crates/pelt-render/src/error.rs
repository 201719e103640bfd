//! Everything that can go wrong in the renderer, with messages that say what to do.

/// Errors from creating a GPU or a renderer, uploading fur or rendering a frame.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No adapter of the requested backend (headless [`crate::Gpu`] only).
    #[error(
        "no GPU adapter found for backend {backend} ({source}). On Linux without a GPU install a software \
         driver: `apt-get install mesa-vulkan-drivers` (Vulkan via lavapipe) or `libegl1 libgl1-mesa-dri` (GL via \
         llvmpipe), then try `--backend vulkan` or `--backend gl`"
    )]
    NoAdapter {
        /// The backend asked for.
        backend: String,
        /// wgpu's reason.
        source: wgpu::RequestAdapterError,
    },
    /// The adapter refused to open a device.
    #[error("the GPU adapter {adapter:?} refused to create a device: {source}")]
    NoDevice {
        /// The adapter's name.
        adapter: String,
        /// wgpu's reason.
        source: wgpu::RequestDeviceError,
    },
    /// The adapter lacks downlevel capabilities Pelt needs (see [`crate::required_downlevel_flags`]).
    #[error(
        "the GPU adapter {adapter:?} lacks {missing:?}, which the unified fur structure needs (it reads storage \
         buffers in vertex shaders); try another backend (`--backend vulkan`)"
    )]
    MissingDownlevelFlags {
        /// The adapter's name.
        adapter: String,
        /// The flags it lacks.
        missing: wgpu::DownlevelFlags,
    },
    /// The device lacks features Pelt needs (see [`crate::required_features`]).
    #[error("the device lacks the features {missing:?}; request `pelt_render::required_features()` when creating it")]
    MissingFeatures {
        /// The features it lacks.
        missing: wgpu::Features,
    },
    /// A device limit is below what Pelt needs (see [`crate::required_limits`]).
    #[error(
        "the device allows {limit} = {got}, Pelt needs at least {needed}; request \
         `pelt_render::required_limits(&adapter.limits())` when creating the device"
    )]
    Limit {
        /// The name of the limit in [`wgpu::Limits`].
        limit: &'static str,
        /// The device's value.
        got: u64,
        /// What Pelt needs.
        needed: u64,
    },
    /// The target description cannot work (see [`crate::FurTarget`]).
    #[error("invalid fur target: {0}")]
    Target(String),
    /// An unknown backend name (headless [`crate::Gpu`] only).
    #[error("unknown backend {0:?}: choose vulkan, gl, metal, dx12 or auto")]
    UnknownBackend(String),
    /// A buffer would exceed the device's size limits.
    #[error(
        "the {what} needs {bytes} bytes but this GPU allows at most {limit} bytes per buffer; use a smaller mesh or \
         fewer layers"
    )]
    TooLarge {
        /// Which buffer.
        what: &'static str,
        /// Its size.
        bytes: u64,
        /// The device's limit.
        limit: u64,
    },
    /// The GPU ran out of memory.
    #[error("the GPU ran out of memory while {during}: {message}")]
    OutOfMemory {
        /// What Pelt was doing.
        during: &'static str,
        /// wgpu's message.
        message: String,
    },
    /// wgpu reported a validation error.
    #[error("GPU error while {during}: {message}")]
    Gpu {
        /// What Pelt was doing.
        during: &'static str,
        /// wgpu's message.
        message: String,
    },
    /// An upload of `(L + 1) * V` positions or `V` normals got another count.
    #[error("got {got} {what}, but the structure has {expected} ({rule})")]
    Count {
        /// What was uploaded.
        what: &'static str,
        /// The count the structure needs.
        expected: usize,
        /// The count given.
        got: usize,
        /// How the expected count is made, e.g. `(L + 1) * V`.
        rule: &'static str,
    },
    /// The fur textures are malformed.
    #[error("invalid fur textures: {0}")]
    Textures(String),
    /// A groom that does not fit the fur, or a fur uploaded without one.
    #[error("groom: {0}")]
    Groom(String),
    /// A target of a size the device cannot hold.
    #[error("the target is {width}x{height}; both sides must be between 1 and {limit}")]
    TargetSize {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The device's largest 2D texture side.
        limit: u32,
    },
    /// The simulation refused an input (a non-finite pose or script key, bad parameters).
    #[error("simulation: {0}")]
    Simulation(#[source] pelt_core::sim::SimError),
    /// Reading a frame back failed (headless only).
    #[error("reading the frame back from the GPU failed: {0}")]
    Readback(String),
}
