//! The bind group layouts every pipeline of one renderer shares (groups 0 to 3 of `shading.wgsl`,
//! `silhouette.wgsl` and `view_lod.wgsl`), and the samplers the fur textures are read with.

/// The bind group layouts and samplers of one renderer, shared by everything it draws.
#[derive(Debug, Clone)]
pub(crate) struct Layouts {
    /// Group 0: the view uniform and the lights.
    pub view: wgpu::BindGroupLayout,
    /// Group 1 of the unified structure and plain meshes: the object uniform and the storage
    /// buffers (positions twice, base normals, wedge uvs, topology, groom attributes, wetness).
    pub unified_object: wgpu::BindGroupLayout,
    /// A pool's copies as the listing passes read them (`crate::pool`).
    pub pool_objects: wgpu::BindGroupLayout,
    /// Group 1 of a pool's shadow casters: `unified_object`'s bindings, the objects of every
    /// copy in place of one uniform (`pool_draws.wgsl`).
    pub pool_draws: wgpu::BindGroupLayout,
    /// Group 1 of the separated structure: the object uniform and the fin vertices.
    #[cfg(feature = "lab")]
    pub separated_object: wgpu::BindGroupLayout,
    /// Group 2: a fur's textures and the samplers.
    pub textures: wgpu::BindGroupLayout,
    /// Group 3 of the silhouette pass: a fur's fin list.
    pub fin_list: wgpu::BindGroupLayout,
    /// Group 3 of the view-angle pass: a fur's shell list.
    pub shell_list: wgpu::BindGroupLayout,
    pub shell_sampler: wgpu::Sampler,
    pub fin_sampler: wgpu::Sampler,
    /// Group 3 of every drawing pipeline: the lights' shadow maps (`shadows.wgsl`).
    pub shadow: wgpu::BindGroupLayout,
    /// Group 2 of plain meshes: nothing.
    pub empty: wgpu::BindGroupLayout,
    pub empty_group: wgpu::BindGroup,
    /// Group 3 of views without shadow maps: 1x1 stand-ins, read by no pipeline they draw with.
    pub no_shadows: wgpu::BindGroup,
    /// The opaque shadow map's filtered comparison and the opacity layers' filtering.
    pub shadow_compare: wgpu::Sampler,
    pub shadow_linear: wgpu::Sampler,
}

