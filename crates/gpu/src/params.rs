//! The per-frame parameters of the free-form pass (camera, ε, lights, materials) as plain
//! `#[repr(C)]` structs with Rust-generated WGSL mirrors, all positions relative to the eye.

use bytemuck::{Pod, Zeroable};
use fray_core::Projector;
use fray_geometry::gpu_layout::{WgslStruct, vec4};
use fray_scene::{Light, Material, Scene};
use glam::DVec3;

/// Projector kinds (the `PROJECTOR` override).
pub const PROJECTOR_PINHOLE: u32 = 0;
pub const PROJECTOR_PARALLEL: u32 = 1;
pub const PROJECTOR_SPHERE: u32 = 2;
/// Light kinds (`GpuLight::kind.x`).
pub const LIGHT_SUN: u32 = 0;
pub const LIGHT_POINT: u32 = 1;

/// Frame parameters (one uniform buffer).
///
/// `size = (width, height, first row of this dispatch, solid count)`,
/// `mode = (projector kind, light count, rows in this dispatch, work items in this dispatch)`;
/// `forward.w` = pinhole `tan(fov_y/2)` or parallel half height; `right.w` = near distance;
/// `up.w` = ε; `centre` = sphere centre (relative) and radius; `sphere = (fov_x, fov_y,
/// ripple amplitude, ripple frequency)`; `shade.x` = shadow-ray offset.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct FrameParams {
    pub size: [u32; 4],
    pub mode: [u32; 4],
    pub forward: [f32; 4],
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub centre: [f32; 4],
    pub sphere: [f32; 4],
    pub shade: [f32; 4],
    pub background: [f32; 4],
    pub ambient: [f32; 4],
}

/// A light: `vector` = sun direction (unit, toward the sun) or point position (relative);
/// `colour` = irradiance or intensity; `kind.x` = [`LIGHT_SUN`] or [`LIGHT_POINT`].
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuLight {
    pub vector: [f32; 4],
    pub colour: [f32; 4],
    pub kind: [u32; 4],
}

/// A material: ambient, diffuse albedo, specular (w = shininess).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct GpuMaterial {
    pub ambient: [f32; 4],
    pub diffuse: [f32; 4],
    pub specular: [f32; 4],
}

/// WGSL mirrors of this module's structs.
pub const WGSL_STRUCTS: [WgslStruct; 3] = [
    WgslStruct {
        name: "FrameParams",
        fields: &[
            ("size", "vec4<u32>"),
            ("mode", "vec4<u32>"),
            ("forward", "vec4<f32>"),
            ("right", "vec4<f32>"),
            ("up", "vec4<f32>"),
            ("centre", "vec4<f32>"),
            ("sphere", "vec4<f32>"),
            ("shade", "vec4<f32>"),
            ("background", "vec4<f32>"),
            ("ambient", "vec4<f32>"),
        ],
    },
    WgslStruct {
        name: "GpuLight",
        fields: &[
            ("vector", "vec4<f32>"),
            ("colour", "vec4<f32>"),
            ("kind", "vec4<u32>"),
        ],
    },
    WgslStruct {
        name: "GpuMaterial",
        fields: &[
            ("ambient", "vec4<f32>"),
            ("diffuse", "vec4<f32>"),
            ("specular", "vec4<f32>"),
        ],
    },
];

/// The constants the shader shares with Rust.
pub fn wgsl_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("PROJECTOR_PINHOLE", PROJECTOR_PINHOLE),
        ("PROJECTOR_PARALLEL", PROJECTOR_PARALLEL),
        ("PROJECTOR_SPHERE", PROJECTOR_SPHERE),
        ("LIGHT_SUN", LIGHT_SUN),
        ("LIGHT_POINT", LIGHT_POINT),
    ]
}

/// The point every GPU position is taken relative to: the projector's eye.
pub fn reference_point(camera: &Projector) -> DVec3 {
    match camera {
        Projector::Pinhole(p) => p.eye,
        Projector::Parallel(p) => p.eye,
        Projector::Sphere(s) => s.eye,
    }
}

/// The projector kind ([`PROJECTOR_PINHOLE`], …).
pub fn projector_kind(camera: &Projector) -> u32 {
    match camera {
        Projector::Pinhole(_) => PROJECTOR_PINHOLE,
        Projector::Parallel(_) => PROJECTOR_PARALLEL,
        Projector::Sphere(_) => PROJECTOR_SPHERE,
    }
}

