//! The GPU structs the passes share — frame parameters, rays in flight (paths), lights,
//! materials — each declared once with [`fray_core::gpu_struct!`] (the WGSL twin is generated),
//! and how a scene and a view fill them. Positions are camera-relative in the passes: the
//! resident scene is anchor-relative and the rebase pass moves it to the camera every frame
//! (`passes::rebase`).

use fray_core::{PixelSamples, Projector, ToneMap};
use fray_geometry::gpu_layout::vec4;
use fray_scene::{Light, Material, Scene};
use glam::DVec3;

/// Texels (of 16 bytes) per row of the data textures (the meshes' arrays, the textures'
/// sections): a power of two, at most the 8192 texels per side every WebGPU device allows
/// (`MESH_TEXTURE_WIDTH` in the prelude).
pub const DATA_TEXTURE_WIDTH: u32 = 4096;
/// The most transmissive surfaces a shadow ray passes through before it counts as blocked
/// (fray-trace's `MAX_SHADOW_CROSSINGS`; a test holds the two equal).
pub const MAX_SHADOW_CROSSINGS: u32 = 32;

/// Projector kinds (the `PROJECTOR` override).
pub const PROJECTOR_PINHOLE: u32 = 0;
pub const PROJECTOR_PARALLEL: u32 = 1;
pub const PROJECTOR_SPHERE: u32 = 2;
/// Light kinds ([`GpuLight::kind`]).
pub const LIGHT_SUN: u32 = 0;
pub const LIGHT_POINT: u32 = 1;
/// Tone maps of the display texture ([`FrameParams::tone_map`]).
pub const TONE_MAP_CLAMP: u32 = 0;
pub const TONE_MAP_REINHARD: u32 = 1;

fray_core::gpu_struct! {
    /// One array's rebase: the offset, the array's size in 16-byte slots, its element stride in
    /// slots and which slots of an element hold a position, a box's lower corner or its upper
    /// corner (bit masks).
    pub struct RebaseParams {
        pub hi: [f32; 4],
        pub lo: [f32; 4],
        pub words: u32,
        pub stride: u32,
        pub points: u32,
        pub box_mins: u32,
        pub box_maxs: u32,
        pub pad: u32,
        pub pad2: [u32; 2],
    }
}

fray_core::gpu_struct! {
    /// One frame's (and one band's) parameters: the view, the image, counts and settings. A
    /// uniform; the camera-dependent and band-dependent fields are written per band.
    pub struct FrameParams {
        /// The view basis; `forward.w`: pinhole `tan(fov_y/2)` or parallel half height;
        /// `right.w`: the near distance (the picture plane); `up.w` unused.
        pub forward: [f32; 4],
        pub right: [f32; 4],
        pub up: [f32; 4],
        /// Sphere picture surface: centre (camera-relative) and radius.
        pub centre: [f32; 4],
        /// Sphere picture surface: fov_x, fov_y, ripple amplitude, ripple frequency.
        pub sphere: [f32; 4],
        pub background: [f32; 4],
        pub ambient: [f32; 4],
        /// The camera's offset from the scene's anchor as a hi/lo pair of f32 vectors
        /// (`hi + lo` holds the f64 offset to about 2⁻⁴⁸): the rebase pass moves the resident
        /// scene by it.
        pub camera_hi: [f32; 4],
        pub camera_lo: [f32; 4],
        /// The camera's pixel footprint (size, growth per unit distance) for terrain LOD.
        pub footprint: [f32; 4],
        pub width: u32,
        pub height: u32,
        /// The band of rows this dispatch covers.
        pub band_y0: u32,
        pub band_rows: u32,
        /// Work items in this band's dispatch, and the first of them in the frame's list.
        pub items: u32,
        pub first_item: u32,
        pub solids: u32,
        pub lights: u32,
        pub terrains: u32,
        /// Anti-aliasing samples per pixel, their rows of strata, and the camera rays per
        /// pixel (1, or the centre and the samples).
        pub samples: u32,
        pub sample_rows: u32,
        pub rays_per_pixel: u32,
        /// Where the candidates' (first word, length) program pairs start in `indices`.
        pub programs_base: u32,
        pub epsilon: f32,
        pub shadow_offset: f32,
        pub exposure: f32,
        pub tone_map: u32,
        /// Whitted: the deepest secondary ray (`settings.max_depth`), the weight below which a
        /// secondary ray is not traced (`settings.min_contribution`), and the slots of the
        /// band's queue of secondary rays (after the band's camera rays in `paths`).
        pub max_depth: u32,
        pub min_contribution: f32,
        pub queue_capacity: u32,
        /// Whitted: the secondary rays one camera ray may trace (`settings.max_secondary_rays`,
        /// shared down its tree: `fray_trace::ray_budget`'s rule).
        pub max_secondary_rays: u32,
        pub pad: u32,
        pub pad2: [u32; 2],
    }
}

