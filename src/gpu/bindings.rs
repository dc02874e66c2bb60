//! The kernel's bind group (`shaders/bindings.wgsl`): one table, from which both the layout
//! and the bind group are built, so the binding numbers are written once on the host.

use crate::params::Params;

/// What each binding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    /// One `Params` per dispatch of a batch, at a dynamic offset.
    Params,
    Nodes,
    Triangles,
    Attributes,
    Materials,
    Lights,
    Film,
    /// Environment rows and punctual lights (`PackedScene::light_data`).
    LightData,
    Textures,
}

/// Binding numbers and the WGSL variable bound there (tests/layout.rs checks them against
/// the kernel).
pub const TABLE: [(u32, Slot, &str); 9] = [
    (0, Slot::Params, "params"),
    (1, Slot::Nodes, "nodes"),
    (2, Slot::Triangles, "triangles"),
    (3, Slot::Attributes, "attributes"),
    (4, Slot::Materials, "materials"),
    (5, Slot::Lights, "lights"),
    (6, Slot::Film, "film"),
    (7, Slot::LightData, "light_data"),
    (8, Slot::Textures, "textures"),
];

/// A geometry binding: a storage buffer, or a texture when the scene is paged.
pub enum Geometry {
    Buffer(wgpu::Buffer),
    Texture(wgpu::TextureView),
}

/// Everything the bind group binds but the params and the film.
pub struct SceneResources {
    pub nodes: Geometry,
    pub triangles: Geometry,
    pub attributes: Geometry,
    pub materials: wgpu::Buffer,
    pub lights: wgpu::Buffer,
    pub light_data: wgpu::Buffer,
    pub textures: wgpu::TextureView,
}

impl SceneResources {
    /// Device bytes of the buffers (textures are counted where they are made).
    pub fn buffer_bytes(&self) -> u64 {
        let g = |g: &Geometry| if let Geometry::Buffer(b) = g { b.size() } else { 0 };
        g(&self.nodes)
            + g(&self.triangles)
            + g(&self.attributes)
            + self.materials.size()
            + self.lights.size()
            + self.light_data.size()
    }
}

fn storage(read_only: bool, dynamic: bool, min: Option<wgpu::BufferSize>) -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only },
        has_dynamic_offset: dynamic,
        min_binding_size: min,
    }
}

/// The bind group layout for a scene whose geometry is paged or not.
pub fn layout(device: &wgpu::Device, paged: bool) -> wgpu::BindGroupLayout {
    let params_size = wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64);
    let entries: Vec<wgpu::BindGroupLayoutEntry> = TABLE
        .iter()
        .map(|&(binding, slot, _)| {
            let ty = match slot {
                Slot::Params => storage(true, true, params_size),
                Slot::Nodes | Slot::Triangles | Slot::Attributes if paged => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Uint,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                Slot::Film => storage(false, false, None),
                Slot::Textures => wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D2Array,
                    multisampled: false,
                },
                _ => storage(true, false, None),
            };
            wgpu::BindGroupLayoutEntry { binding, visibility: wgpu::ShaderStages::COMPUTE, ty, count: None }
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("scene"), entries: &entries })
}

/// The bind group of a scene, its params and a film.
pub fn bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    scene: &SceneResources,
    params: &wgpu::Buffer,
    film: &wgpu::Buffer,
) -> wgpu::BindGroup {
    let params_size = wgpu::BufferSize::new(std::mem::size_of::<Params>() as u64);
    fn geometry(g: &Geometry) -> wgpu::BindingResource<'_> {
        match g {
            Geometry::Buffer(b) => b.as_entire_binding(),
            Geometry::Texture(v) => wgpu::BindingResource::TextureView(v),
        }
    }
    let entries: Vec<wgpu::BindGroupEntry> = TABLE
        .iter()
        .map(|&(binding, slot, _)| {
            let resource = match slot {
                Slot::Params => {
                    wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer: params, offset: 0, size: params_size })
                }
                Slot::Nodes => geometry(&scene.nodes),
                Slot::Triangles => geometry(&scene.triangles),
                Slot::Attributes => geometry(&scene.attributes),
                Slot::Materials => scene.materials.as_entire_binding(),
                Slot::Lights => scene.lights.as_entire_binding(),
                Slot::Film => film.as_entire_binding(),
                Slot::LightData => scene.light_data.as_entire_binding(),
                Slot::Textures => wgpu::BindingResource::TextureView(&scene.textures),
            };
            wgpu::BindGroupEntry { binding, resource }
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("scene"), layout, entries: &entries })
}