/// The frame parameters of `scene` (rows and first row are set per dispatch).
pub fn frame_params(scene: &Scene, epsilon: f64, shadow_offset: f64) -> FrameParams {
    let reference = reference_point(&scene.camera);
    let mut f = FrameParams {
        size: [scene.width, scene.height, 0, scene.objects.len() as u32],
        mode: [
            projector_kind(&scene.camera),
            scene.lights.len() as u32,
            scene.height,
            0,
        ],
        shade: [shadow_offset as f32, 0.0, 0.0, 0.0],
        background: vec4(scene.background.as_dvec3(), 0.0),
        ambient: vec4(scene.ambient.as_dvec3(), 0.0),
        ..FrameParams::default()
    };
    let (basis, k, near) = match &scene.camera {
        Projector::Pinhole(p) => (p.basis, p.tan_half_fov_y, p.near),
        Projector::Parallel(p) => (p.basis, 0.5 * p.height, p.near),
        Projector::Sphere(s) => {
            f.centre = vec4(s.centre - reference, s.radius);
            f.sphere = [
                s.fov_x as f32,
                s.fov_y as f32,
                s.amplitude as f32,
                s.frequency as f32,
            ];
            (s.basis, 0.0, 0.0)
        }
    };
    f.forward = vec4(basis.forward, k);
    f.right = vec4(basis.right, near);
    f.up = vec4(basis.up, epsilon);
    f
}

/// The lights of `scene`, positions relative to the eye (one dummy entry if there are none:
/// storage buffers cannot be empty; the light count says how many are real).
pub fn lights(scene: &Scene) -> Vec<GpuLight> {
    let reference = reference_point(&scene.camera);
    let mut out: Vec<GpuLight> = scene
        .lights
        .iter()
        .map(|l| match *l {
            Light::Sun {
                direction,
                irradiance,
            } => GpuLight {
                vector: vec4(direction, 0.0),
                colour: vec4(irradiance.as_dvec3(), 0.0),
                kind: [LIGHT_SUN, 0, 0, 0],
            },
            Light::Point {
                position,
                intensity,
            } => GpuLight {
                vector: vec4(position - reference, 0.0),
                colour: vec4(intensity.as_dvec3(), 0.0),
                kind: [LIGHT_POINT, 0, 0, 0],
            },
        })
        .collect();
    if out.is_empty() {
        out.push(GpuLight::default());
    }
    out
}

/// The materials of `scene` followed by the default material, which leaves without a valid
/// material index use (as fray-trace does).
pub fn materials(scene: &Scene) -> Vec<GpuMaterial> {
    scene
        .materials
        .iter()
        .chain(std::iter::once(&Material::default()))
        .map(|m| GpuMaterial {
            ambient: vec4(m.ambient.as_dvec3(), 0.0),
            diffuse: vec4(m.diffuse.as_dvec3(), 0.0),
            specular: vec4(m.specular.as_dvec3(), m.shininess),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{offset_of, size_of};

    #[test]
    fn wgsl_tables_match_rust_layouts() {
        let rust = [
            (
                size_of::<FrameParams>(),
                vec![
                    offset_of!(FrameParams, size),
                    offset_of!(FrameParams, mode),
                    offset_of!(FrameParams, forward),
                    offset_of!(FrameParams, right),
                    offset_of!(FrameParams, up),
                    offset_of!(FrameParams, centre),
                    offset_of!(FrameParams, sphere),
                    offset_of!(FrameParams, shade),
                    offset_of!(FrameParams, background),
                    offset_of!(FrameParams, ambient),
                ],
            ),
            (
                size_of::<GpuLight>(),
                vec![
                    offset_of!(GpuLight, vector),
                    offset_of!(GpuLight, colour),
                    offset_of!(GpuLight, kind),
                ],
            ),
            (
                size_of::<GpuMaterial>(),
                vec![
                    offset_of!(GpuMaterial, ambient),
                    offset_of!(GpuMaterial, diffuse),
                    offset_of!(GpuMaterial, specular),
                ],
            ),
        ];
        // Every field of these structs is a 16-byte vec4.
        for (st, (size, offsets)) in WGSL_STRUCTS.iter().zip(rust) {
            assert_eq!(st.layout(|_| 16), (offsets, size), "{}", st.name);
        }
    }
}
