//! The per-frame listing passes: compute passes that decide, one thread an item, what shows this
//! frame, then list what shows in the items' order (one workgroup, `scan.wgsl`) for indexed
//! indirect draws. [`fins`]: the silhouette pass (which fins show). [`shells`]: shells by view
//! angle (which triangles the thinned shells still need).
//!
//! Both have one shape, kept here: their pipelines ([`ListingPipelines`]) bind the view and a
//! pool's objects (`crate::pool`: every copy of one fur made together) in groups 0 and 1 and the
//! pool's lists in group 3, and each dispatch lists every copy of the pool that lists this frame
//! (workgroup z is the copy's slot), in a compute pass in the host's encoder
//! ([`crate::FurRenderer::prepare_fins`]) before the render pass that draws the furs. Nothing is
//! read back, nothing blocks.

mod fins;
mod shells;

pub(crate) use fins::{FIN_INSTANCE_LAYOUT, FinList};
pub(crate) use shells::ShellList;

use wgpu::util::DrawIndexedIndirectArgs;

use crate::RenderError;
use crate::shaders::{Layouts, silhouette_shader_source, view_lod_shader_source};

/// One indexed indirect draw as the passes write it (`FinDraw`, `ShellDraw` in the WGSL).
pub(crate) const DRAW_ARGS_BYTES: u64 = size_of::<DrawIndexedIndirectArgs>() as u64;

/// Workgroup width of the one-thread-an-item dispatches (`ITEMS_WIDTH` in `scan.wgsl`), and the
/// most workgroups in one row of a dispatch.
const ITEMS_WIDTH: u32 = 64;
const MOST_GROUPS_PER_ROW: u32 = 65_535;
/// Threads of the one workgroup that lists what shows (`SCAN_WIDTH` in `scan.wgsl`).
const SCAN_WIDTH: u32 = 256;

/// Both listing passes' pipelines, one set per renderer.
#[derive(Debug)]
pub(crate) struct ListingPasses {
    /// Each edge's fade, then the shown fins listed in edge order with the draw's count.
    pub silhouette: ListingPipelines<2>,
    /// Each triangle's flag, then the list, then one draw per shell.
    pub view_lod: ListingPipelines<3>,
}

impl ListingPasses {
    pub fn new(device: &wgpu::Device, layouts: &Layouts) -> Self {
        Self {
            silhouette: ListingPipelines::new(
                device,
                layouts,
                ("pelt silhouette", silhouette_shader_source()),
                &layouts.fin_list,
                ["cs_fin_fades", "cs_silhouette"],
            ),
            view_lod: ListingPipelines::new(
                device,
                layouts,
                ("pelt view lod", view_lod_shader_source()),
                &layouts.shell_list,
                ["cs_view_lod_flags", "cs_view_lod_list", "cs_view_lod_draws"],
            ),
        }
    }
}

/// The compute pipelines of one listing pass, in dispatch order: one module, the view and unified
/// object in groups 0 and 1, the fur's list in group 3.
#[derive(Debug)]
pub(crate) struct ListingPipelines<const N: usize> {
    label: &'static str,
    pipelines: [wgpu::ComputePipeline; N],
}

impl<const N: usize> ListingPipelines<N> {
    /// One pipeline per entry point of the module `source`.
    fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        (label, source): (&'static str, String),
        list_layout: &wgpu::BindGroupLayout,
        entry_points: [&str; N],
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&layouts.view), Some(&layouts.pool_objects), None, Some(list_layout)],
            immediate_size: 0,
        });
        let pipelines = entry_points.map(|entry_point| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            })
        });
        Self { label, pipelines }
    }

    /// Records the dispatches into `pass`: pipeline `k` over `groups[k]` workgroups (x, y) for
    /// each of a pool's `slots` copies (z), in order, with `view`, the pool's `objects` and its
    /// `lists` bound. wgpu orders the dispatches: each sees every write of the one before.
    fn record(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        (view, objects, lists): (&wgpu::BindGroup, &wgpu::BindGroup, &wgpu::BindGroup),
        groups: [(u32, u32); N],
        slots: u32,
    ) {
        pass.push_debug_group(self.label);
        pass.set_bind_group(0, view, &[]);
        pass.set_bind_group(1, objects, &[]);
        pass.set_bind_group(3, lists, &[]);
        for (pipeline, (x, y)) in self.pipelines.iter().zip(groups) {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups(x, y, slots);
        }
        pass.pop_debug_group();
    }
}

/// The workgroups of a one-thread-an-item dispatch over `items`: `(per row, rows)`.
fn item_groups(items: u32) -> (u32, u32) {
    let groups = items.div_ceil(ITEMS_WIDTH).max(1);
    let per_row = groups.min(MOST_GROUPS_PER_ROW);
    (per_row, groups.div_ceil(per_row))
}

/// The listing passes need one workgroup of `SCAN_WIDTH` threads (WebGPU's default limits allow it).
fn check_scan_width(device: &wgpu::Device) -> Result<(), RenderError> {
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

/// The bind group of one fur's list (group 3): `buffers` at bindings `0..`.
fn list_bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<_> = (0..)
        .zip(buffers)
        .map(|(binding, buffer)| wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn item_dispatch_covers_every_item_within_the_row_limit() {
        assert_eq!(item_groups(0), (1, 1));
        assert_eq!(item_groups(5_511), (87, 1));
        for items in [1, 64, 65, 4_194_240, 4_194_241, 40_000_000] {
            let (per_row, rows) = item_groups(items);
            assert!(per_row <= MOST_GROUPS_PER_ROW);
            let threads = u64::from(per_row) * u64::from(rows) * u64::from(ITEMS_WIDTH);
            assert!(threads >= u64::from(items) && threads < u64::from(items) + u64::from(per_row * ITEMS_WIDTH));
        }
    }

    /// The Rust constants are the WGSL ones.
    #[test]
    fn widths_match_scan_wgsl() {
        let source = silhouette_shader_source();
        assert!(source.contains(&format!("const SCAN_WIDTH: u32 = {SCAN_WIDTH}u;")));
        assert!(source.contains(&format!("const ITEMS_WIDTH: u32 = {ITEMS_WIDTH}u;")));
        assert!(source.contains(&format!("@workgroup_size({ITEMS_WIDTH})")));
        assert!(source.contains(&format!("@workgroup_size({SCAN_WIDTH})")));
    }
}
