//! Silhouette fins: a compute pass decides once per edge per frame which fins show
//! (`silhouette.wgsl`) and writes them as the instances of an indexed indirect draw, so the fin
//! pass shades only those edges instead of every edge and every vertex testing its own edge.
//!
//! The pass goes into the host's encoder ([`crate::FurRenderer::prepare_fins`]) before the render
//! pass that draws the fur; nothing is read back, nothing blocks.

use crate::RenderError;
use crate::pipeline::listing_pipelines;
use crate::requirements::check_size;
use crate::shaders::{Layouts, silhouette_shader_source};

/// One fin instance: the edge and its fade (f32 bits).
pub(crate) const FIN_INSTANCE_BYTES: u64 = 8;
/// `wgpu::util::DrawIndexedIndirectArgs`.
const DRAW_ARGS_BYTES: u64 = 20;

/// The vertex input of the silhouette fin pipelines: one `(edge, fade bits)` per instance.
pub(crate) const FIN_INSTANCE_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: FIN_INSTANCE_BYTES,
    step_mode: wgpu::VertexStepMode::Instance,
    attributes: &[wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32x2, offset: 0, shader_location: 0 }],
};

/// The silhouette pass's two pipelines (`silhouette.wgsl`), one pair per renderer.
#[derive(Debug)]
pub(crate) struct SilhouettePipelines {
    /// Each edge's fade, one thread an edge.
    fades: wgpu::ComputePipeline,
    /// The shown fins listed in edge order, and the draw's count.
    list: wgpu::ComputePipeline,
}

/// Workgroup width of the one-thread-an-item dispatches (`cs_fin_fades`, `cs_view_lod_flags`),
/// and the most workgroups in one row of a dispatch.
const ITEMS_WIDTH: u32 = 64;
const MOST_GROUPS_PER_ROW: u32 = 65_535;

impl SilhouettePipelines {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let source = ("pelt silhouette", silhouette_shader_source());
        let [fades, list] =
            listing_pipelines(device, layouts, source, &layouts.fin_list, ["cs_fin_fades", "cs_silhouette"]);
        Self { fades, list }
    }
}

/// The workgroups of a one-thread-an-item dispatch over `items`: `(per row, rows)`.
pub(crate) fn item_groups(items: u32) -> (u32, u32) {
    let groups = items.div_ceil(ITEMS_WIDTH).max(1);
    let per_row = groups.min(MOST_GROUPS_PER_ROW);
    (per_row, groups.div_ceil(per_row))
}

/// One fur's fins as the silhouette pass leaves them: the indirect draw and its instances.
#[derive(Debug)]
pub(crate) struct FinList {
    /// `DrawIndexedIndirectArgs`: `6L` indices, the instance count the pass counted.
    pub draw: wgpu::Buffer,
    /// Up to `E` instances of [`FIN_INSTANCE_LAYOUT`].
    pub instances: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    edge_count: u32,
}

impl FinList {
    /// The list of a fur with `edge_count` edges and `layers` layers; `None` without fins.
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        edge_count: u32,
        layers: u32,
    ) -> Result<Option<Self>, RenderError> {
        if edge_count == 0 || layers == 0 {
            return Ok(None);
        }
        let instance_bytes = u64::from(edge_count) * FIN_INSTANCE_BYTES;
        check_size(device, "fin instances", instance_bytes)?;
        check_scan_width(device)?;
        let args: [u32; 5] = [6 * layers, 0, 0, 0, 0];
        let draw = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt fin draw"),
                contents: bytemuck::cast_slice(&args),
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::INDIRECT
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
            },
        );
        debug_assert_eq!(draw.size(), DRAW_ARGS_BYTES);
        let instances = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt fin instances"),
            size: instance_bytes,
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::VERTEX
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt fin list"),
            layout: &layouts.fin_list,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: draw.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: instances.as_entire_binding() },
            ],
        });
        Ok(Some(Self { draw, instances, bind_group, edge_count }))
    }

    /// Records the silhouette pass: every edge's fade, then one workgroup lists the shown fins
    /// in edge order and writes the draw's count.
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        pipelines: &SilhouettePipelines,
        view: &wgpu::BindGroup,
        object: &wgpu::BindGroup,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("pelt silhouette"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, view, &[]);
        pass.set_bind_group(1, object, &[]);
        pass.set_bind_group(3, &self.bind_group, &[]);
        pass.set_pipeline(&pipelines.fades);
        let (per_row, rows) = item_groups(self.edge_count);
        pass.dispatch_workgroups(per_row, rows, 1);
        // wgpu orders the two dispatches: both write the instances.
        pass.set_pipeline(&pipelines.list);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Writes a list decided on the CPU (`(edge, fade bits)` per fin, at most `E`) and its
    /// indirect draw of `segments` segments a fin, in place of the compute pass.
    pub fn write(&self, queue: &wgpu::Queue, fins: &[[u32; 2]], segments: u32) {
        let fins = &fins[..fins.len().min(self.edge_count as usize)];
        if !fins.is_empty() {
            queue.write_buffer(&self.instances, 0, bytemuck::cast_slice(fins));
        }
        let args: [u32; 5] = [6 * segments, fins.len() as u32, 0, 0, 0];
        queue.write_buffer(&self.draw, 0, bytemuck::cast_slice(&args));
    }

    /// GPU bytes of the list.
    pub fn bytes(&self) -> u64 {
        self.draw.size() + self.instances.size()
    }
}

/// Threads of the one workgroup that lists what shows (`SCAN_WIDTH` in `scan.wgsl`).
pub(crate) const SCAN_WIDTH: u32 = 256;

/// The listing passes need one workgroup of `SCAN_WIDTH` threads (WebGPU's default limits allow it).
pub(crate) fn check_scan_width(device: &wgpu::Device) -> Result<(), RenderError> {
    let limits = device.limits();
    let most = limits.max_compute_invocations_per_workgroup.min(limits.max_compute_workgroup_size_x);
    if most < SCAN_WIDTH {
        return Err(RenderError::Limit {
            limit: "max_compute_invocations_per_workgroup",
            got: most.into(),
            needed: SCAN_WIDTH.into(),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fade_dispatch_covers_every_edge_within_the_row_limit() {
        assert_eq!(item_groups(0), (1, 1));
        assert_eq!(item_groups(5_511), (87, 1));
        for edges in [1, 64, 65, 4_194_240, 4_194_241, 40_000_000] {
            let (per_row, rows) = item_groups(edges);
            assert!(per_row <= MOST_GROUPS_PER_ROW);
            let threads = u64::from(per_row) * u64::from(rows) * u64::from(ITEMS_WIDTH);
            assert!(threads >= u64::from(edges) && threads < u64::from(edges) + u64::from(per_row * ITEMS_WIDTH));
        }
    }
}
