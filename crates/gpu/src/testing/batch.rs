//! The one batch pass: a kernel module (`shaders/*_batch.wgsl`, each built on `batch.wgsl`) run
//! over queries given by the caller, reading a kind's or a medium's resources as the frame binds
//! them, and its answers read back — the GPU side of the parity tests, ray by ray.

use crate::bindings::{BATCH, Group};
use crate::passes::PipelineCache;
use crate::shader::{ModuleOptions, Specialisation};
use crate::{GpuContext, GpuError};
use bytemuck::Pod;
use std::sync::Arc;

/// Invocations per workgroup (`batch.wgsl`'s `@workgroup_size`).
const WORKGROUP: u32 = 64;

/// What a batch kernel is: its entry module and what it is composed with, the groups it binds
/// after [`BATCH`] (its kind's or medium's resources), and the rows of its queries and answers
/// (the module's `QUERY_ROWS` and `ANSWER_ROWS`; a unit test checks each kernel's pair).
#[derive(Clone, Copy, Debug)]
pub struct Kernel {
    pub label: &'static str,
    pub module: &'static str,
    pub options: ModuleOptions,
    pub data: &'static [Group],
    pub query_rows: usize,
    pub answer_rows: usize,
}

/// A kernel's pipeline.
#[derive(Debug)]
pub struct BatchPass {
    kernel: Kernel,
    cache: PipelineCache,
    pipeline: Arc<wgpu::ComputePipeline>,
}

impl BatchPass {
    /// Builds `kernel`'s pipeline.
    pub fn new(ctx: &GpuContext, kernel: Kernel) -> Result<Self, GpuError> {
        let cache = PipelineCache::default();
        let groups: Vec<Group> = std::iter::once(BATCH)
            .chain(kernel.data.iter().copied())
            .collect();
        let pipeline = cache.pipeline(
            ctx,
            kernel.module,
            &groups,
            &kernel.options,
            &Specialisation::default(),
        )?;
        Ok(Self {
            kernel,
            cache,
            pipeline,
        })
    }

    /// The bind group of the kernel's data group `group` over `resources` (in its bindings'
    /// order).
    pub fn bind(
        &self,
        ctx: &GpuContext,
        group: &Group,
        resources: &[wgpu::BindingResource<'_>],
    ) -> wgpu::BindGroup {
        group.bind(&ctx.device, &self.cache.layout(ctx, group), resources)
    }

    /// The kernel's answers to `queries` (`query_rows` rows each), with `params` as the batch's
    /// three parameters and `data` bound as its data groups: `answer_rows` rows of words per
    /// query.
    pub fn run(
        &self,
        ctx: &GpuContext,
        queries: &[[f32; 4]],
        params: [u32; 3],
        data: &[&wgpu::BindGroup],
    ) -> Result<Vec<[u32; 4]>, GpuError> {
        let k = &self.kernel;
        debug_assert_eq!(queries.len() % k.query_rows, 0, "{}", k.label);
        let count = queries.len() / k.query_rows;
        if count == 0 {
            return Ok(Vec::new());
        }
        let count = u32::try_from(count).map_err(|_| GpuError::TooLarge {
            what: "batch queries",
            needed: count as u64,
            limit: u32::MAX.into(),
        })?;
        let header = crate::bindings::upload(
            ctx,
            "batch",
            &[[count, params[0], params[1], params[2]]],
            [0; 4],
            wgpu::BufferUsages::UNIFORM,
        )?;
        let bytes = u64::from(count) * k.answer_rows as u64 * 16;
        let (query_buffer, answers) =
            batch_buffers(ctx, ("batch queries", "batch answers"), queries, bytes)?;
        let io = BATCH.bind(
            &ctx.device,
            &self.cache.layout(ctx, &BATCH),
            &[
                header.as_entire_binding(),
                query_buffer.as_entire_binding(),
                answers.as_entire_binding(),
            ],
        );
        let groups: Vec<&wgpu::BindGroup> =
            std::iter::once(&io).chain(data.iter().copied()).collect();
        run_batch(
            ctx,
            &self.pipeline,
            &groups,
            count,
            WORKGROUP,
            &answers,
            bytes,
            k.label,
        )
    }
}

/// A batch pass's buffers: `inputs` uploaded as a storage buffer, and a storage buffer of
/// `result_bytes` for the kernel to write and [`run_batch`] to copy back — each checked against
/// the device's limits first under its name (`names`: inputs, results), which labels it too.
fn batch_buffers<T: Pod>(
    ctx: &crate::context::GpuContext,
    (inputs_name, results_name): (&'static str, &'static str),
    inputs: &[T],
    result_bytes: u64,
) -> Result<(wgpu::Buffer, wgpu::Buffer), GpuError> {
    use wgpu::util::DeviceExt;
    let input_bytes = std::mem::size_of_val(inputs) as u64;
    for (what, size) in [(inputs_name, input_bytes), (results_name, result_bytes)] {
        crate::bindings::check_buffer(ctx, what, size, wgpu::BufferUsages::STORAGE)?;
    }
    let input = ctx
        .device
        .create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some(inputs_name),
            contents: bytemuck::cast_slice(inputs),
            usage: wgpu::BufferUsages::STORAGE,
        });
    let output = ctx.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(results_name),
        size: result_bytes,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    Ok((input, output))
}

