//! Lens objects' vertex rays traced on the GPU (thesis 6.4.1): each tessellation level's
//! vertices go up as one storage buffer, one compute invocation per vertex walks its paths
//! through the lens object's flat BVH (`lens_rays.wgsl`, uploaded once per placed object) and
//! the paths come back for the tessellation's splitting decisions. The walk is
//! pis-compile's [`trace_vertex`] written again in WGSL; [`CpuVertexTracer`] is the model it
//! is held to (tests/lens_rays_vs_cpu.rs) and the fallback where the GPU cannot trace: a
//! model whose paths go deeper than the shader's stack, a tree deeper than its node stack,
//! or a failed readback.

use std::sync::{Arc, Mutex};

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use wgpu::util::DeviceExt;

use pis_compile::hybrid::lens_bvh::{FlatBvh, MAX_STACK};
use pis_compile::hybrid::{
    vertex_normal, view_ray, CpuVertexTracer, HybridVertex, LensModel, LensObject, LensPath,
    Topology, VertexRay, VertexTracer, MAX_TERMS,
};

use crate::frame::readback::map_read_range;
use crate::gpu::Gpu;

/// The deepest `max_depth` the shader's branch stack (16) holds: depth + 2 branches.
pub const MAX_GPU_DEPTH: u32 = 14;
/// Vertices per dispatch (the workgroup count stays within every device's limit).
const BATCH: usize = 64 * 65_535;
/// Bytes of one vertex's result (`VertexOut`).
const OUT_BYTES: usize = 4 * (MAX_TERMS * 12 + 4);

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Params {
    eye: [f32; 3],
    count: u32,
    ior: f32,
    max_depth: u32,
    terms_kept: u32,
    min_weight: f32,
    base: [f32; 3],
    absorbing: u32,
    sigma_a: [f32; 3],
    nodes: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct VertexIn {
    position: [f32; 3],
    front_face: u32,
    normal: [f32; 3],
    pad: u32,
}

/// The compute pipeline of `lens_rays.wgsl`, made once per device.
pub struct LensRayPipeline {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::ComputePipeline,
}

impl LensRayPipeline {
    pub fn new(gpu: &Gpu) -> LensRayPipeline {
        let d = &gpu.device;
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let types = [uniform, storage(true), storage(true), storage(true), storage(false)];
        let entries: Vec<_> = types
            .into_iter()
            .enumerate()
            .map(|(k, ty)| wgpu::BindGroupLayoutEntry {
                binding: k as u32,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty,
                count: None,
            })
            .collect();
        let layout = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("lens rays"),
            entries: &entries,
        });
        let pl = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lens rays"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let module = d.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("lens_rays.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("lens_rays.wgsl").into()),
        });
        let pipeline = d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("lens rays"),
            layout: Some(&pl),
            module: &module,
            entry_point: Some("trace"),
            compilation_options: Default::default(),
            cache: None,
        });
        LensRayPipeline { layout, pipeline }
    }
}

/// A device and the pipeline that traces vertex rays on it.
pub type GpuRays = (Arc<Gpu>, Arc<LensRayPipeline>);

/// What traces `lens`'s vertex rays: the GPU where `gpu` is given (the object's BVH uploaded
/// now), else the workers.
pub fn vertex_tracer(
    gpu: Option<&GpuRays>,
    lens: &LensObject,
) -> Arc<dyn VertexTracer + Send + Sync> {
    match gpu {
        Some((gpu, pipeline)) => {
            Arc::new(GpuVertexTracer::new(gpu.clone(), pipeline.clone(), lens))
        }
        None => Arc::new(CpuVertexTracer),
    }
}

/// A placed lens object on the GPU: its flat BVH, uploaded once, and what traces through it.
pub struct GpuVertexTracer {
    gpu: Arc<Gpu>,
    pipeline: Arc<LensRayPipeline>,
    nodes: wgpu::Buffer,
    triangles: wgpu::Buffer,
    node_count: u32,
    /// Whether the shader's node stack holds the tree.
    fits: bool,
    /// The object's triangle count: the object traced must be the one uploaded.
    triangle_count: usize,
    /// The buffers of a level, kept for the next (made anew for a larger one).
    buffers: Mutex<Option<LevelBuffers>>,
}

/// The buffers one dispatch reads and writes, for up to `capacity` vertices, and their
/// bindings.
struct LevelBuffers {
    capacity: usize,
    params: wgpu::Buffer,
    input: wgpu::Buffer,
    output: wgpu::Buffer,
    read: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

impl LevelBuffers {
    fn new(lens: &GpuVertexTracer, n: usize) -> Self {
        let d = &lens.gpu.device;
        let buffer = |label, size: usize, usage| {
            d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let params = buffer("lens ray params", size_of::<Params>(), U::UNIFORM | U::COPY_DST);
        let input = buffer("vertex rays", n * size_of::<VertexIn>(), U::STORAGE | U::COPY_DST);
        let output = buffer("vertex paths", n * OUT_BYTES, U::STORAGE | U::COPY_SRC);
        let read = buffer("vertex paths readback", n * OUT_BYTES, U::COPY_DST | U::MAP_READ);
        let bind_group = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("lens rays"),
            layout: &lens.pipeline.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: lens.nodes.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: lens.triangles.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: input.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: output.as_entire_binding() },
            ],
        });
        LevelBuffers { capacity: n, params, input, output, read, bind_group }
    }
}

