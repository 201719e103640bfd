//! What a device must offer for Pelt, so a host can ask for it when it creates its device, and the
//! checks that turn a device without it into a clear error instead of a wgpu panic.

use crate::RenderError;

/// Storage buffers a stage binds: the GPU simulation's compute stage 8 (WebGPU's default); the
/// unified vertex shaders read 7 (two position states, base normals, wedge uvs, topology, groom
/// attributes and wetness).
const STORAGE_BUFFERS_PER_STAGE: u32 = 8;
/// View, object and textures; the silhouette pass's fin list is group 3.
const BIND_GROUPS: u32 = 4;
/// The varyings of `shading.wgsl`.
const INTER_STAGE_VARIABLES: u32 = 11;

/// wgpu features Pelt needs: none beyond WebGPU's core.
#[must_use]
pub fn required_features() -> wgpu::Features {
    wgpu::Features::empty()
}

/// wgpu features Pelt uses where the adapter has them (request them with
/// [`required_features`]): `INDIRECT_FIRST_INSTANCE`, with which a herd's camera draws gather
/// the copies whose shells the view angle thins, and their fins, into one call a level
/// ([`crate::HerdDraws`]); without it those copies draw alone, to the same picture.
#[must_use]
pub fn optional_features(adapter: wgpu::Features) -> wgpu::Features {
    adapter & wgpu::Features::INDIRECT_FIRST_INSTANCE
}

/// Downlevel capabilities Pelt needs: storage buffers in vertex shaders (the shared vertex array
/// is fetched there), compute shaders and indirect draws (the silhouette pass). Every WebGPU,
/// Vulkan, Metal and DX12 adapter has them; WebGL2 does not.
#[must_use]
pub fn required_downlevel_flags() -> wgpu::DownlevelFlags {
    wgpu::DownlevelFlags::VERTEX_STORAGE
        | wgpu::DownlevelFlags::COMPUTE_SHADERS
        | wgpu::DownlevelFlags::INDIRECT_EXECUTION
}

/// `base` (e.g. `adapter.limits()` for the largest meshes the hardware allows, or
/// [`wgpu::Limits::default`]) raised where Pelt needs more. Request these when creating the device.
#[must_use]
pub fn required_limits(base: &wgpu::Limits) -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffers_per_shader_stage: base.max_storage_buffers_per_shader_stage.max(STORAGE_BUFFERS_PER_STAGE),
        max_bind_groups: base.max_bind_groups.max(BIND_GROUPS),
        max_inter_stage_shader_variables: base.max_inter_stage_shader_variables.max(INTER_STAGE_VARIABLES),
        ..base.clone()
    }
}

/// Checks that `adapter` can run Pelt (downlevel flags and limits), for hosts that choose an
/// adapter before creating their device.
///
/// # Errors
/// [`RenderError::MissingDownlevelFlags`], [`RenderError::MissingFeatures`] or [`RenderError::Limit`].
pub fn check_adapter(adapter: &wgpu::Adapter) -> Result<(), RenderError> {
    let flags = adapter.get_downlevel_capabilities().flags;
    let missing = required_downlevel_flags() - flags;
    if !missing.is_empty() {
        return Err(RenderError::MissingDownlevelFlags { adapter: adapter.get_info().name, missing });
    }
    check_features_and_limits(adapter.features(), &adapter.limits())
}

/// The device-side check [`crate::FurRenderer::new`] runs (a device cannot report its downlevel
/// flags; pipeline creation catches a missing `VERTEX_STORAGE`).
pub(crate) fn check_features_and_limits(features: wgpu::Features, limits: &wgpu::Limits) -> Result<(), RenderError> {
    let missing = required_features() - features;
    if !missing.is_empty() {
        return Err(RenderError::MissingFeatures { missing });
    }
    let checks = [
        (
            "max_storage_buffers_per_shader_stage",
            limits.max_storage_buffers_per_shader_stage,
            STORAGE_BUFFERS_PER_STAGE,
        ),
        ("max_bind_groups", limits.max_bind_groups, BIND_GROUPS),
        ("max_inter_stage_shader_variables", limits.max_inter_stage_shader_variables, INTER_STAGE_VARIABLES),
    ];
    for (limit, got, needed) in checks {
        if got < needed {
            return Err(RenderError::Limit { limit, got: got.into(), needed: needed.into() });
        }
    }
    Ok(())
}

