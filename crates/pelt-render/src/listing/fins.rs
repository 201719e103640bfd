//! Silhouette fins: the pass decides once per edge per frame which fins show (`silhouette.wgsl`)
//! and writes them as the instances of an indexed indirect draw, so the fin pass shades only
//! those edges instead of every edge and every vertex testing its own edge.

use wgpu::util::DrawIndexedIndirectArgs;

use super::{DRAW_ARGS_BYTES, ListingPipelines, check_scan_width, item_groups, list_bind_group};
use crate::RenderError;
use crate::requirements::check_size;
use crate::shaders::Layouts;

/// One fin instance: the edge and its fade (f32 bits).
const FIN_INSTANCE_BYTES: u64 = 8;

/// The vertex input of the silhouette fin pipelines: one `(edge, fade bits)` per instance.
pub(crate) const FIN_INSTANCE_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: FIN_INSTANCE_BYTES,
    step_mode: wgpu::VertexStepMode::Instance,
    attributes: &[wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32x2, offset: 0, shader_location: 0 }],
};

/// The indirect draw of `fins` fins of `segments` segments each.
fn fin_draw(segments: u32, fins: u32) -> DrawIndexedIndirectArgs {
    DrawIndexedIndirectArgs {
        index_count: 6 * segments,
        instance_count: fins,
        first_index: 0,
        base_vertex: 0,
        first_instance: 0,
    }
}

/// The draws a pool of `slots` copies keeps a layer: its own, and the gathered ones where
/// there is more than one copy (a pool of one always draws alone).
pub(super) fn gathered_draws(slots: u32) -> u32 {
    if slots > 1 { 2 * slots } else { slots }
}

/// The fins of every copy in a pool (`crate::pool`) as the silhouette pass leaves them: slot by
/// slot, each copy's indirect draw and instances.
#[derive(Debug)]
pub(crate) struct FinList {
    /// `DrawIndexedIndirectArgs` a slot: `6L` indices, the instance count the pass counted; then
    /// in a pool of more than one as many gathered draws (`crate::HerdDraws`), each from its
    /// copy's first instance.
    pub draws: wgpu::Buffer,
    /// Up to `E` instances of [`FIN_INSTANCE_LAYOUT`] a slot.
    pub instances: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    edge_count: u32,
    slots: u32,
}

impl FinList {
    /// The lists of `slots` copies of a fur with `edge_count` edges and `layers` layers; `None`
    /// without fins.
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        (edge_count, layers): (u32, u32),
        slots: u32,
    ) -> Result<Option<Self>, RenderError> {
        if edge_count == 0 || layers == 0 {
            return Ok(None);
        }
        let instance_bytes = u64::from(edge_count) * FIN_INSTANCE_BYTES * u64::from(slots);
        check_size(device, "fin instances", instance_bytes)?;
        check_scan_width(device)?;
        let draws: Vec<u8> = (0..gathered_draws(slots)).flat_map(|_| fin_draw(layers, 0).as_bytes().to_vec()).collect();
        let draws = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt fin draws"),
                contents: &draws,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
            },
        );
        debug_assert_eq!(draws.size(), DRAW_ARGS_BYTES * u64::from(gathered_draws(slots)));
        let instances = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt fin instances"),
            size: instance_bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = list_bind_group(device, "pelt fin list", &layouts.fin_list, &[&draws, &instances]);
        Ok(Some(Self { draws, instances, bind_group, edge_count, slots }))
    }

    /// Records the silhouette pass of every copy in the pool that lists fins this frame (its
    /// object's `pool.w`): every edge's fade, then one workgroup a copy lists its shown fins in
    /// edge order and writes its draw's count (both write the instances).
    pub fn record(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipelines: &ListingPipelines<2>,
        view: &wgpu::BindGroup,
        objects: &wgpu::BindGroup,
    ) {
        pipelines.record(pass, (view, objects, &self.bind_group), [item_groups(self.edge_count), (1, 1)], self.slots);
    }

    /// Slot `slot`'s instances.
    pub fn instances_of(&self, slot: u32) -> wgpu::BufferSlice<'_> {
        let bytes = u64::from(self.edge_count) * FIN_INSTANCE_BYTES;
        self.instances.slice(u64::from(slot) * bytes..(u64::from(slot) + 1) * bytes)
    }

    /// The byte offset of slot `slot`'s indirect draw in [`FinList::draws`].
    pub fn draw_offset(slot: u32) -> u64 {
        u64::from(slot) * DRAW_ARGS_BYTES
    }

    /// The byte offset of the gathered draw at `position` in [`FinList::draws`].
    pub fn gathered_offset(&self, position: u32) -> u64 {
        (u64::from(self.slots) + u64::from(position)) * DRAW_ARGS_BYTES
    }

    /// Writes slot `slot`'s list decided on the CPU (`(edge, fade bits)` per fin, at most `E`)
    /// and its indirect draw of `segments` segments a fin, in place of the compute pass.
    #[cfg(feature = "lab")]
    pub fn write(&self, queue: &wgpu::Queue, slot: u32, fins: &[[u32; 2]], segments: u32) {
        let fins = &fins[..fins.len().min(self.edge_count as usize)];
        if !fins.is_empty() {
            queue.write_buffer(&self.instances, self.instances_of(slot).offset(), bytemuck::cast_slice(fins));
        }
        queue.write_buffer(&self.draws, Self::draw_offset(slot), fin_draw(segments, fins.len() as u32).as_bytes());
    }

    /// GPU bytes of one slot's list.
    pub fn slot_bytes(&self) -> u64 {
        u64::from(gathered_draws(self.slots) / self.slots) * DRAW_ARGS_BYTES
            + u64::from(self.edge_count) * FIN_INSTANCE_BYTES
    }
}
