//! The GPU for Pelt's own commands and tests: instance, adapter, device and queue, chosen by
//! backend, created blocking (the `headless` feature). Hosts bring their own device instead.

use std::fmt;
use std::str::FromStr;

use crate::RenderError;

/// Which graphics API to ask for an adapter.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Backend {
    /// `WGPU_BACKEND` when set, else every backend wgpu supports here (a real GPU wins).
    #[default]
    Auto,
    /// Vulkan (lavapipe without a GPU).
    Vulkan,
    /// OpenGL / GLES (llvmpipe without a GPU).
    Gl,
    /// Metal.
    Metal,
    /// Direct3D 12.
    Dx12,
}

impl Backend {
    fn backends(self) -> wgpu::Backends {
        match self {
            Self::Auto => wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all()),
            Self::Vulkan => wgpu::Backends::VULKAN,
            Self::Gl => wgpu::Backends::GL,
            Self::Metal => wgpu::Backends::METAL,
            Self::Dx12 => wgpu::Backends::DX12,
        }
    }
}

impl FromStr for Backend {
    type Err = RenderError;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        match name.to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "vulkan" | "vk" => Ok(Self::Vulkan),
            "gl" | "gles" | "opengl" => Ok(Self::Gl),
            "metal" => Ok(Self::Metal),
            "dx12" | "d3d12" => Ok(Self::Dx12),
            _ => Err(RenderError::UnknownBackend(name.to_owned())),
        }
    }
}

impl fmt::Display for Backend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self {
            Self::Auto => "auto",
            Self::Vulkan => "vulkan",
            Self::Gl => "gl",
            Self::Metal => "metal",
            Self::Dx12 => "dx12",
        };
        f.write_str(name)
    }
}

/// The best adapter of `backends`: a real GPU if there is one, else a software one.
fn request_adapter(backends: wgpu::Backends) -> Result<(wgpu::Instance, wgpu::Adapter), wgpu::RequestAdapterError> {
    let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
    descriptor.backends = backends;
    let instance = wgpu::Instance::new(descriptor);
    let options = wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        ..wgpu::RequestAdapterOptions::default()
    };
    let adapter = match pollster::block_on(instance.request_adapter(&options)) {
        Ok(adapter) => adapter,
        // Some drivers only list a CPU adapter as the fallback one.
        Err(first) => pollster::block_on(
            instance.request_adapter(&wgpu::RequestAdapterOptions { force_fallback_adapter: true, ..options }),
        )
        .map_err(|_| first)?,
    };
    Ok((instance, adapter))
}

/// An adapter with its device and queue.
#[derive(Debug)]
pub struct Gpu {
    /// The instance the adapter came from (window surfaces are made with it).
    pub instance: wgpu::Instance,
    /// The adapter.
    pub adapter: wgpu::Adapter,
    /// The device, with [`crate::required_limits`] of the adapter's own limits.
    pub device: wgpu::Device,
    /// The device's queue.
    pub queue: wgpu::Queue,
}

impl Gpu {
    /// Opens the best adapter of `backend` without a window (headless rendering, tests).
    ///
    /// Prefers a real GPU; a software one (lavapipe, llvmpipe) is used when it is all there is.
    ///
    /// # Errors
    /// [`RenderError::NoAdapter`] (with install advice), [`RenderError::NoDevice`] or
    /// what [`crate::check_adapter`] finds.
    pub fn new(backend: Backend) -> Result<Self, RenderError> {
        // Auto tries the modern APIs first and GL only without them: probing GL (EGL) prints
        // warnings on machines without a display, which a working Vulkan makes pointless.
        let attempts = match backend {
            Backend::Auto if wgpu::Backends::from_env().is_none() => {
                vec![wgpu::Backends::PRIMARY, wgpu::Backends::GL]
            }
            _ => vec![backend.backends()],
        };
        let mut last_error = None;
        for backends in attempts {
            match request_adapter(backends) {
                Ok((instance, adapter)) => return Self::from_adapter(instance, adapter),
                Err(error) => last_error = Some(error),
            }
        }
        let source = last_error.expect("at least one attempt");
        Err(RenderError::NoAdapter { backend: backend.to_string(), source })
    }

    /// Opens a device on `adapter` (e.g. one compatible with a window surface) with the limits
    /// the renderer needs: the adapter's own, so large meshes fit where the hardware allows.
    ///
    /// # Errors
    /// [`RenderError::NoDevice`] or what [`crate::check_adapter`] finds.
    pub fn from_adapter(instance: wgpu::Instance, adapter: wgpu::Adapter) -> Result<Self, RenderError> {
        crate::check_adapter(&adapter)?;
        let name = adapter.get_info().name;
        let descriptor = wgpu::DeviceDescriptor {
            label: Some("pelt"),
            required_features: crate::required_features() | crate::optional_features(adapter.features()),
            required_limits: crate::required_limits(&adapter.limits()),
            ..wgpu::DeviceDescriptor::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&descriptor))
            .map_err(|source| RenderError::NoDevice { adapter: name, source })?;
        Ok(Self { instance, adapter, device, queue })
    }

    /// One line naming the adapter, its backend and driver.
    #[must_use]
    pub fn summary(&self) -> String {
        let info = self.adapter.get_info();
        format!("{} ({:?}, {:?}, {})", info.name, info.backend, info.device_type, info.driver_info)
    }
}