fray_core::gpu_struct! {
    /// A ray in flight and what became of it: written by ray generation, narrowed by the
    /// intersection passes, shaded, resolved. Camera-relative.
    pub struct GpuPath {
        /// Origin (xyz) and `t_near` (w; `< 0`: no ray, a degenerate projector pair).
        pub origin: [f32; 4],
        /// Unit direction (xyz) and the sample's box-filter weight (w).
        pub dir: [f32; 4],
        /// The nearest hit: `t` (x, `< 0` for none) and, for kinds that know it at hit time
        /// (terrains), the shading normal (yzw).
        pub hit: [f32; 4],
        /// Radiance brought back along the ray (rgb), written by the shade pass.
        pub radiance: [f32; 4],
        /// The primitive hit (`fray_scene::PrimitiveKind` code, index within the kind).
        pub kind: u32,
        pub index: u32,
        /// The kind's part of the hit (a terrain's levels above the finest).
        pub part: u32,
        pub pad: u32,
    }
}

fray_core::gpu_struct! {
    /// A light: a sun's unit direction toward it, or a point light's position (anchor-relative
    /// here, camera-relative after the rebase), and its irradiance or intensity.
    pub struct GpuLight {
        pub direction: [f32; 4],
        pub position: [f32; 4],
        pub colour: [f32; 4],
        /// [`LIGHT_SUN`] or [`LIGHT_POINT`].
        pub kind: u32,
        pub pad: u32,
        pub pad2: [u32; 2],
    }
}

fray_core::gpu_struct! {
    /// A material (fray-trace's Phong-style model with Whitted's terms).
    pub struct GpuMaterial {
        pub ambient: [f32; 4],
        pub diffuse: [f32; 4],
        pub specular: [f32; 4],
        /// Mirror reflectance `kr` (rgb) and the index of refraction (w).
        pub reflect: [f32; 4],
        /// Transmittance `kt` (rgb) and 1 where Fresnel weights `kr`/`kt` (w), else 0.
        pub transmit: [f32; 4],
        pub shininess: f32,
        pub pad: f32,
        pub pad2: [f32; 2],
    }
}

fray_core::gpu_struct! {
    /// Whitted's record of a ray in `paths` (same slot): what it carries and what it spawned.
    /// Only scenes whose materials reflect or transmit allocate these.
    pub struct GpuSecondary {
        /// The ray's weight relative to its parent (`kr` or `kt` after Fresnel; rgb; 1 for a
        /// camera ray) and the path's length from the camera to the ray's origin (w).
        pub weight: [f32; 4],
        /// The product of the weights from the camera (rgb): the contribution cut-off's.
        pub throughput: [f32; 4],
        /// Its children's slots `[first_child, first_child + children)` in `paths`.
        pub first_child: u32,
        pub children: u32,
        /// Secondary rays from the camera to this one (0: a camera ray).
        pub depth: u32,
        /// The secondary rays this ray's tree may still trace below it (a camera ray: the
        /// budget; its children share it, fray-trace's `ray_budget`).
        pub allowance: u32,
    }
}

/// The constants the shaders share with Rust.
pub fn wgsl_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("PROJECTOR_PINHOLE", PROJECTOR_PINHOLE),
        ("PROJECTOR_PARALLEL", PROJECTOR_PARALLEL),
        ("PROJECTOR_SPHERE", PROJECTOR_SPHERE),
        ("LIGHT_SUN", LIGHT_SUN),
        ("LIGHT_POINT", LIGHT_POINT),
        ("TONE_MAP_CLAMP", TONE_MAP_CLAMP),
        ("TONE_MAP_REINHARD", TONE_MAP_REINHARD),
    ]
}

/// The point a projector's rays start from (every camera-relative position is relative to it).
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

/// An f64 vector as a hi/lo pair of f32 vectors: `hi` its rounding, `lo` the rounding of the
/// rest (`hi + lo` is the vector to about 2⁻⁴⁸ relative).
pub fn hi_lo(v: DVec3) -> ([f32; 4], [f32; 4]) {
    let hi = v.as_vec3();
    let lo = (v - hi.as_dvec3()).as_vec3();
    ([hi.x, hi.y, hi.z, 0.0], [lo.x, lo.y, lo.z, 0.0])
}

/// What a frame shows: the camera, the image size, the samples and how the display texture is
/// tone mapped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub camera: Projector,
    pub width: u32,
    pub height: u32,
    pub samples: PixelSamples,
    pub tone_map: ToneMap,
    pub exposure: f32,
}

impl View {
    /// The scene's own view: its camera and image size, `samples`, clamped tone map at
    /// exposure 1.
    pub fn of_scene(scene: &Scene, samples: PixelSamples) -> Self {
        Self {
            camera: scene.camera,
            width: scene.width,
            height: scene.height,
            samples,
            tone_map: ToneMap::Clamp,
            exposure: 1.0,
        }
    }

