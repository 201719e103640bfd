//! Shells by view angle, the culling half: the pass lists, once per frame and view, the triangles
//! that still show in the layers the next coarser stride drops (`view_lod.wgsl`), and writes one
//! indexed indirect draw per shell over that list. The renderer then draws the kept shells over
//! every triangle and the thinned ones over the list, one shell at a time from the innermost out
//! (blending needs that order). Facing the eye, most triangles leave the list.
//!
//! A fur drawn without the pass (or whose mesh is too large to number every shell's vertices in
//! one `u32`) draws every triangle in every shell, with the same view-angle fading: the same
//! picture, without the savings.

use std::sync::atomic::{AtomicBool, Ordering};

use super::fins::gathered_draws;
use super::{DRAW_ARGS_BYTES, ListingPipelines, check_scan_width, item_groups, list_bind_group};
use crate::RenderError;
use crate::requirements::check_size;
use crate::shaders::Layouts;

/// Shells one workgroup writes draws for (`cs_view_lod_draws` in `view_lod.wgsl`).
const WORKGROUP: u32 = 64;

/// The shell lists of every copy in a pool (`crate::pool`) as the pass leaves them, slot by slot.
#[derive(Debug)]
pub(crate) struct ShellList {
    /// Indices listed (3 a triangle), one `u32` a slot; `COPY_SRC` for hosts that count.
    pub listed: wgpu::Buffer,
    /// In a pool of more than one, every furred triangle's corners or base vertices (the head,
    /// which the gathered draws of the shells kept whole read); then the listed ones (the index
    /// buffer of the thinned shells), `3F` a slot; each slot's draws start at its own.
    pub indices: wgpu::Buffer,
    /// One `DrawIndexedIndirectArgs` per shell, [`DRAW_ARGS_BYTES`] apart, `L` a slot; then in a
    /// pool of more than one as many gathered ones (`crate::HerdDraws`): all `L` of a copy's
    /// shells, in order.
    pub draws: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    layers: u32,
    triangle_count: u32,
    slots: u32,
    /// Per slot, whether the pass was recorded since the copy's last `prepare` (else the list
    /// may be from another level or view, and the shells are drawn whole).
    recorded: Vec<AtomicBool>,
    /// Where the head's indices are in the topology buffer, and whether they were copied.
    head: (wgpu::Buffer, u64),
    head_filled: AtomicBool,
}

impl ShellList {
    /// The lists of `slots` copies of a fur of `triangle_count` triangles, `layers` layers and
    /// `per_shell` vertex indices a shell (the wedges with uvs, V without); `None` where there is
    /// nothing to thin (fewer than two layers) or the shells' vertex indices would not fit an
    /// `i32` base vertex.
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        (triangle_count, per_shell, layers): (u32, u32, u32),
        (slots, head): (u32, (&wgpu::Buffer, u64)),
    ) -> Result<Option<Self>, RenderError> {
        let numbered = u64::from(layers) * u64::from(per_shell);
        if layers < 2 || triangle_count == 0 || numbered > i32::MAX as u64 {
            return Ok(None);
        }
        let index_bytes = u64::from(triangle_count) * 12 * (u64::from(slots) + u64::from(slots > 1));
        check_size(device, "view-angle shell list", index_bytes)?;
        check_scan_width(device)?;
        let buffer = |label, size, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage: usage | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            })
        };
        let listed = buffer("pelt shell list count", 4 * u64::from(slots), wgpu::BufferUsages::COPY_DST);
        let indices = buffer("pelt shell list", index_bytes, wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST);
        let draws = buffer(
            "pelt shell draws",
            u64::from(layers) * DRAW_ARGS_BYTES * u64::from(gathered_draws(slots)),
            wgpu::BufferUsages::INDIRECT,
        );
        let bind_group = list_bind_group(device, "pelt shell list", &layouts.shell_list, &[&listed, &indices, &draws]);
        let recorded = (0..slots).map(|_| AtomicBool::new(false)).collect();
        let (topology, first) = head;
        let head = (topology.clone(), 4 * first);
        let head_filled = AtomicBool::new(false);
        Ok(Some(Self {
            listed,
            indices,
            draws,
            bind_group,
            layers,
            triangle_count,
            slots,
            recorded,
            head,
            head_filled,
        }))
    }

    /// Copies every furred triangle's indices into the head of [`ShellList::indices`] the first
    /// time it is called (before the first listing pass: the buffer is written nowhere else).
    pub fn fill_head(&self, encoder: &mut wgpu::CommandEncoder) {
        if self.slots > 1 && !self.head_filled.swap(true, Ordering::Relaxed) {
            let (topology, at) = &self.head;
            encoder.copy_buffer_to_buffer(topology, *at, &self.indices, 0, u64::from(self.triangle_count) * 12);
        }
    }

    /// Records the pass of every copy in the pool that thins its shells this frame (its object's
    /// `pool.w`): every triangle's flag, then one workgroup a copy lists its triangles in order,
    /// then the draws are written. `listed` are the slots this frame's draws may use the lists of.
    pub fn record(
        &self,
        pass: &mut wgpu::ComputePass<'_>,
        pipelines: &ListingPipelines<3>,
        (view, objects): (&wgpu::BindGroup, &wgpu::BindGroup),
        listed: impl IntoIterator<Item = u32>,
    ) {
        let groups = [item_groups(self.triangle_count), (1, 1), (self.layers.div_ceil(WORKGROUP), 1)];
        pipelines.record(pass, (view, objects, &self.bind_group), groups, self.slots);
        for slot in listed {
            self.recorded[slot as usize].store(true, Ordering::Relaxed);
        }
    }

    /// Forgets slot `slot`'s last pass (a new level or frame is being prepared).
    pub fn invalidate(&self, slot: u32) {
        self.recorded[slot as usize].store(false, Ordering::Relaxed);
    }

    /// Whether slot `slot`'s pass was recorded since its last [`ShellList::invalidate`].
    pub fn recorded(&self, slot: u32) -> bool {
        self.recorded[slot as usize].load(Ordering::Relaxed)
    }

    /// The byte offset of slot `slot`'s first draw in [`ShellList::draws`].
    pub fn draws_offset(&self, slot: u32) -> u64 {
        u64::from(slot) * u64::from(self.layers) * DRAW_ARGS_BYTES
    }

    /// The byte offset of the gathered draws at `position` (a copy's `L`) in [`ShellList::draws`].
    pub fn gathered_offset(&self, position: u32) -> u64 {
        (u64::from(self.slots) + u64::from(position)) * u64::from(self.layers) * DRAW_ARGS_BYTES
    }

    /// Slot `slot`'s count and indices.
    pub fn listed_of(&self, slot: u32) -> (wgpu::BufferSlice<'_>, wgpu::BufferSlice<'_>) {
        let bytes = u64::from(self.triangle_count) * 12;
        let slot = u64::from(slot);
        let first = slot + u64::from(self.slots > 1);
        (self.listed.slice(4 * slot..4 * slot + 4), self.indices.slice(first * bytes..(first + 1) * bytes))
    }

    /// GPU bytes of one slot's list.
    pub fn slot_bytes(&self) -> u64 {
        let draws = gathered_draws(self.slots) / self.slots;
        4 + u64::from(self.triangle_count) * 12 + u64::from(draws * self.layers) * DRAW_ARGS_BYTES
    }

    /// GPU bytes the pool's copies share: the head (none in a pool of one).
    pub fn head_bytes(&self) -> u64 {
        if self.slots > 1 { u64::from(self.triangle_count) * 12 } else { 0 }
    }
}
