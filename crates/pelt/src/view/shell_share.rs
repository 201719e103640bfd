//! The overlay's share of shell triangles drawn: the view-angle pass's count, read back without
//! waiting (a frame or two late), so the viewer never stalls on it.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};

use pelt_render::GpuFur;

const IDLE: u8 = 0;
const COPIED: u8 = 1;
const MAPPING: u8 = 2;
const MAPPED: u8 = 3;

/// One staging word cycling through copy, map and read.
#[derive(Debug)]
pub struct ShellShare {
    staging: wgpu::Buffer,
    state: Arc<AtomicU8>,
    /// Indices the pass listed, as last read.
    listed: Option<u32>,
}

impl ShellShare {
    pub fn new(device: &wgpu::Device) -> Self {
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt view shell count"),
            size: 4,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Self { staging, state: Arc::new(AtomicU8::new(IDLE)), listed: None }
    }

    /// Records the copy of this frame's count when the last one has been read (after the pass
    /// that drew `fur`).
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, fur: &GpuFur) {
        if let Some(count) = fur.view_lod_count()
            && fur.shells_thinned() > 0
            && self.state.compare_exchange(IDLE, COPIED, Ordering::AcqRel, Ordering::Acquire).is_ok()
        {
            encoder.copy_buffer_to_buffer(count.buffer(), count.offset(), &self.staging, 0, 4);
        }
    }

    /// After the frame's submission: starts mapping a recorded copy, reads a mapped one.
    pub fn after_submit(&mut self) {
        match self.state.load(Ordering::Acquire) {
            COPIED => {
                self.state.store(MAPPING, Ordering::Release);
                let state = Arc::clone(&self.state);
                self.staging.slice(..).map_async(wgpu::MapMode::Read, move |result| {
                    // A failed map starts over with the next frame's copy.
                    state.store(if result.is_ok() { MAPPED } else { IDLE }, Ordering::Release);
                });
            }
            MAPPED => {
                if let Ok(bytes) = self.staging.slice(..).get_mapped_range() {
                    self.listed = Some(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]));
                }
                self.staging.unmap();
                self.state.store(IDLE, Ordering::Release);
            }
            _ => {}
        }
    }

    /// The share of shell triangles `fur` draws at its level (the thinned shells over the
    /// listed triangles, `faces` in each other shell); `None` before the first count or without
    /// view-angle LOD.
    pub fn share(&self, fur: &GpuFur, faces: u32) -> Option<f64> {
        let thinned = f64::from(fur.shells_thinned());
        let shells = f64::from(fur.drawn_shells());
        if thinned == 0.0 || shells == 0.0 || faces == 0 {
            return None;
        }
        let faces = f64::from(faces);
        let listed = (f64::from(self.listed?) / 3.0).min(faces);
        Some((faces * (shells - thinned) + listed * thinned) / (faces * shells))
    }
}
