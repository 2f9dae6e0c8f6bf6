// no_texture.wgsl — the textures' hook in shade.wgsl for a scene without image textures or
// colour ramps: every material as it is (C = 1 exactly, so the radiance is bit for bit what it
// was before textures reached the GPU); no texture code, uniform or data texture is compiled.

fn textured(m: GpuMaterial, material: u32, path: GpuPath, p: vec3<f32>, normal: vec3<f32>, distance: f32) -> GpuMaterial {
    return m;
}