impl Layouts {
    pub fn new(device: &wgpu::Device) -> Self {
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        // The silhouette pass (compute) reads the view, the object and its positions too.
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let entry = |binding, visibility, ty| wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None };
        let view = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt view"),
            // The view, then the fur model's lights and environment.
            entries: &[entry(0, both, uniform), entry(1, both, uniform)],
        });
        // Storage buffers are read by vertex shaders and the silhouette pass only, so fragment
        // stages need no storage.
        let vertex = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::COMPUTE;
        let unified_object = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt unified object"),
            entries: &[
                entry(0, both, uniform),
                entry(1, vertex, storage),
                entry(2, vertex, storage),
                entry(3, vertex, storage),
                entry(4, vertex, storage),
                entry(5, vertex, storage),
                // A groom's attributes and the wetness: vertex shaders only, so the listing
                // passes stay within WebGPU's 8 storage buffers per compute stage.
                entry(6, wgpu::ShaderStages::VERTEX, storage),
                entry(7, wgpu::ShaderStages::VERTEX, storage),
            ],
        });
        // A pool's copies for the listing passes (`object_pool.wgsl`): their objects, the states
        // (bound twice, as the draws bind a copy's previous and current), the normals and the
        // shared topology; within WebGPU's 8 storage buffers per compute stage with the lists.
        let compute = wgpu::ShaderStages::COMPUTE;
        let pool_objects = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt pool objects"),
            entries: &[
                entry(0, compute, storage),
                entry(1, compute, storage),
                entry(2, compute, storage),
                entry(3, compute, storage),
                entry(5, compute, storage),
            ],
        });
        // A pool's shadow casters: 8 storage buffers in the vertex stage, the objects also in the
        // opacity fragments.
        let pool_draws = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt pool draws"),
            entries: &[
                entry(0, wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT, storage),
                entry(1, wgpu::ShaderStages::VERTEX, storage),
                entry(2, wgpu::ShaderStages::VERTEX, storage),
                entry(3, wgpu::ShaderStages::VERTEX, storage),
                entry(4, wgpu::ShaderStages::VERTEX, storage),
                entry(5, wgpu::ShaderStages::VERTEX, storage),
                entry(6, wgpu::ShaderStages::VERTEX, storage),
                entry(7, wgpu::ShaderStages::VERTEX, storage),
            ],
        });
        // The separated fins' vertices, read back by each fin vertex to decide for its whole fin.
        #[cfg(feature = "lab")]
        let separated_object = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt separated object"),
            // A groom's per-vertex attributes and each fin's two base vertices.
            entries: &[
                entry(0, both, uniform),
                entry(1, vertex, storage),
                entry(2, vertex, storage),
                entry(3, vertex, storage),
            ],
        });
        let texture = |view_dimension| wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: true },
            view_dimension,
            multisampled: false,
        };
        let filtering = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering);
        let fragment = wgpu::ShaderStages::FRAGMENT;
        // Shells and fins look their shadows up per vertex, the skin and plain meshes per fragment.
        let render = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let depth_texture = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Depth,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let unfilterable = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let textures = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt fur textures"),
            entries: &[
                entry(0, fragment, texture(wgpu::TextureViewDimension::D2Array)),
                entry(1, fragment, texture(wgpu::TextureViewDimension::D2)),
                entry(2, fragment, filtering),
                entry(3, fragment, filtering),
                entry(4, fragment, texture(wgpu::TextureViewDimension::D2)),
                // The strands' keep values (a groom's density), fetched by texel.
                entry(5, fragment, texture(wgpu::TextureViewDimension::D2Array)),
                // The strands' tilts (a wet coat's per-strand lighting), filtered.
                entry(6, fragment, texture(wgpu::TextureViewDimension::D2Array)),
            ],
        });
        let shadow = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt shadows"),
            entries: &[
                entry(0, render, uniform),
                entry(1, render, depth_texture),
                entry(2, render, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison)),
                // The fur's first-surface depth, fetched by texel as a float texture (GLSL
                // cannot fetch from a depth texture).
                entry(3, render, unfilterable),
                entry(4, render, texture(wgpu::TextureViewDimension::D2Array)),
                entry(5, render, filtering),
            ],
        });
        let empty = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("pelt empty"), entries: &[] });
        let empty_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt empty"),
            layout: &empty,
            entries: &[],
        });
        let clamped = |label, compare| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                compare,
                ..wgpu::SamplerDescriptor::default()
            })
        };
        let shadow_compare = clamped("pelt shadow compare", Some(wgpu::CompareFunction::LessEqual));
        let shadow_linear = clamped("pelt shadow linear", None);
        let no_shadows = stand_in_shadows(device, &shadow, (&shadow_compare, &shadow_linear));
        let sampler = |label, v_mode| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v: v_mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                ..wgpu::SamplerDescriptor::default()
            })
        };
        Self {
            view,
            unified_object,
            pool_objects,
            pool_draws,
            #[cfg(feature = "lab")]
            separated_object,
            textures,
            // The fin list: the indirect draw and its instances.
            fin_list: list_layout(device, "pelt fin list", 2),
            // The shell list: the count, the listed indices and one indirect draw per shell.
            shell_list: list_layout(device, "pelt shell list", 3),
            shell_sampler: sampler("pelt shell sampler", wgpu::AddressMode::Repeat),
            // Fin rows run root to tip: clamp so the tips do not bleed into the roots.
            fin_sampler: sampler("pelt fin sampler", wgpu::AddressMode::ClampToEdge),
            shadow,
            empty,
            empty_group,
            no_shadows,
            shadow_compare,
            shadow_linear,
        }
    }

    /// The layout of pipelines that draw with `object` in group 1, with textures or the empty
    /// group in group 2, and the shadows in group 3.
    pub fn pipeline_layout(
        &self,
        device: &wgpu::Device,
        label: &str,
        object: &wgpu::BindGroupLayout,
        with_textures: bool,
    ) -> wgpu::PipelineLayout {
        let textures = if with_textures { &self.textures } else { &self.empty };
        device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&self.view), Some(object), Some(textures), Some(&self.shadow)],
            immediate_size: 0,
        })
    }

    /// Group 3 over a shadow uniform and the three maps.
    pub fn shadow_group(
        &self,
        device: &wgpu::Device,
        uniform: &wgpu::Buffer,
        (depth, fur_depth, opacity): (&wgpu::TextureView, &wgpu::TextureView, &wgpu::TextureView),
    ) -> wgpu::BindGroup {
        shadow_group(
            device,
            &self.shadow,
            uniform,
            (depth, fur_depth, opacity),
            (&self.shadow_compare, &self.shadow_linear),
        )
    }
}

