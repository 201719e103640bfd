//! One fur on the GPU in the unified structure: its shared vertex array (one or two simulation
//! states), rest topology, uvs, base normals, textures and per-fur uniform.

use std::sync::atomic::{AtomicBool, Ordering};

use glam::Vec3;
use pelt_core::FurStructure;
use pelt_core::texture::FurTextures;

use crate::RenderError;
use crate::asset::FurAsset;
use crate::geometry::{Furred, SharedGeometry, UnifiedGeometry};
use crate::listing::{FinList, ShellList};
use crate::lod::PreparedLevel;
use crate::object::{FurFrame, GpuBytes};
use crate::pool::{LIST_FINS, LIST_SHELLS, MemberPool};
use crate::requirements::ErrorScope;
use crate::shaders::Layouts;
use crate::textures::GpuTextures;
use crate::view::ShadowLookups;

/// How many simulation states a [`GpuFur`] keeps on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FurStates {
    /// One shared array: the host uploads the positions to draw each frame (e.g. the CPU
    /// simulation's interpolated output). Half the memory.
    One,
    /// The previous and the current state; the vertex shader draws
    /// `previous * (1 - t) + current * t` with `t` = [`FurFrame::interpolation`], so a
    /// simulation uploads (or computes) once per step, not once per frame.
    #[default]
    Two,
}

/// Which of a fur's optional looks its shells and fins are drawn with: each has its own
/// pipelines, so a dry, ungroomed coat runs none of the groom's or the wetness's shader code
/// (`GROOM` and `WET` in `shading.wgsl`) and interpolates none of their varyings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Coat {
    /// The groom's density, clump or tint reach the shading.
    pub groomed: bool,
    /// Some strand is wet.
    pub wet: bool,
    /// The view it is drawn through reads shadow maps (`SHADOWS` in `shadows.wgsl`): a coat
    /// seen without shadows runs none of their lookups.
    pub shadowed: bool,
    /// The fur model lights it (else Kajiya-Kay).
    pub fur_model: bool,
    /// The maps hold one view, light 0's (`SHADOW_KEY_ONLY`): the lookups read it at fixed
    /// offsets.
    pub key_shadows: bool,
}

impl Coat {
    /// Dry and ungroomed, Kajiya-Kay, without shadows: the lean entry points.
    pub const PLAIN: Self = Self { groomed: false, wet: false, shadowed: false, fur_model: false, key_shadows: false };
    /// Every coat, by [`Coat::index`].
    pub const COUNT: usize = 32;

    pub fn index(self) -> usize {
        usize::from(self.groomed)
            | usize::from(self.wet) << 1
            | usize::from(self.shadowed) << 2
            | usize::from(self.fur_model) << 3
            | usize::from(self.key_shadows) << 4
    }

    /// The entry point of `name`'s kind for this coat: the lean one, or its `_groomed` twin.
    pub fn entry(self, name: &str) -> String {
        if self.groomed || self.wet { format!("{name}_groomed") } else { name.to_owned() }
    }

    /// The same coat, seen with `lookups`.
    pub fn shadowed(self, lookups: ShadowLookups) -> Self {
        Self { shadowed: lookups != ShadowLookups::Off, key_shadows: lookups == ShadowLookups::Key, ..self }
    }
}

/// One fur's GPU data: draw it with [`FurRenderer::draw`](crate::FurRenderer::draw) into any pass
/// of the renderer's target, as many furs per pass as you like.
///
/// # The shared arrays, for hosts that write them on the GPU
/// Each state is a range of a buffer (starting on a multiple of 256 bytes; copies made together
/// keep their states in one buffer) of `(L + 1) * V` positions `NV[i * V + j]` (layer `i`, base
/// vertex `j`), each three little-endian `f32` (x, y, z) packed with no padding (12 bytes, so
/// WGSL reads it as `array<f32>`), in model space; usage
/// [`POSITIONS_USAGE`](crate::POSITIONS_USAGE) (`STORAGE | VERTEX | COPY_DST | COPY_SRC`). A
/// compute pass (e.g. a GPU simulation) steps by calling [`GpuFur::swap_states`] and then
/// writing the new state into [`GpuFur::current_positions`], reading the last one from
/// [`GpuFur::previous_positions`]. The base normals ([`GpuFur::base_normals`]) are a range of
/// `V` packed xyz `f32` triples likewise (`STORAGE | COPY_DST | COPY_SRC`).
#[derive(Debug)]
pub struct GpuFur {
    geometry: UnifiedGeometry,
    /// What it shares with the other copies of its fur (its geometry's shared part and the
    /// textures).
    asset: FurAsset,
    /// The level of detail of the last `prepare`.
    level: PreparedLevel,
    /// Whether the last `prepare`'s frame was wet (its coat's pipelines read the wetness).
    wet: AtomicBool,
    /// Whether the last `prepare`'s look was the fur model.
    fur_model: AtomicBool,
}

