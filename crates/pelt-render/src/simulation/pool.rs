//! The GPU simulation's buffers for the copies of one fur made together (a pool's members): each
//! copy's strand inputs, strand state and wet strands are ranges of one buffer each, so a step
//! runs every copy that takes it in one dispatch (`simulation_pooled.wgsl`; with contact, two,
//! through the pool's contact). A fur's own kernels bind its ranges and see a buffer of their own.

use std::sync::OnceLock;

use super::pool_contact::PoolContact;
use super::{STATE_BYTES, STEP_SLOT_BYTES, STRAND_BYTES};
use crate::RenderError;
use crate::requirements::{ErrorScope, check_size};
use crate::sim_pipelines::PooledStep;

/// Every range starts on this many bytes: the largest storage offset alignment WebGPU lets a
/// device ask for.
const RANGE_ALIGNMENT: u64 = 256;
/// Bytes per strand of the wet strands' weights (`vec2<f32>`).
pub(super) const WET_BYTES: u64 = 8;

/// One copy's range of a pooled buffer.
#[derive(Clone, Copy, Debug)]
pub(super) struct Range {
    pub at: u64,
    pub size: u64,
}

impl Range {
    /// The range as a binding of `buffer`.
    pub fn binding<'a>(&self, buffer: &'a wgpu::Buffer) -> wgpu::BindingResource<'a> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer,
            offset: self.at,
            size: wgpu::BufferSize::new(self.size),
        })
    }

    /// Where the range starts, in elements of `bytes`.
    pub fn first(&self, bytes: u64) -> u32 {
        u32::try_from(self.at / bytes).unwrap_or(u32::MAX)
    }
}

/// The simulation's buffers of `slots` copies of a fur of `V` strands.
#[derive(Debug)]
pub(crate) struct SimPool {
    pub strands: wgpu::Buffer,
    pub state: wgpu::Buffer,
    pub wet: wgpu::Buffer,
    vertex_count: u64,
    strands_stride: u64,
    state_stride: u64,
    wet_stride: u64,
    slots: u32,
    /// The steps of a pooled dispatch's copies, packed from 0 (copied from their rings).
    pub steps: wgpu::Buffer,
    /// The pooled step's bind group: the whole buffers, with the rest segments and the shared
    /// vertex arrays of the first copy that bound them. Copies with others step alone.
    pooled: OnceLock<((wgpu::Buffer, wgpu::Buffer), wgpu::BindGroup)>,
    /// What the pooled steps with contact read.
    pub contact: PoolContact,
}

impl SimPool {
    /// Buffers for `slots` copies of a fur of `vertex_count` strands.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when a buffer exceeds what the device binds,
    /// [`RenderError::OutOfMemory`].
    pub fn new(device: &wgpu::Device, vertex_count: usize, slots: u32) -> Result<Self, RenderError> {
        let v = vertex_count.max(1) as u64;
        let stride = |bytes: u64| (v * bytes).next_multiple_of(RANGE_ALIGNMENT);
        let (strands_stride, state_stride, wet_stride) = (stride(STRAND_BYTES), stride(STATE_BYTES), stride(WET_BYTES));
        let count = u64::from(slots.max(1));
        check_size(device, "simulation strand inputs", strands_stride * count)?;
        check_size(device, "simulation strand state", state_stride * count)?;
        check_size(device, "simulation wet strands", wet_stride * count)?;
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let scope = ErrorScope::push(device);
        // Dry strands weigh 1.
        let wet = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt simulation wet strands"),
                contents: bytemuck::cast_slice(&vec![1.0_f32; (wet_stride * count / 4) as usize]),
                usage: storage,
            },
        );
        let strands = buffer("pelt simulation strands", strands_stride * count, storage);
        // Read back by tests comparing it with the CPU's inputs.
        let state =
            buffer("pelt simulation strand state", state_stride * count, storage | wgpu::BufferUsages::COPY_SRC);
        // A lone fur never steps pooled.
        let steps =
            buffer("pelt simulation pooled steps", STEP_SLOT_BYTES * if slots > 1 { count } else { 1 }, storage);
        scope.pop("creating the GPU simulation's pool")?;
        Ok(Self {
            strands,
            state,
            wet,
            vertex_count: v,
            strands_stride,
            state_stride,
            wet_stride,
            slots: slots.max(1),
            steps,
            pooled: OnceLock::new(),
            contact: PoolContact::new(vertex_count, slots),
        })
    }

    /// The copies it holds.
    pub fn slots(&self) -> u32 {
        self.slots
    }

    /// Copy `slot`'s strand inputs, strand state and wet strands.
    pub(super) fn ranges(&self, slot: u32) -> [Range; 3] {
        let slot = u64::from(slot);
        let v = self.vertex_count;
        [
            Range { at: slot * self.strands_stride, size: v * STRAND_BYTES },
            Range { at: slot * self.state_stride, size: v * STATE_BYTES },
            Range { at: slot * self.wet_stride, size: v * WET_BYTES },
        ]
    }

    /// The bytes copy `slot` holds here: its ranges, its step's slot when pooled, and its part of
    /// the pool's contact (with the shared part for slot 0).
    pub fn slot_bytes(&self, slot: u32) -> u64 {
        let step = if self.slots > 1 { STEP_SLOT_BYTES } else { 0 };
        self.strands_stride + self.state_stride + self.wet_stride + step + self.contact.slot_bytes(slot)
    }

    /// Binds the pooled step to `rest` and `positions` (the pool's shared vertex arrays) the
    /// first time; whether a copy with those steps pooled (a lone fur never does).
    pub fn bind_pooled(
        &self,
        device: &wgpu::Device,
        pipeline: &PooledStep,
        (rest, positions): (&wgpu::Buffer, &wgpu::Buffer),
    ) -> Result<bool, RenderError> {
        if self.slots < 2 {
            return Ok(false);
        }
        if self.pooled.get().is_none() {
            let scope = ErrorScope::push(device);
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pelt simulation pooled"),
                layout: &pipeline.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: self.steps.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: rest.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: self.strands.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: self.state.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: positions.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 6, resource: self.wet.as_entire_binding() },
                ],
            });
            scope.pop("binding a herd's GPU simulation")?;
            let _ = self.pooled.set(((rest.clone(), positions.clone()), bind_group));
        }
        Ok(self.pooled_group((rest, positions)).is_some())
    }

    /// The pooled step's bind group, when it binds `rest` and `positions`.
    pub fn pooled_group(&self, (rest, positions): (&wgpu::Buffer, &wgpu::Buffer)) -> Option<&wgpu::BindGroup> {
        self.pooled.get().filter(|((r, p), _)| r == rest && p == positions).map(|(_, group)| group)
    }
}