/// The layout of one fur's list (group 3 of a listing pass): `buffers` storage buffers the
/// compute stage writes, at bindings `0..buffers`.
fn list_layout(device: &wgpu::Device, label: &str, buffers: u32) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = (0..buffers)
        .map(|binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only: false },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
}

fn shadow_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    uniform: &wgpu::Buffer,
    (depth, fur_depth, opacity): (&wgpu::TextureView, &wgpu::TextureView, &wgpu::TextureView),
    (compare, linear): (&wgpu::Sampler, &wgpu::Sampler),
) -> wgpu::BindGroup {
    let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("pelt shadows"),
        layout,
        entries: &[
            entry(0, uniform.as_entire_binding()),
            entry(1, wgpu::BindingResource::TextureView(depth)),
            entry(2, wgpu::BindingResource::Sampler(compare)),
            entry(3, wgpu::BindingResource::TextureView(fur_depth)),
            entry(4, wgpu::BindingResource::TextureView(opacity)),
            entry(5, wgpu::BindingResource::Sampler(linear)),
        ],
    })
}

/// A `size` x `size` texture of `format` with `layers` layers (one per light view), whole as an
/// array view; `attachment`: drawn into as well.
pub(crate) fn shadow_texture(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    (size, layers): (u32, u32),
    attachment: bool,
) -> wgpu::Texture {
    let usage = if attachment {
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::RENDER_ATTACHMENT
    } else {
        wgpu::TextureUsages::TEXTURE_BINDING
    };
    // GL's extra layer, if any, stays unused.
    let layers = crate::requirements::array_layers(device, (size, size), layers);
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("pelt shadow map"),
        size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

/// The whole of a shadow texture as an array view (one layer too: the shaders read arrays).
pub(crate) fn array_view(texture: &wgpu::Texture) -> wgpu::TextureView {
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..wgpu::TextureViewDescriptor::default()
    })
}

/// The shadows' group for views without a shadow map: nothing in it is read.
fn stand_in_shadows(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    samplers: (&wgpu::Sampler, &wgpu::Sampler),
) -> wgpu::BindGroup {
    let uniform = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("pelt no shadows"),
        size: size_of::<super::ShadowUniform>() as u64,
        usage: wgpu::BufferUsages::UNIFORM,
        mapped_at_creation: false,
    });
    let depth = array_view(&shadow_texture(device, SHADOW_DEPTH_FORMAT, (1, 1), false));
    let opacity = array_view(&shadow_texture(device, SHADOW_OPACITY_FORMAT, (1, 1), false));
    shadow_group(device, layout, &uniform, (&depth, &depth, &opacity), samplers)
}

/// The shadow maps' depth format.
pub(crate) const SHADOW_DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// The opacity layers' format: four layers, blended additively.
pub(crate) const SHADOW_OPACITY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