impl GpuFur {
    /// [`GpuFur::new`] with the layouts of the renderer it is drawn with.
    pub(crate) fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layouts: &Layouts,
        structure: &FurStructure,
        textures: &FurTextures,
        states: FurStates,
    ) -> Result<Self, RenderError> {
        let asset = FurAsset::upload(device, queue, layouts, structure, textures)?;
        Self::instance(device, layouts, &asset, states)
    }

    /// [`GpuFur::from_asset`] with the renderer's layouts.
    pub(crate) fn instance(
        device: &wgpu::Device,
        layouts: &Layouts,
        asset: &FurAsset,
        states: FurStates,
    ) -> Result<Self, RenderError> {
        let mut copies = Self::copies(device, layouts, asset, states, 1)?;
        Ok(copies.remove(0))
    }

    /// `count` copies of `asset`, their own state in shared pools (`crate::pool`) as large as the
    /// device binds: the listing passes list a pool's copies in one dispatch.
    pub(crate) fn copies(
        device: &wgpu::Device,
        layouts: &Layouts,
        asset: &FurAsset,
        states: FurStates,
        count: usize,
    ) -> Result<Vec<Self>, RenderError> {
        let scope = ErrorScope::push(device);
        let (positions, normals) = &*asset.rest;
        let shared = &asset.geometry;
        let states = state_count(states);
        let most = MemberPool::most_slots(device, shared.shape, states) as usize;
        let made = (|| {
            let mut copies = Vec::with_capacity(count);
            let mut left = count;
            while left > 0 {
                let slots = left.min(most);
                let mesh = (positions.as_slice(), normals.as_slice());
                let pool = UnifiedGeometry::pool(device, layouts, shared, mesh, (states, slots as u32))?;
                copies.extend((0..slots as u32).map(|slot| Self {
                    geometry: UnifiedGeometry::in_pool(device, layouts, shared, &pool, slot),
                    asset: asset.clone(),
                    level: PreparedLevel::new(),
                    wet: AtomicBool::new(false),
                    fur_model: AtomicBool::new(false),
                }));
                left -= slots;
            }
            Ok(copies)
        })();
        scope.pop("uploading the fur")?;
        made
    }

    /// What this fur shares with every copy made from it ([`GpuFur::from_asset`]).
    #[must_use]
    pub fn asset(&self) -> &FurAsset {
        &self.asset
    }

    /// [`GpuFur::set_structure`] with the renderer's layouts: a new asset of its own (other
    /// copies of the old one keep it).
    pub(crate) fn upload_structure(
        &mut self,
        device: &wgpu::Device,
        layouts: &Layouts,
        structure: &FurStructure,
    ) -> Result<(), RenderError> {
        let states = if self.geometry.state_count() == 1 { FurStates::One } else { FurStates::Two };
        let scope = ErrorScope::push(device);
        let furred = Furred::of(structure);
        let shared =
            SharedGeometry::new(device, (&structure.mesh, furred.as_ref(), structure.groom.as_ref()), structure.layers);
        scope.pop("uploading the fur")?;
        let asset = FurAsset::from_parts(shared?, self.asset.textures.clone(), structure);
        let fresh = Self::instance(device, layouts, &asset, states)?;
        (self.geometry, self.asset) = (fresh.geometry, fresh.asset);
        Ok(())
    }

    /// [`GpuFur::set_textures`] with the renderer's layouts.
    pub(crate) fn upload_textures(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layouts: &Layouts,
        textures: &FurTextures,
    ) -> Result<(), RenderError> {
        let scope = ErrorScope::push(device);
        let textures = GpuTextures::new(device, queue, layouts, textures, self.geometry.shape.groomed);
        scope.pop("uploading the fur textures")?;
        self.asset = self.asset.with_textures(textures?);
        Ok(())
    }

    /// Rewrites the groom's density, clump and tint (one small buffer write, no new textures or
    /// geometry): the cheap path for painting them. The fur must have been grown with a groom
    /// (any map; `set_structure` with a groomed structure first), and for density its textures
    /// uploaded while it had one (`new` or `set_textures`), which brings the strands' keep
    /// values. Lengths and directions shape the shared array: they change with
    /// [`GpuFur::set_structure`]. Takes effect at the next [`GpuFur::prepare`].
    ///
    /// # Errors
    /// [`RenderError::Groom`] for a fur without a groom, a density map on textures without keep
    /// values, or a groom that does not fit the mesh.
    pub fn set_groom(&mut self, queue: &wgpu::Queue, groom: &pelt_core::groom::Groom) -> Result<(), RenderError> {
        if self.geometry.shape.groomed && groom.density.is_some() && !self.asset.textures.has_keep {
            return Err(RenderError::Groom(
                "a density map needs the textures uploaded with a groom (set_textures after set_structure)".to_owned(),
            ));
        }
        self.geometry.set_groom(queue, groom)
    }

    /// Bytes the groom adds on the GPU: the per-vertex attributes (32 a vertex) and the strands'
    /// keep values (one byte a shell texel). 0 without a groom.
    #[must_use]
    pub fn groom_bytes(&self) -> u64 {
        let keep = if self.asset.textures.has_keep { self.asset.textures.keep_bytes } else { 0 };
        self.geometry.groom_bytes() + keep
    }

    /// Writes this frame's model transform, interpolation and look (takes effect at the next
    /// submission; one transform per fur and submission).
    pub fn prepare(&self, queue: &wgpu::Queue, frame: &FurFrame) {
        let textures = self.asset.textures.shape;
        // One state has nothing to interpolate; 1 lets the shader fetch it once.
        let frame = if self.geometry.state_count() == 1 { FurFrame { interpolation: 1.0, ..*frame } } else { *frame };
        // A fading coat's skin turns from the roots' colour to the coat's.
        let coat = frame.level.clamped(self.geometry.shape.layers).coat;
        let skin = if coat >= 1.0 {
            self.asset.textures.root_colour
        } else {
            let look = &frame.look;
            self.asset
                .textures
                .coat_colour(look.root_occlusion, look.shading.fur_model)
                .lerp(self.asset.textures.root_colour, coat)
        };
        let tint = frame.look.tint;
        let skin = if tint.is_finite() { skin * tint.max(Vec3::ZERO) } else { skin };
        self.level.set(frame.level, self.geometry.shape.layers);
        // What the listing passes list of it this frame, should they be recorded.
        let uniform = self.geometry.shape.uniform(&frame, skin, textures);
        self.geometry.write_uniform(queue, &uniform, self.lists());
        self.wet.store(frame.wet, Ordering::Relaxed);
        if frame.wet {
            self.asset.textures.bind_wet(queue);
        }
        self.fur_model.store(frame.look.shading.fur_model, Ordering::Relaxed);
        if let Some(list) = self.shell_list() {
            list.invalidate(self.slot());
        }
    }

    /// Writes `positions` (`(L + 1) * V`, layer-major, model space) into both states: the
    /// one-state way to animate (upload what to draw, every frame).
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there are exactly `(L + 1) * V` positions.
    pub fn set_positions(&self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<(), RenderError> {
        self.geometry.set_positions(queue, positions)
    }

    /// Writes both states at once (with [`FurStates::One`] only `current` is kept).
    ///
    /// # Errors
    /// [`RenderError::Count`] unless both have `(L + 1) * V` positions.
    pub fn set_states(&self, queue: &wgpu::Queue, previous: &[Vec3], current: &[Vec3]) -> Result<(), RenderError> {
        self.geometry.set_states(queue, previous, current)
    }

    /// A new simulation step: the current state becomes the previous one and `positions` the
    /// current one. One upload per step; frames between steps only change
    /// [`FurFrame::interpolation`].
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there are exactly `(L + 1) * V` positions.
    pub fn push_state(&mut self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<(), RenderError> {
        self.geometry.push_state(queue, positions)
    }

    /// Makes the current state the previous one; the buffer that held the previous state becomes
    /// [`GpuFur::current_positions`], to be overwritten with the new state (e.g. by a compute
    /// pass). With [`FurStates::One`] nothing changes.
    pub fn swap_states(&mut self) {
        self.geometry.swap_states();
    }

    /// The current (newer) state: a range of a buffer that may hold other copies' states too
    /// (copies made together share one); see the layout in [`GpuFur`].
    #[must_use]
    pub fn current_positions(&self) -> wgpu::BufferSlice<'_> {
        self.geometry.current()
    }

    /// The previous (older) state; the same range as the current one with [`FurStates::One`].
    #[must_use]
    pub fn previous_positions(&self) -> wgpu::BufferSlice<'_> {
        self.geometry.previous()
    }

    /// Replaces the base normals (`V` of them, model space, unit length): an animated mesh's
    /// posed normals. They start as the rest normals.
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there are exactly `V` normals.
    pub fn set_base_normals(&self, queue: &wgpu::Queue, normals: &[Vec3]) -> Result<(), RenderError> {
        self.geometry.set_normals(queue, normals)
    }

    /// Replaces the wetness per base vertex (`V` values in `0..=1`; they start at 0). The
    /// shaders read it only for a [`FurFrame`] with `wet` set.
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there are exactly `V` values.
    pub fn set_wetness(&self, queue: &wgpu::Queue, wetness: &[f32]) -> Result<(), RenderError> {
        self.geometry.set_wetness(queue, wetness)
    }

    /// The base normals' range of their buffer; see the layout in [`GpuFur`].
    #[must_use]
    pub fn base_normals(&self) -> wgpu::BufferSlice<'_> {
        self.geometry.normals()
    }

    /// Bytes this fur holds on the GPU (both states of the shared array when it keeps two). The
    /// silhouette pass's per-frame list (8 bytes per edge, [`GpuFur::silhouette_list_bytes`]) is
    /// working memory, not structure, and is not counted here.
    #[must_use]
    pub fn gpu_bytes(&self) -> GpuBytes {
        GpuBytes { textures: self.asset.textures.bytes + self.asset.textures.tilt_bytes(), ..self.geometry.bytes() }
    }

    /// Bytes this copy holds apart from its [`FurAsset`] ([`FurAsset::gpu_bytes`]): the shared
    /// array's states and the base normals. A herd of `n` holds `n` times this, the asset once,
    /// and each copy's [`GpuFur::silhouette_list_bytes`].
    #[must_use]
    pub fn own_bytes(&self) -> GpuBytes {
        self.geometry.own_bytes()
    }

    /// Bytes of the silhouette pass's fin list (the edges it keeps and their indirect draw) and
    /// of the view-angle pass's shell list (12 bytes a triangle, 20 a layer), each draw twice
    /// in a herd (its own and the gathered one, [`crate::HerdDraws`]).
    #[must_use]
    pub fn silhouette_list_bytes(&self) -> u64 {
        self.pool().slot_list_bytes()
    }

    /// Bytes the lists of the copies made together with this one share: every furred
    /// triangle's indices once (12 bytes a triangle) for the gathered draws; none for a fur
    /// made alone.
    #[must_use]
    pub fn herd_list_bytes(&self) -> u64 {
        self.pool().shared_list_bytes()
    }

    /// The view-angle pass's count (one little-endian `u32`, `COPY_SRC`): three times the
    /// triangles drawn in each shell the view angle thins, when [`GpuFur::shells_thinned`].
    /// For hosts and benchmarks that read it back; `None` for a fur with fewer than two layers.
    #[must_use]
    pub fn view_lod_count(&self) -> Option<wgpu::BufferSlice<'_>> {
        self.shell_list().map(|list| list.listed_of(self.slot()).0)
    }

    /// The view-angle pass's list (`COPY_SRC`): as many little-endian `u32`s as
    /// [`GpuFur::view_lod_count`] says, three a triangle, each a triangle corner (meshes with
    /// uvs: `3 * triangle + k`) or a base vertex (meshes without), in no particular order. A
    /// groomed fur numbers its triangles with the furred ones first (`FurStructure::furred_triangles`
    /// in order, then the bald ones).
    #[must_use]
    pub fn view_lod_indices(&self) -> Option<wgpu::BufferSlice<'_>> {
        self.shell_list().map(|list| list.listed_of(self.slot()).1)
    }

    /// The shells the level of the last [`GpuFur::prepare`] thins by view angle (drawn over the
    /// view-angle pass's list when [`crate::FurRenderer::prepare_fins`] was recorded after it);
    /// 0 without view-angle LOD.
    #[must_use]
    pub fn shells_thinned(&self) -> u32 {
        let layers = self.geometry.shape.layers;
        if !self.level.by_view() {
            return 0;
        }
        (0..self.drawn_shells()).filter(|&k| self.level.dropped_shell(layers, k)).count() as u32
    }

    /// The silhouette pass's indirect draw (`wgpu::util::DrawIndexedIndirectArgs`, 20 bytes,
    /// `COPY_SRC`): its second `u32` is the number of fins the last pass kept. For hosts and
    /// benchmarks that read it back; `None` for a fur without fins.
    #[must_use]
    pub fn silhouette_draw(&self) -> Option<wgpu::BufferSlice<'_>> {
        let at = FinList::draw_offset(self.slot());
        self.fin_list().map(|list| list.draws.slice(at..at + crate::listing::DRAW_ARGS_BYTES))
    }

    /// The fins the silhouette pass (or the `lab` feature's `GpuFur::prepare_fins_on_cpu`) kept:
    /// `(edge, fade as f32 bits)` as two little-endian `u32`s per fin (a groomed fur's `edge`
    /// indexes `FurStructure::fin_edges`), in no particular order, as
    /// many as the indirect draw's instance count ([`GpuFur::silhouette_draw`]); `COPY_SRC`. For
    /// hosts and tests that read it back; `None` for a fur without fins.
    #[must_use]
    pub fn silhouette_instances(&self) -> Option<wgpu::BufferSlice<'_>> {
        self.fin_list().map(|list| list.instances_of(self.slot()))
    }

    /// `L`, the shell layers above the base.
    #[must_use]
    pub fn layers(&self) -> u32 {
        self.geometry.shape.layers
    }

    /// `V`, the base vertices (strands).
    #[must_use]
    pub fn vertex_count(&self) -> u32 {
        self.geometry.shape.vertex_count
    }

    pub(crate) fn geometry(&self) -> &UnifiedGeometry {
        &self.geometry
    }

    /// The coat the last `prepare` left the fur drawing with.
    pub(crate) fn coat(&self) -> Coat {
        Coat {
            groomed: self.geometry.shape.groom_shading,
            wet: self.wet.load(Ordering::Relaxed),
            shadowed: false,
            key_shadows: false,
            fur_model: self.fur_model.load(Ordering::Relaxed),
        }
    }

    pub(crate) fn textures_bind_group(&self) -> &wgpu::BindGroup {
        self.asset.textures.bind_group()
    }

    /// What the listing passes list of it at the level of its last `prepare`
    /// ([`LIST_FINS`], [`LIST_SHELLS`]): its fins while they show, its shells while the view
    /// angle thins them, nothing once its coat has faded.
    pub(crate) fn lists(&self) -> u32 {
        let level = &self.level;
        if !level.coat_shown() {
            return 0;
        }
        let fins = self.fin_list().is_some() && level.fins_shown();
        let shells = self.shell_list().is_some() && level.by_view();
        (u32::from(fins) * LIST_FINS) | (u32::from(shells) * LIST_SHELLS)
    }

    /// Its pool's fin lists (its own is at [`GpuFur::slot`]).
    pub(crate) fn fin_list(&self) -> Option<&FinList> {
        self.pool().fins()
    }

    /// Its pool's shell lists (its own is at [`GpuFur::slot`]).
    pub(crate) fn shell_list(&self) -> Option<&ShellList> {
        self.pool().shells()
    }

    /// The pool its own state lives in (`crate::pool`).
    pub(crate) fn pool(&self) -> &std::sync::Arc<MemberPool> {
        self.geometry.slot().0
    }

    /// Its slot in [`GpuFur::pool`].
    pub(crate) fn slot(&self) -> u32 {
        self.geometry.slot().1
    }

    pub(crate) fn prepared_level(&self) -> &PreparedLevel {
        &self.level
    }

    /// Shells (and fin segments) drawn at the level of the last [`GpuFur::prepare`].
    #[must_use]
    pub fn drawn_shells(&self) -> u32 {
        self.level.get().shells(self.geometry.shape.layers)
    }

    /// Whether the level of the last [`GpuFur::prepare`] draws fins (and records their silhouette
    /// pass): not once the coat or the fins have faded out ([`crate::FurLevel::fins`]).
    #[must_use]
    pub fn fins_drawn(&self) -> bool {
        self.level.fins_shown()
    }
}

fn state_count(states: FurStates) -> usize {
    match states {
        FurStates::One => 1,
        FurStates::Two => 2,
    }
}
