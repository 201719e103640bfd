//! The page's GPU: WebGPU on the canvas (opened by the renderer's rules), configured for the
//! page's frame ([`PageGpu`]), which draws into the canvas each frame. Browser failures (no
//! adapter, a lost device, a zero-size canvas, a frame the canvas does not give) are messages,
//! never panics.

use std::sync::{Arc, Mutex};

use pelt_core::FurTextures;

use crate::model::Model;
use crate::page_gpu::{CANVAS_USAGE, PageGpu};

/// What went wrong on the device since the last frame, kept by wgpu's callbacks.
#[derive(Debug, Default)]
struct DeviceTrouble {
    lost: Option<String>,
    error: Option<String>,
}

/// WebGPU on one canvas with the fur drawn into it.
#[derive(Debug)]
pub struct CanvasGpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    /// False until the canvas has a non-zero size.
    configured: bool,
    page: PageGpu,
    trouble: Arc<Mutex<DeviceTrouble>>,
    /// What the adapter says it is (e.g. SwiftShader), for the page and the figures.
    pub adapter_name: String,
}

/// Why a frame was not drawn (the page keeps going and tries again next frame).
#[derive(Debug, PartialEq, Eq)]
pub enum Skipped {
    /// The canvas has no area (hidden, collapsed).
    ZeroSize,
    /// The canvas gave no texture this time.
    NoFrame,
}

impl CanvasGpu {
    /// Opens WebGPU on `canvas` with Pelt's limits and uploads the model's fur.
    ///
    /// # Errors
    /// A message for no WebGPU adapter, an adapter Pelt cannot use, or a failed device.
    pub async fn open(
        canvas: web_sys::HtmlCanvasElement,
        model: &Model,
        textures: &FurTextures,
        tile_scale: f32,
    ) -> Result<Self, String> {
        let mut descriptor = wgpu::InstanceDescriptor::new_without_display_handle();
        descriptor.backends = wgpu::Backends::BROWSER_WEBGPU;
        let instance = wgpu::Instance::new(descriptor);
        let surface = instance
            .create_surface(wgpu::SurfaceTarget::Canvas(canvas))
            .map_err(|e| format!("WebGPU cannot draw into the canvas: {e}"))?;
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                compatible_surface: Some(&surface),
                ..wgpu::RequestAdapterOptions::default()
            })
            .await
            .map_err(|e| format!("this browser offers no WebGPU adapter ({e})"))?;
        pelt_render::check_adapter(&adapter).map_err(|e| format!("this GPU cannot draw Pelt's fur: {e}"))?;
        let info = adapter.get_info();
        let adapter_name = [info.name.as_str(), info.driver.as_str(), info.driver_info.as_str()]
            .into_iter()
            .filter(|s| !s.is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("pelt web"),
                required_features: pelt_render::required_features()
                    | pelt_render::optional_features(adapter.features()),
                required_limits: pelt_render::required_limits(&adapter.limits()),
                ..wgpu::DeviceDescriptor::default()
            })
            .await
            .map_err(|e| format!("could not open the GPU device: {e}"))?;
        let trouble = Arc::new(Mutex::new(DeviceTrouble::default()));
        let on_lost = Arc::clone(&trouble);
        device.set_device_lost_callback(move |reason, message| {
            if let Ok(mut trouble) = on_lost.lock() {
                trouble.lost = Some(format!("{reason:?}: {message}"));
            }
        });
        // wgpu's default handler panics; on a page an error is a message and the page goes on.
        let on_error = Arc::clone(&trouble);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            if let Ok(mut trouble) = on_error.lock() {
                trouble.error.get_or_insert_with(|| error.to_string());
            }
        }));

        let caps = surface.get_capabilities(&adapter);
        let format = caps.formats.first().copied().ok_or("the canvas offers no texture format")?;
        let config = wgpu::SurfaceConfiguration {
            usage: CANVAS_USAGE,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: 1,
            height: 1,
            present_mode: wgpu::PresentMode::Fifo,
            desired_maximum_frame_latency: 2,
            alpha_mode: wgpu::CompositeAlphaMode::Opaque,
            view_formats: vec![],
        };
        let page = PageGpu::new(&device, &queue, format, model, textures, tile_scale)?;
        Ok(Self { device, queue, surface, config, configured: false, page, trouble, adapter_name })
    }

    /// The message of a lost device, once it is lost (the page then starts a new one).
    #[must_use]
    pub fn lost(&self) -> Option<String> {
        self.trouble.lock().ok().and_then(|t| t.lost.clone())
    }

    /// The first GPU error since the last call, if any.
    pub fn take_error(&self) -> Option<String> {
        self.trouble.lock().ok().and_then(|mut t| t.error.take())
    }

    /// A new rest pose (scene, length or preset changed).
    ///
    /// # Errors
    /// The renderer's message (e.g. a structure over the device's limits).
    pub fn set_structure(&mut self, model: &Model) -> Result<(), String> {
        self.page.set_structure(&self.device, &self.queue, model)
    }

    /// New textures, made with a tile `tile_scale` times smaller than the preset's.
    ///
    /// # Errors
    /// The renderer's message.
    pub fn set_textures(&mut self, model: &Model, textures: &FurTextures, tile_scale: f32) -> Result<(), String> {
        self.page.set_textures((&self.device, &self.queue), model, textures, tile_scale)
    }

    /// Advances the model's fur by `frame_secs` of wall time (see [`PageGpu::advance`]).
    ///
    /// # Errors
    /// The driver's message.
    pub fn advance(&mut self, model: &mut Model, frame_secs: f64) -> Result<(), String> {
        self.page.advance(&self.device, &self.queue, model, frame_secs)
    }

    /// Draws the model into the canvas at `width_px x height_px` device pixels.
    ///
    /// # Errors
    /// The renderer's message (e.g. positions of the wrong size).
    pub fn draw(&mut self, model: &Model, width_px: u32, height_px: u32) -> Result<Result<(), Skipped>, String> {
        let limit = self.device.limits().max_texture_dimension_2d;
        let (width_px, height_px) = (width_px.min(limit), height_px.min(limit));
        if width_px == 0 || height_px == 0 {
            return Ok(Err(Skipped::ZeroSize));
        }
        if !self.configured || self.config.width != width_px || self.config.height != height_px {
            self.config.width = width_px;
            self.config.height = height_px;
            self.surface.configure(&self.device, &self.config);
            self.page.resize(&self.device, width_px, height_px)?;
            self.configured = true;
        }
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.configured = false;
                return Ok(Err(Skipped::NoFrame));
            }
            _ => return Ok(Err(Skipped::NoFrame)),
        };
        self.page.render(&self.device, &self.queue, model, &frame.texture)?;
        self.queue.present(frame);
        Ok(Ok(()))
    }
}
