//! The strand renderer: the explicit strand reference (`pelt_core::reference`) drawn strand by
//! strand as camera-facing ribbons, with the shells' camera, object uniform and lighting
//! (`hair_lighting` in `shading.wgsl`). Offline quality, not real time: it is the ground truth
//! shells and fins are measured against, so hosts render it supersampled (e.g. at 4x the size,
//! filtered down).
//!
//! Ribbons are built on the CPU once per shape of the fur (a state of the shared array) and serve
//! every view: each node carries its position, direction, root normal, colour and half width,
//! and the vertex shader turns the width toward the camera. A wet reference's strands (their
//! root's wetness) darken and shine as `wet.wgsl` makes the shells do.

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};
use pelt_core::reference::StrandReference;
use pelt_core::reference::shadow::Receiver;

use crate::RenderError;
use crate::fur::GpuFur;
use crate::renderer::FurRenderer;
use crate::requirements::{ErrorScope, check_size};
use crate::shaders::strands_shader_source;
use crate::textures::srgb_to_linear;
use crate::view::FurView;

/// One ribbon vertex; matches `StrandVertex` in `strands.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct RibbonVertex {
    position: [f32; 3],
    tangent: [f32; 3],
    normal: [f32; 3],
    colour_height: [f32; 4],
    half_width: f32,
    wetness: f32,
}

const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 6] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x4, 4 => Float32, 5 => Float32
];
/// The key light's transmittance at each ribbon vertex, in a buffer of its own (rewritten per
/// light without rebuilding the ribbons).
const TRANSMITTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 1] = wgpu::vertex_attr_array![6 => Float32];

/// The strand pipeline for the target of a [`FurRenderer`] (its layouts, so it draws with the
/// same [`FurView`]s and [`GpuFur`] uniforms).
#[derive(Debug)]
pub struct StrandRenderer {
    pipeline: wgpu::RenderPipeline,
    /// Group 2 (the strands read no fur textures).
    empty: wgpu::BindGroup,
}