    /// Camera rays per pixel: the centre alone, or the centre (depth and normals) and the
    /// samples (colour).
    pub fn rays_per_pixel(&self) -> u32 {
        if self.samples.count() == 1 {
            1
        } else {
            1 + self.samples.count()
        }
    }
}

/// The frame parameters of `scene` seen in `view` from `anchor` (band fields are set per band).
pub fn frame_params(
    scene: &Scene,
    view: &View,
    anchor: DVec3,
    epsilon: f64,
    shadow_offset: f64,
) -> FrameParams {
    let reference = reference_point(&view.camera);
    let (camera_hi, camera_lo) = hi_lo(reference - anchor);
    let footprint = view.camera.pixel_footprint(view.width, view.height);
    let mut f = FrameParams {
        background: vec4(scene.background.as_dvec3(), 0.0),
        ambient: vec4(scene.ambient.as_dvec3(), 0.0),
        camera_hi,
        camera_lo,
        footprint: [footprint.size as f32, footprint.angle as f32, 0.0, 0.0],
        width: view.width,
        height: view.height,
        band_y0: 0,
        band_rows: view.height,
        solids: scene.objects.len() as u32,
        lights: scene.lights.len() as u32,
        terrains: scene.terrains.len() as u32,
        samples: view.samples.count(),
        sample_rows: view.samples.rows(),
        rays_per_pixel: view.rays_per_pixel(),
        epsilon: epsilon as f32,
        shadow_offset: shadow_offset as f32,
        exposure: view.exposure,
        tone_map: match view.tone_map {
            ToneMap::Clamp => TONE_MAP_CLAMP,
            ToneMap::Reinhard => TONE_MAP_REINHARD,
        },
        ..FrameParams::default()
    };
    let (basis, k, near) = match &view.camera {
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
    f.up = vec4(basis.up, 0.0);
    f
}

/// The lights of `scene`, positions relative to `anchor` (at least one entry: a uniform array
/// cannot be empty; the light count says how many are real).
pub fn lights(scene: &Scene, anchor: DVec3) -> Vec<GpuLight> {
    let mut out: Vec<GpuLight> = scene
        .lights
        .iter()
        .map(|l| match *l {
            Light::Sun {
                direction,
                irradiance,
            } => GpuLight {
                direction: vec4(direction, 0.0),
                colour: vec4(irradiance.as_dvec3(), 0.0),
                kind: LIGHT_SUN,
                ..GpuLight::default()
            },
            Light::Point {
                position,
                intensity,
            } => GpuLight {
                position: vec4(position - anchor, 0.0),
                colour: vec4(intensity.as_dvec3(), 0.0),
                kind: LIGHT_POINT,
                ..GpuLight::default()
            },
        })
        .collect();
    if out.is_empty() {
        out.push(GpuLight::default());
    }
    out
}

/// The materials of `scene` followed by the default material, which parts without a valid
/// material index use (as fray-trace does).
pub fn materials(scene: &Scene) -> Vec<GpuMaterial> {
    scene
        .materials
        .iter()
        .chain(std::iter::once(&Material::default()))
        .map(|m| GpuMaterial {
            ambient: vec4(m.ambient.as_dvec3(), 0.0),
            diffuse: vec4(m.diffuse.as_dvec3(), 0.0),
            specular: vec4(m.specular.as_dvec3(), 0.0),
            reflect: vec4(m.reflect.as_dvec3(), m.ior),
            transmit: vec4(m.transmit.as_dvec3(), if m.fresnel { 1.0 } else { 0.0 }),
            shininess: m.shininess as f32,
            ..GpuMaterial::default()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::gpu_struct::GpuStruct;

    #[test]
    fn wgsl_layouts_match_rust_layouts() {
        FrameParams::check_layout().unwrap();
        GpuPath::check_layout().unwrap();
        GpuLight::check_layout().unwrap();
        GpuMaterial::check_layout().unwrap();
        GpuSecondary::check_layout().unwrap();
        // Uniform arrays need a 16-byte stride.
        for size in [
            std::mem::size_of::<GpuLight>(),
            std::mem::size_of::<GpuMaterial>(),
        ] {
            assert_eq!(size % 16, 0);
        }
    }

    #[test]
    fn hi_lo_holds_an_f64_offset_to_far_beyond_f32() {
        let v = DVec3::new(1.0e6 + 0.123_456_789, -3.0e7 - 1.0e-3, 7.0);
        let (hi, lo) = hi_lo(v);
        for k in 0..3 {
            let sum = f64::from(hi[k]) + f64::from(lo[k]);
            assert!((sum - v[k]).abs() <= 1e-9 * v[k].abs().max(1.0), "{k}");
        }
        assert_eq!(hi_lo(DVec3::ZERO), ([0.0; 4], [0.0; 4]));
    }
}