/// Runs a batch test pass: `pipeline` over `items` invocations in workgroups of `workgroup`
/// (spread over two dimensions past the device's per-dimension limit) with `groups` bound in
/// order, then copies `output[..bytes]` to a fresh readback buffer and reads it back as `T`s.
#[allow(clippy::too_many_arguments)]
fn run_batch<T: Pod>(
    ctx: &crate::context::GpuContext,
    pipeline: &wgpu::ComputePipeline,
    groups: &[&wgpu::BindGroup],
    items: u32,
    workgroup: u32,
    output: &wgpu::Buffer,
    bytes: u64,
    pass: &'static str,
) -> Result<Vec<T>, GpuError> {
    let device = &ctx.device;
    let readback = crate::readback::readback_buffer(device, pass, bytes);
    let workgroups = items.div_ceil(workgroup);
    let x = workgroups.min(ctx.limits.max_compute_workgroups_per_dimension.max(1));
    let mut encoder =
        device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: None });
    {
        let mut compute = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some(pass),
            timestamp_writes: None,
        });
        compute.set_pipeline(pipeline);
        for (index, group) in groups.iter().enumerate() {
            compute.set_bind_group(index as u32, *group, &[]);
        }
        compute.dispatch_workgroups(x, workgroups.div_ceil(x), 1);
    }
    encoder.copy_buffer_to_buffer(output, 0, &readback, 0, bytes);
    ctx.queue.submit([encoder.finish()]);
    crate::readback::read_back(device, &readback, bytes, pass)
}

/// Rows of floats from rows of words.
pub fn floats(words: [u32; 4]) -> [f32; 4] {
    words.map(f32::from_bits)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every kernel's module validates with naga, declares [`BATCH`] and then its data groups in
    /// that order (how the pass binds them), and says the rows its kernel description says.
    #[test]
    fn every_kernel_declares_its_groups_and_rows() {
        for kernel in crate::testing::KERNELS {
            let groups = crate::shader::module_groups(kernel.module, &kernel.options).unwrap();
            let expected: Vec<Group> = std::iter::once(BATCH)
                .chain(kernel.data.iter().copied())
                .collect();
            assert_eq!(groups, expected, "{}", kernel.module);
            let source = crate::shader::compose(kernel.module, &kernel.options).unwrap();
            let module = naga::front::wgsl::parse_str(&source)
                .unwrap_or_else(|e| panic!("{}: {e}", kernel.module));
            naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            )
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}: {e:?}", kernel.module));
            for (name, rows) in [
                ("QUERY_ROWS", kernel.query_rows),
                ("ANSWER_ROWS", kernel.answer_rows),
            ] {
                assert!(
                    source.contains(&format!("const {name}: u32 = {rows}u;")),
                    "{}: {name} is not {rows}",
                    kernel.module
                );
            }
        }
    }
}