impl StrandRenderer {
    /// Builds the pipeline for `renderer`'s target.
    ///
    /// # Errors
    /// [`RenderError::Gpu`] when the device rejects it.
    pub fn new(device: &wgpu::Device, renderer: &FurRenderer) -> Result<Self, RenderError> {
        let scope = ErrorScope::push(device);
        let layouts = renderer.layouts();
        let layout = layouts.pipeline_layout(device, "pelt strands", &layouts.unified_object, false);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt strands"),
            source: wgpu::ShaderSource::Wgsl(strands_shader_source().into()),
        });
        let target = renderer.target();
        let constants = [("ALPHA_TO_COVERAGE", 0.0)];
        let compilation_options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("pelt strands"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_strand"),
                compilation_options: compilation_options.clone(),
                buffers: &[
                    Some(wgpu::VertexBufferLayout {
                        array_stride: size_of::<RibbonVertex>() as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &VERTEX_ATTRIBUTES,
                    }),
                    Some(wgpu::VertexBufferLayout {
                        array_stride: size_of::<f32>() as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &TRANSMITTANCE_ATTRIBUTES,
                    }),
                ],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                // Ribbons face the camera, but their winding depends on the strand's direction.
                cull_mode: None,
                ..wgpu::PrimitiveState::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: target.depth_format,
                depth_write_enabled: Some(true),
                depth_compare: Some(target.depth_compare),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState {
                count: target.sample_count,
                mask: !0,
                alpha_to_coverage_enabled: false,
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_strand"),
                compilation_options,
                targets: &[Some(wgpu::ColorTargetState {
                    format: target.colour_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        scope.pop("building the strand pipeline")?;
        Ok(Self { pipeline, empty: layouts.empty_group.clone() })
    }

    /// Records `ribbons` as seen from `view`, with `fur`'s object uniform (model transform and
    /// look: call [`GpuFur::prepare`] first). Opaque: draw the fur's skin in the same pass
    /// (`FurDrawSettings::SKIN`) so the strands stand on it.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, view: &FurView, fur: &GpuFur, ribbons: &StrandRibbons) {
        if ribbons.index_count == 0 {
            return;
        }
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, fur.geometry().bind_group(), &[]);
        pass.set_bind_group(2, &self.empty, &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        pass.set_vertex_buffer(0, ribbons.vertices.slice(..));
        pass.set_vertex_buffer(1, ribbons.transmittance.slice(..));
        pass.set_index_buffer(ribbons.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..ribbons.index_count, 0, 0..1);
    }
}

/// The ribbons of every strand of a reference in one shape of the fur, on the GPU.
#[derive(Debug)]
pub struct StrandRibbons {
    vertices: wgpu::Buffer,
    /// The key light's transmittance per ribbon vertex (1 until [`StrandRibbons::set_transmittance`]).
    transmittance: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    strands: usize,
    /// Each pair of ribbon vertices' point on its strand (CPU side, for the traced shadow).
    points: Vec<RibbonPoint>,
}

/// One pair of ribbon vertices: the point on the strand's centre line between them.
#[derive(Clone, Copy, Debug)]
struct RibbonPoint {
    position: Vec3,
    tangent: Vec3,
    radius: f32,
    strand: u32,
}

impl StrandRibbons {
    /// Builds the ribbons of `reference` for the shared array `positions` (the rest pose or a
    /// simulation state) of the fur whose base normals are `normals`.
    ///
    /// # Errors
    /// [`RenderError::Textures`] for a shared array or normals of the wrong size,
    /// [`RenderError::TooLarge`] for more ribbon data than a buffer may hold.
    pub fn new(
        device: &wgpu::Device,
        reference: &StrandReference,
        positions: &[Vec3],
        normals: &[Vec3],
        triangles: &[[u32; 3]],
    ) -> Result<Self, RenderError> {
        let nodes = reference.node_positions(positions).map_err(|e| RenderError::Textures(e.to_string()))?;
        let radii = reference.node_radii();
        let surface = reference.field.surface();
        let mut vertices = Vec::with_capacity(nodes.len() * 2);
        let mut indices = Vec::with_capacity(nodes.len() * 6);
        let mut receivers = Vec::with_capacity(nodes.len());
        for (strand_index, placed) in (0u32..).zip(&reference.strands) {
            let strand = reference.field_strand(placed);
            let triangle = triangles
                .get(placed.triangle as usize)
                .ok_or_else(|| RenderError::Textures(format!("no triangle {} in the mesh", placed.triangle)))?;
            let strand_nodes = reference.strand_nodes(placed);
            let root_weights = strand_nodes[0].barycentric;
            let mut normal = Vec3::ZERO;
            for (k, weight) in triangle.iter().zip(root_weights.to_array()) {
                let n = normals.get(*k as usize).ok_or_else(|| RenderError::Textures("too few normals".to_owned()))?;
                normal += *n * weight;
            }
            let normal = normal.normalize_or_zero();
            // Surface mode: the mesh's texture at the root tints the strand, as on the shells.
            let tint = match (surface, placed.surface_uv) {
                (Some(image), Some(uv)) => image.sample_wrapped(uv.x, uv.y).truncate().map(srgb_to_linear),
                _ => Vec3::ONE,
            };
            let first = placed.first_node as usize;
            let points = &nodes[first..first + strand_nodes.len()];
            for (k, node) in strand_nodes.iter().enumerate() {
                let tangent = if k + 1 < points.len() { points[k + 1] - points[k] } else { points[k] - points[k - 1] };
                // The texture's 8-bit sRGB colour, as the shells sample it.
                let albedo = reference
                    .field
                    .colour(strand, node.height)
                    .map(|c| srgb_to_linear((c.clamp(0.0, 1.0) * 255.0).round() / 255.0))
                    * tint;
                let half_width = radii[first + k];
                let colour_height = Vec4::from((albedo, node.height)).to_array();
                let base = vertices.len() as u32;
                for side in [-1.0, 1.0] {
                    vertices.push(RibbonVertex {
                        position: points[k].to_array(),
                        tangent: tangent.to_array(),
                        normal: normal.to_array(),
                        colour_height,
                        half_width: half_width * side,
                        wetness: placed.wetness,
                    });
                }
                receivers.push(RibbonPoint { position: points[k], tangent, radius: half_width, strand: strand_index });
                if k + 1 < points.len() {
                    indices.extend_from_slice(&[base, base + 1, base + 3, base, base + 3, base + 2]);
                }
            }
        }
        let vertex_bytes: &[u8] = bytemuck::cast_slice(&vertices);
        let index_bytes: &[u8] = bytemuck::cast_slice(&indices);
        check_size(device, "strand ribbon vertices", vertex_bytes.len() as u64)?;
        check_size(device, "strand ribbon indices", index_bytes.len() as u64)?;
        let buffer = |label, contents: &[u8], usage| {
            wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage },
            )
        };
        // An empty reference still gets (unused) buffers of a valid size.
        let pad = |bytes: &[u8]| if bytes.is_empty() { vec![0u8; 4] } else { bytes.to_vec() };
        Ok(Self {
            vertices: buffer("pelt strand ribbons", &pad(vertex_bytes), wgpu::BufferUsages::VERTEX),
            transmittance: buffer(
                "pelt strand transmittance",
                &pad(bytemuck::cast_slice(&vec![1.0f32; vertices.len()])),
                wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
            ),
            indices: buffer("pelt strand ribbon indices", &pad(index_bytes), wgpu::BufferUsages::INDEX),
            index_count: indices.len() as u32,
            strands: reference.strands.len(),
            points: receivers,
        })
    }

    /// The points that take the key light, one per pair of ribbon vertices in their order, as
    /// a camera at `eye` sees them (model space: the fur's transform is left out): each on its
    /// strand's centre line, `across` it as `vs_strand` widens the ribbon, `cross(tangent, to
    /// the camera)`. Trace them with `pelt_core::reference::shadow::ribbon_transmittance`.
    #[must_use]
    pub fn shadow_receivers(&self, eye: Vec3) -> Vec<Receiver> {
        self.points
            .iter()
            .map(|p| {
                let tangent = p.tangent.normalize_or(Vec3::Y);
                let across = tangent
                    .cross((eye - p.position).normalize_or(Vec3::Z))
                    .normalize_or(tangent.any_orthonormal_vector());
                Receiver { position: p.position, across, radius: p.radius, strand: p.strand }
            })
            .collect()
    }

    /// Sets how much of the key light (light 0) reaches each ribbon vertex: per pair in the
    /// order of [`StrandRibbons::shadow_receivers`], the vertex on the `-across` and on the
    /// `+across` side; `None`: 1 everywhere (unshadowed). It multiplies the key light's share of
    /// a strand's light only.
    ///
    /// # Errors
    /// [`RenderError::Textures`] for a list of another length than the receivers.
    pub fn set_transmittance(&self, queue: &wgpu::Queue, per_pair: Option<&[[f32; 2]]>) -> Result<(), RenderError> {
        let values: Vec<f32> = match per_pair {
            Some(values) if values.len() == self.points.len() => values.iter().flatten().copied().collect(),
            Some(values) => {
                return Err(RenderError::Textures(format!(
                    "{} transmittance values for {} ribbon points",
                    values.len(),
                    self.points.len()
                )));
            }
            None => vec![1.0; 2 * self.points.len()],
        };
        if !values.is_empty() {
            queue.write_buffer(&self.transmittance, 0, bytemuck::cast_slice(&values));
        }
        Ok(())
    }

    /// Strands drawn.
    #[must_use]
    pub fn strand_count(&self) -> usize {
        self.strands
    }

    /// Triangles drawn (two per strand segment).
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.index_count as usize / 3
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shaders::{assert_vertex_mirrors, rust_layout};

    #[test]
    fn ribbon_vertex_mirrors_strand_vertex() {
        let rust = rust_layout!(RibbonVertex { position, tangent, normal, colour_height, half_width, wetness });
        assert_vertex_mirrors(&strands_shader_source(), "StrandVertex", &rust, &VERTEX_ATTRIBUTES);
    }
}
