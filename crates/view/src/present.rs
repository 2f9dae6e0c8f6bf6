//! Drawing a frame to the window: the frame's texture (uploaded from the CPU or copied on the
//! GPU from `fray-gpu`'s targets) blitted to the surface, nearest texel, with no readback.

use wgpu::util::DeviceExt;

/// What the blit shows of its source texture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DebugView {
    /// The picture: tone-mapped sRGB colour.
    #[default]
    Colour,
    /// Depth as grey, `exp(−depth / scale)`, black where nothing was hit.
    Depth,
    /// Normals as `0.5 + 0.5 n`, black where nothing was hit.
    Normals,
}

/// The blit's uniform (`blit.wgsl`'s `Blit`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BlitParams {
    surface: [f32; 2],
    source: [f32; 2],
    mode: u32,
    srgb_surface: u32,
    depth_scale: f32,
    pad: f32,
}

/// A texture the blit draws from.
#[derive(Debug)]
struct Source {
    texture: wgpu::Texture,
    bind_group: wgpu::BindGroup,
}

/// The blit pipeline and the textures it draws: `picture` (RGBA8, sRGB bytes) and `data`
/// (RGBA32F: the GPU's colour + depth or normals, for the debug views).
#[derive(Debug)]
pub struct Presenter {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    srgb_surface: bool,
    picture: Option<Source>,
    data: Option<Source>,
    /// Which of the two the last frame filled, and how to show it.
    showing: Option<(bool, DebugView)>,
    pub depth_scale: f32,
}

impl Presenter {
    /// The blit for a surface of `format`.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("blit"),
            source: wgpu::ShaderSource::Wgsl(include_str!("blit.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("blit"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    // Not filterable: RGBA32F binds here as well as RGBA8 (read by textureLoad).
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("blit"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("blit"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            multiview_mask: None,
            cache: None,
        });
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("blit params"),
            contents: bytemuck::bytes_of(&BlitParams::zeroed()),
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        });
        Self {
            pipeline,
            layout,
            params,
            srgb_surface: format.is_srgb(),
            picture: None,
            data: None,
            showing: None,
            depth_scale: 1.0,
        }
    }

    /// A source texture of `format` and size, reused while the size holds.
    fn source<'s>(
        &self,
        slot: &'s mut Option<Source>,
        device: &wgpu::Device,
        format: wgpu::TextureFormat,
        (width, height): (u32, u32),
    ) -> &'s Source {
        let fits = slot
            .as_ref()
            .is_some_and(|s| (s.texture.width(), s.texture.height()) == (width, height));
        if !fits {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("viewer frame"),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            });
            let view = texture.create_view(&Default::default());
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("blit"),
                layout: &self.layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: self.params.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::TextureView(&view),
                    },
                ],
            });
            *slot = Some(Source {
                texture,
                bind_group,
            });
        }
        slot.as_ref()
            .unwrap_or_else(|| unreachable!("filled above"))
    }

    /// Uploads a CPU picture: `width × height` RGBA8 texels of sRGB bytes.
    pub fn upload_picture(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        rgba: &[u8],
    ) {
        let mut slot = self.picture.take();
        let source = self.source(
            &mut slot,
            device,
            wgpu::TextureFormat::Rgba8Unorm,
            (width, height),
        );
        queue.write_texture(
            source.texture.as_image_copy(),
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * width),
                rows_per_image: Some(height),
            },
            source.texture.size(),
        );
        self.picture = slot;
        self.showing = Some((true, DebugView::Colour));
    }

    /// Copies a frame `fray-gpu` left on the device (GPU to GPU): its display texture for the
    /// picture, its colour + depth or normal texture for a debug view.
    pub fn copy_gpu_frame(
        &mut self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        textures: &fray_gpu::FrameTextures<'_>,
        debug: DebugView,
    ) {
        let (texture, picture) = match debug {
            DebugView::Colour => (textures.display, true),
            DebugView::Depth => (textures.colour_depth, false),
            DebugView::Normals => (textures.normals, false),
        };
        let size = (texture.width(), texture.height());
        let mut slot = if picture {
            self.picture.take()
        } else {
            self.data.take()
        };
        let source = self.source(&mut slot, device, texture.format(), size);
        encoder.copy_texture_to_texture(
            texture.as_image_copy(),
            source.texture.as_image_copy(),
            texture.size(),
        );
        if picture {
            self.picture = slot;
        } else {
            self.data = slot;
        }
        self.showing = Some((picture, debug));
    }

    /// Draws the last frame over the whole of `target` (`surface` pixels), scaled to it.
    pub fn draw(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        surface: (u32, u32),
    ) {
        let shown = self.showing.and_then(|(picture, debug)| {
            let source = if picture { &self.picture } else { &self.data };
            source.as_ref().map(|s| (s, debug))
        });
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("blit"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        if let Some((source, debug)) = shown {
            let params = BlitParams {
                surface: [surface.0 as f32, surface.1 as f32],
                source: [
                    source.texture.width() as f32,
                    source.texture.height() as f32,
                ],
                mode: match debug {
                    DebugView::Colour => 0,
                    DebugView::Depth => 1,
                    DebugView::Normals => 2,
                },
                srgb_surface: u32::from(self.srgb_surface),
                depth_scale: self.depth_scale,
                pad: 0.0,
            };
            queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &source.bind_group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}

use bytemuck::Zeroable;

#[cfg(test)]
mod tests {
    use super::BlitParams;
    use std::mem::offset_of;

    /// The blit shader parses and validates, and its `Blit` uniform is `BlitParams` member for
    /// member — the same names in the same order at the same offsets, the same size — so a field
    /// added, dropped or swapped on one side fails here.
    #[test]
    fn the_blit_shader_validates_and_its_uniform_is_blit_params() {
        let module = naga::front::wgsl::parse_str(include_str!("blit.wgsl")).unwrap();
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap();
        let (members, span) = module
            .types
            .iter()
            .find_map(|(_, t)| match &t.inner {
                naga::TypeInner::Struct { members, span } if t.name.as_deref() == Some("Blit") => {
                    Some((members.clone(), *span))
                }
                _ => None,
            })
            .expect("blit.wgsl declares struct Blit");
        let rust = [
            ("surface", offset_of!(BlitParams, surface)),
            ("source", offset_of!(BlitParams, source)),
            ("mode", offset_of!(BlitParams, mode)),
            ("srgb_surface", offset_of!(BlitParams, srgb_surface)),
            ("depth_scale", offset_of!(BlitParams, depth_scale)),
            ("pad", offset_of!(BlitParams, pad)),
        ];
        let wgsl: Vec<(String, usize)> = members
            .iter()
            .map(|m| (m.name.clone().unwrap_or_default(), m.offset as usize))
            .collect();
        let rust: Vec<(String, usize)> = rust.iter().map(|(n, o)| (n.to_string(), *o)).collect();
        assert_eq!(wgsl, rust);
        assert_eq!(span as usize, std::mem::size_of::<BlitParams>());
    }
}