impl GpuVertexTracer {
    /// Uploads `lens`'s BVH.
    pub fn new(gpu: Arc<Gpu>, pipeline: Arc<LensRayPipeline>, lens: &LensObject) -> Self {
        let bvh = FlatBvh::new(lens);
        // A buffer binding is never empty.
        let words = |w: &[u32]| if w.is_empty() { vec![0u32; 8] } else { w.to_vec() };
        let node_words: Vec<u32> = bvh.nodes.iter().flatten().copied().collect();
        let tri_floats: Vec<f32> = bvh.triangles.iter().flatten().copied().collect();
        let tri_words: Vec<u32> = tri_floats.iter().map(|f| f.to_bits()).collect();
        let upload = |label, w: &[u32]| {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::cast_slice(&words(w)),
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let (nodes, triangles) =
            (upload("lens nodes", &node_words), upload("lens triangles", &tri_words));
        GpuVertexTracer {
            node_count: bvh.nodes.len() as u32,
            fits: bvh.depth < MAX_STACK,
            triangle_count: lens.triangles.len(),
            buffers: Mutex::new(None),
            gpu,
            pipeline,
            nodes,
            triangles,
        }
    }

    /// Whether rays of `model` to `max_depth` through `lens` are traced on the GPU (else on
    /// the workers).
    pub fn traces(&self, lens: &LensObject, max_depth: u32) -> bool {
        self.fits && max_depth <= MAX_GPU_DEPTH && lens.triangles.len() == self.triangle_count
    }

    /// One dispatch over `rays`: the raw results, [`OUT_BYTES`] each.
    fn dispatch(
        &self,
        lens: &LensObject,
        eye: Vec3,
        rays: &[VertexRay],
        model: LensModel,
        max_depth: u32,
    ) -> Result<Vec<u8>, crate::PlayError> {
        let d = &self.gpu.device;
        let m = lens.material;
        let params = Params {
            eye: eye.to_array(),
            count: rays.len() as u32,
            ior: m.ior,
            max_depth,
            terms_kept: model.terms() as u32,
            min_weight: model.min_weight(),
            base: m.base.to_array(),
            absorbing: (m.sigma_a != Vec3::ZERO) as u32,
            sigma_a: m.sigma_a.to_array(),
            nodes: self.node_count,
        };
        let input: Vec<VertexIn> = rays
            .iter()
            .map(|r| VertexIn {
                position: r.position.to_array(),
                front_face: r.front_face as u32,
                normal: r.normal.to_array(),
                pad: 0,
            })
            .collect();
        let mut held = self.buffers.lock().unwrap_or_else(|e| e.into_inner());
        if held.as_ref().is_none_or(|b| b.capacity < rays.len()) {
            *held = Some(LevelBuffers::new(self, rays.len()));
        }
        let b = held.as_ref().expect("made above");
        let q = &self.gpu.queue;
        q.write_buffer(&b.params, 0, bytemuck::bytes_of(&params));
        q.write_buffer(&b.input, 0, bytemuck::cast_slice(&input));
        let size = (rays.len() * OUT_BYTES) as u64;
        let mut encoder = d.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("lens rays"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline.pipeline);
            pass.set_bind_group(0, &b.bind_group, &[]);
            pass.dispatch_workgroups(rays.len().div_ceil(64) as u32, 1, 1);
        }
        encoder.copy_buffer_to_buffer(&b.output, 0, &b.read, 0, size);
        let submitted = q.submit([encoder.finish()]);
        map_read_range(&self.gpu, &b.read, size, Some(submitted))
    }
}

/// One vertex's result: `bytes` ([`OUT_BYTES`]) as the shader wrote them, with what the CPU
/// keeps of the input itself (its position, normal and side).
fn vertex(bytes: &[u8], ray: &VertexRay, eye: Vec3, model: LensModel) -> (HybridVertex, u64) {
    let word = |k: usize| u32::from_le_bytes(bytes[k * 4..k * 4 + 4].try_into().expect("4 bytes"));
    let float = |k: usize| f32::from_bits(word(k));
    let vec = |k: usize| Vec3::new(float(k), float(k + 1), float(k + 2));
    let mut paths: [Option<LensPath>; MAX_TERMS] = [None; MAX_TERMS];
    for (t, path) in paths.iter_mut().enumerate().take(model.terms()) {
        let k = t * 12;
        if word(k + 3) != 0 {
            *path = Some(LensPath {
                exit_origin: vec(k),
                exit_direction: vec(k + 4),
                modulation: vec(k + 8),
                topology: Topology { interfaces: word(k + 7) as u8, reflected: word(k + 11) },
                exit: (),
            });
        }
    }
    let base = MAX_TERMS * 12;
    // trace_vertex's normal, by the same functions.
    let v = HybridVertex {
        position: ray.position,
        normal: vertex_normal(ray.normal, view_ray(eye, ray.position).0),
        visible: word(base) != 0,
        front_face: ray.front_face,
        paths,
    };
    (v, word(base + 1) as u64)
}

impl VertexTracer for GpuVertexTracer {
    fn trace(
        &self,
        lens: &LensObject,
        eye: Vec3,
        rays: &[VertexRay],
        model: LensModel,
        max_depth: u32,
    ) -> Vec<(HybridVertex, u64)> {
        if rays.is_empty() || !self.traces(lens, max_depth) {
            return CpuVertexTracer.trace(lens, eye, rays, model, max_depth);
        }
        let mut out = Vec::with_capacity(rays.len());
        for chunk in rays.chunks(BATCH) {
            match self.dispatch(lens, eye, chunk, model, max_depth) {
                Ok(bytes) => out.extend(
                    bytes.chunks_exact(OUT_BYTES).zip(chunk).map(|(b, r)| vertex(b, r, eye, model)),
                ),
                // A readback that failed: this level traced on the workers.
                Err(_) => out.extend(CpuVertexTracer.trace(lens, eye, chunk, model, max_depth)),
            }
        }
        out
    }
}