/// Fails with [`RenderError::TooLarge`] when `bytes` exceed what one storage binding or
/// buffer may hold on `device`.
/// Layers to allocate for a 2D array texture of `layers` layers of `width` x `height`, so every
/// backend makes it an array: wgpu's GL backend makes a texture of one layer a plain 2D texture
/// and one of square layers in a multiple of six a cube map (wgpu-hal's `get_info_from_desc`),
/// which an array view then cannot sample (every lookup reads 0: shells and shadows go black).
/// On GL one more layer where it needs it (the caller fills it as it likes); elsewhere `layers`.
pub(crate) fn array_layers(device: &wgpu::Device, (width, height): (u32, u32), layers: u32) -> u32 {
    if device.adapter_info().backend != wgpu::Backend::Gl {
        return layers;
    }
    let layers = layers.max(2);
    if width == height && layers.is_multiple_of(6) { layers + 1 } else { layers }
}

pub(crate) fn check_size(device: &wgpu::Device, what: &'static str, bytes: u64) -> Result<(), RenderError> {
    let limits = device.limits();
    let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    if bytes > limit { Err(RenderError::TooLarge { what, bytes, limit }) } else { Ok(()) }
}

/// Catches out-of-memory and validation errors of the GPU calls between `push` and `pop` and
/// turns them into [`RenderError`]s instead of a panic in wgpu's default handler, without
/// blocking: native wgpu answers a popped scope at once, so one poll reads it. On the web
/// (where the answer comes later) no scope is pushed and errors reach the device's own handler.
pub(crate) struct ErrorScope {
    #[cfg(not(target_arch = "wasm32"))]
    scopes: [wgpu::ErrorScopeGuard; 2],
}

impl ErrorScope {
    pub(crate) fn push(device: &wgpu::Device) -> Self {
        #[cfg(target_arch = "wasm32")]
        {
            let _ = device;
            Self {}
        }
        #[cfg(not(target_arch = "wasm32"))]
        {
            let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
            let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
            Self { scopes: [validation, memory] }
        }
    }

    pub(crate) fn pop(self, during: &'static str) -> Result<(), RenderError> {
        #[cfg(target_arch = "wasm32")]
        {
            let _ = during;
            Ok(())
        }
        #[cfg(not(target_arch = "wasm32"))]
        {
            // Innermost first: scopes pop in the reverse order of their pushes.
            let [validation, memory] = self.scopes;
            let validation = poll_once(validation.pop());
            let memory = poll_once(memory.pop());
            if let Some(error) = memory {
                return Err(RenderError::OutOfMemory { during, message: error.to_string() });
            }
            if let Some(error) = validation {
                return Err(RenderError::Gpu { during, message: error.to_string() });
            }
            Ok(())
        }
    }
}

/// The future's value if it is ready on the first poll; `None` (nothing learned) otherwise.
#[cfg(not(target_arch = "wasm32"))]
fn poll_once(future: impl Future<Output = Option<wgpu::Error>>) -> Option<wgpu::Error> {
    let mut future = std::pin::pin!(future);
    let mut context = std::task::Context::from_waker(std::task::Waker::noop());
    match future.as_mut().poll(&mut context) {
        std::task::Poll::Ready(error) => error,
        std::task::Poll::Pending => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_raised_only_where_needed() {
        let base = wgpu::Limits::downlevel_defaults();
        let limits = required_limits(&base);
        assert_eq!(limits.max_storage_buffers_per_shader_stage, STORAGE_BUFFERS_PER_STAGE);
        assert_eq!(limits.max_buffer_size, base.max_buffer_size);
        assert!(check_features_and_limits(wgpu::Features::empty(), &limits).is_ok());
        let error = check_features_and_limits(wgpu::Features::empty(), &base).unwrap_err();
        assert!(error.to_string().contains("max_storage_buffers_per_shader_stage = 4"), "{error}");
        let generous = wgpu::Limits { max_storage_buffers_per_shader_stage: 16, ..base };
        assert_eq!(required_limits(&generous).max_storage_buffers_per_shader_stage, 16);
    }
}
