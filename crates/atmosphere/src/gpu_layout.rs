//! The atmosphere's GPU parameter blocks: [`GpuFog`] (the fog layer) and [`GpuSky`] (the
//! physically based sky), `#[repr(C)]` Pod structs declared with their WGSL twins from one field
//! list each (`fray_core::gpu_struct!`), and the constants that name their options in WGSL.
//! `shaders/fog.wgsl` is the f32 twin of [`FogLayer`]'s terms over the first, `shaders/sky.wgsl`
//! that of [`Sky`]'s tables, disc and march over the second.
//!
//! Both are filled in f64 each frame before rounding to f32, relative to a reference point (the
//! camera): the fog's heights, so that a layer thousands of metres below a camera far from the
//! world origin keeps f32 precision in the distances it is cut at; the sky's eye altitude, so
//! that the shader never forms an altitude as the difference of two radii near 6.4·10⁶ m.

use crate::sky::{MAX_OBSERVER_ALTITUDE, Sky};
use crate::{FogLayer, FogModel, Phase};
pub use fray_core::gpu_struct::GpuStruct;
use glam::DVec3;

/// Phase functions ([`GpuFog::phase`]), the order of [`Phase`]'s variants.
pub const PHASE_ISOTROPIC: u32 = 0;
pub const PHASE_HENYEY_GREENSTEIN: u32 = 1;
pub const PHASE_PRINTED: u32 = 2;
/// Models ([`GpuFog::model`]), the order of [`FogModel`]'s variants.
pub const FOG_EXACT: u32 = 0;
pub const FOG_METHOD: u32 = 1;
/// "No light": [`GpuFog::sky_sun`] or [`GpuSky::sun_light`] when the sky has no sun among the
/// scene's lights.
pub const NO_LIGHT: u32 = u32::MAX;
/// [`GpuSky::flags`]: draw the sun's disc on the background.
pub const SKY_SUN_DISC: u32 = 1;
/// [`GpuSky::flags`]: the air between the camera and surfaces (aerial perspective).
pub const SKY_AERIAL_PERSPECTIVE: u32 = 2;

fray_core::gpu_struct! {
    /// A fog layer as the GPU reads it: [`FogLayer`]'s fields, its heights relative to the
    /// reference point's height, and the model its in-scatter is evaluated with.
    pub struct GpuFog {
        /// Single-scattering albedo per channel (rgb); `w` unused.
        pub albedo: [f32; 4],
        /// The layer's bottom and top, minus the reference point's height (f64, then rounded).
        pub base: f32,
        pub top: f32,
        /// `top − base`, from the f64 heights (the difference of the two rounded ones would lose
        /// the thickness of a thin layer far below the camera).
        pub thickness: f32,
        /// Extinction `B` in 1/m (at `base` when it falls off).
        pub extinction: f32,
        /// Scale height in metres of the exponential falloff; 0: homogeneous.
        pub scale_height: f32,
        /// The phase function's asymmetry `g` (0 for isotropic).
        pub g: f32,
        /// [`PHASE_ISOTROPIC`], [`PHASE_HENYEY_GREENSTEIN`] or [`PHASE_PRINTED`].
        pub phase: u32,
        /// [`FOG_EXACT`] or [`FOG_METHOD`].
        pub model: u32,
        /// The sky's sun's irradiance reaching the layer's top, as a fraction of the light's
        /// (rgb; Klassen's `Ic` through the air above the fog); `w` unused.
        pub sky_sun_transmittance: [f32; 4],
        /// Which of the scene's lights [`GpuFog::sky_sun_transmittance`] dims ([`NO_LIGHT`]:
        /// none, every sun reaches the top whole).
        pub sky_sun: u32,
        pub pad: u32,
        pub pad2: [u32; 2],
    }
}

impl GpuFog {
    /// `layer` evaluated by `model`, its heights relative to `reference_y` (the camera's height).
    pub fn new(layer: &FogLayer, model: FogModel, reference_y: f64) -> Self {
        let (phase, g) = match layer.phase {
            Phase::Isotropic => (PHASE_ISOTROPIC, 0.0),
            Phase::HenyeyGreenstein { g } => (PHASE_HENYEY_GREENSTEIN, g),
            Phase::Printed { g } => (PHASE_PRINTED, g),
        };
        let a = layer.albedo;
        Self {
            albedo: [a.x as f32, a.y as f32, a.z as f32, 0.0],
            base: (layer.base - reference_y) as f32,
            top: (layer.top - reference_y) as f32,
            thickness: layer.thickness() as f32,
            extinction: layer.extinction as f32,
            scale_height: layer.falloff.unwrap_or(0.0) as f32,
            g: g as f32,
            phase,
            model: match model {
                FogModel::Exact => FOG_EXACT,
                FogModel::Method => FOG_METHOD,
            },
            sky_sun_transmittance: [1.0; 4],
            sky_sun: NO_LIGHT,
            ..Self::default()
        }
    }

    /// The layer lit by light `index` (the sky's sun) through the air above it: its irradiance
    /// at the layer's top is the light's times `transmittance` (`Sky::transmittance_to_sun` at
    /// the top above the eye, in f64).
    pub fn with_sky_sun(self, index: usize, transmittance: DVec3) -> Self {
        let t = transmittance.as_vec3();
        Self {
            sky_sun_transmittance: [t.x, t.y, t.z, 1.0],
            sky_sun: u32::try_from(index).unwrap_or(NO_LIGHT),
            ..self
        }
    }
}

fray_core::gpu_struct! {
    /// The physically based sky as the GPU reads it, for one frame: the model's coefficients,
    /// the sun, the two tables' sizes and the eye — every derived value taken in f64 before
    /// rounding (the planet's radii near 6.4·10⁶ m leave f32 half a metre, so the shader works
    /// with altitudes, and with the eye's altitude from here).
    pub struct GpuSky {
        /// Rayleigh scattering at the ground (rgb, 1/m); `w`: its scale height `H_R` (m).
        pub rayleigh: [f32; 4],
        /// Ozone absorption at the tent's peak (rgb, 1/m); `w`: the peak's altitude (m).
        pub ozone: [f32; 4],
        /// Unit vector toward the sun (xyz); `w`: `|d − s|²` at the disc's edge, `4 sin²(α/2)`
        /// (`d·s ≥ cos α` for unit vectors, without the cancellation of `1 − cos α` in f32).
        pub sun_direction: [f32; 4],
        /// The sun's irradiance at the top of the atmosphere `E` (rgb, W/m²).
        pub sun_irradiance: [f32; 4],
        /// The disc's radiance `E / Ω` (rgb, W/(m² sr)).
        pub sun_radiance: [f32; 4],
        /// The sky-view table's azimuth frame: the sun's horizontal direction `s` (`+X` for a
        /// sun at the zenith) and `Y × s`.
        pub sun_horizontal: [f32; 4],
        pub sun_side: [f32; 4],
        /// The planet's radius `R_g` and the atmosphere's top `R_t` (m).
        pub ground_radius: f32,
        pub top_radius: f32,
        /// `R_t − R_g`, the top's altitude (m).
        pub top_altitude: f32,
        /// `√(R_t² − R_g²)`, the transmittance table's `H` (m).
        pub horizon_distance: f32,
        /// Mie scattering and extinction (`σ_M + σ_Ma`) at the ground (1/m), its scale height
        /// (m) and the Cornette–Shanks asymmetry `g`.
        pub mie_scattering: f32,
        pub mie_extinction: f32,
        pub mie_scale_height: f32,
        pub mie_g: f32,
        /// Half the ozone tent's full width (m).
        pub ozone_half_width: f32,
        /// The eye's height above the planet's surface, `eye.y − ground_elevation`, unclamped:
        /// a ray from camera-relative `o` starts at altitude `eye_height + o.y` (clamped).
        pub eye_height: f32,
        /// The eye's altitude clamped to `[0, MAX_OBSERVER_ALTITUDE]` (the sky-view table's) and
        /// its radius `R_g + altitude`.
        pub eye_altitude: f32,
        pub eye_radius: f32,
        /// The sky-view table's horizon: its zenith angle `θ_h = π − β`, its angle from the
        /// nadir `β = asin(R_g / r)` and its dip below the horizontal `π/2 − β`.
        pub horizon_zenith: f32,
        pub horizon_nadir: f32,
        pub horizon_dip: f32,
        /// `MAX_OBSERVER_ALTITUDE` (m).
        pub max_altitude: f32,
        /// The transmittance table's and the sky-view table's sizes (texels).
        pub transmittance_width: u32,
        pub transmittance_height: u32,
        pub view_width: u32,
        pub view_height: u32,
        /// Steps of the aerial-perspective march (1…4096).
        pub steps: u32,
        /// Which of the scene's lights is the sky's sun, dimmed by the air ([`NO_LIGHT`]: none).
        pub sun_light: u32,
        /// [`SKY_SUN_DISC`] | [`SKY_AERIAL_PERSPECTIVE`].
        pub flags: u32,
        pub pad2: u32,
    }
}

/// What a scene asks of its sky besides the model and the sun ([`GpuSky::new`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GpuSkyOptions {
    /// Draw the sun's disc on the background.
    pub sun_disc: bool,
    /// The air between the camera and surfaces.
    pub aerial_perspective: bool,
    /// Steps of the aerial-perspective march (clamped to `1..=4096`, as the CPU does).
    pub steps: u32,
    /// Which of the scene's lights is the sky's sun.
    pub sun_light: Option<usize>,
}

impl GpuSky {
    /// `sky` seen by an eye at height `eye_y` (scene `y`; only the height matters, see
    /// `fray_atmosphere::sky`'s frame), with the scene's `options`.
    pub fn new(sky: &Sky, eye_y: f64, options: GpuSkyOptions) -> Self {
        let m = sky.model();
        let sun = sky.sun();
        let r = m.observer_radius(eye_y);
        // As `SkyViewTable::build` does, in f64: the horizon's dip and the azimuth frame.
        let beta = (m.ground_radius / r).min(1.0).asin();
        let l = sun.direction;
        let sun_h = DVec3::new(l.x, 0.0, l.z)
            .try_normalize()
            .unwrap_or(DVec3::X);
        let side = DVec3::Y.cross(sun_h);
        let edge = (0.5 * sun.angular_radius).sin();
        let v4 = |v: DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        let tables = sky.tables();
        let mut flags = 0;
        if options.sun_disc {
            flags |= SKY_SUN_DISC;
        }
        if options.aerial_perspective {
            flags |= SKY_AERIAL_PERSPECTIVE;
        }
        Self {
            rayleigh: v4(m.rayleigh_scattering, m.rayleigh_scale_height),
            ozone: v4(m.ozone_absorption, m.ozone_centre),
            sun_direction: v4(l, 4.0 * edge * edge),
            sun_irradiance: v4(sun.irradiance, 0.0),
            sun_radiance: v4(sun.disc_radiance(), 0.0),
            sun_horizontal: v4(sun_h, 0.0),
            sun_side: v4(side, 0.0),
            ground_radius: m.ground_radius as f32,
            top_radius: m.top_radius as f32,
            top_altitude: (m.top_radius - m.ground_radius) as f32,
            horizon_distance: ((m.top_radius - m.ground_radius) * (m.top_radius + m.ground_radius))
                .sqrt() as f32,
            mie_scattering: m.mie_scattering as f32,
            mie_extinction: m.mie_extinction() as f32,
            mie_scale_height: m.mie_scale_height as f32,
            mie_g: m.mie_g as f32,
            ozone_half_width: (0.5 * m.ozone_width) as f32,
            eye_height: (eye_y - m.ground_elevation) as f32,
            eye_altitude: (r - m.ground_radius) as f32,
            eye_radius: r as f32,
            horizon_zenith: (std::f64::consts::PI - beta) as f32,
            horizon_nadir: beta as f32,
            horizon_dip: (std::f64::consts::FRAC_PI_2 - beta) as f32,
            max_altitude: MAX_OBSERVER_ALTITUDE as f32,
            transmittance_width: tables.transmittance_width,
            transmittance_height: tables.transmittance_height,
            view_width: tables.sky_view_width,
            view_height: tables.sky_view_height,
            steps: options.steps.clamp(1, crate::sky::MAX_STEPS),
            sun_light: options
                .sun_light
                .and_then(|i| u32::try_from(i).ok())
                .unwrap_or(NO_LIGHT),
            flags,
            pad2: 0,
        }
    }
}

/// The WGSL declarations of [`GpuFog`] and [`GpuSky`] (generated from their one definitions).
pub fn wgsl_declaration() -> String {
    format!(
        "// Generated by fray_atmosphere::gpu_layout — do not edit.\n{}{}",
        GpuFog::declaration(),
        GpuSky::declaration()
    )
}

/// The constants the fog's WGSL shares with Rust.
pub fn wgsl_constants() -> Vec<(&'static str, u32)> {
    vec![
        ("PHASE_ISOTROPIC", PHASE_ISOTROPIC),
        ("PHASE_HENYEY_GREENSTEIN", PHASE_HENYEY_GREENSTEIN),
        ("PHASE_PRINTED", PHASE_PRINTED),
        ("FOG_EXACT", FOG_EXACT),
        ("FOG_METHOD", FOG_METHOD),
        ("NO_LIGHT", NO_LIGHT),
        ("SKY_SUN_DISC", SKY_SUN_DISC),
        ("SKY_AERIAL_PERSPECTIVE", SKY_AERIAL_PERSPECTIVE),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn the_wgsl_layout_is_the_rust_layout() {
        GpuFog::check_layout().unwrap();
        GpuSky::check_layout().unwrap();
        // Uniforms: 16-byte multiples.
        assert_eq!(std::mem::size_of::<GpuFog>() % 16, 0);
        assert_eq!(std::mem::size_of::<GpuSky>() % 16, 0);
        assert!(wgsl_declaration().contains("struct GpuFog {\n    albedo: vec4<f32>,"));
        assert!(wgsl_declaration().contains("struct GpuSky {\n    rayleigh: vec4<f32>,"));
    }

    #[test]
    fn the_sky_block_is_taken_in_f64() {
        use crate::sky::{SkyModel, SkySun, SkyTables};
        let model = SkyModel {
            ground_elevation: -1300.0,
            ..SkyModel::earth()
        };
        let sun = SkySun::from_angles(2f64.to_radians(), 0.3, DVec3::splat(20.0));
        let tables = SkyTables {
            transmittance_width: 16,
            transmittance_height: 8,
            sky_view_width: 8,
            sky_view_height: 6,
            sky_view_steps: 4,
        };
        let sky = Sky::new(model, sun, tables, &fray_core::MemoryBudget::unlimited()).unwrap();
        let options = GpuSkyOptions {
            sun_disc: true,
            aerial_perspective: false,
            steps: 0,
            sun_light: Some(2),
        };
        let g = GpuSky::new(&sky, 2.5, options);
        // The altitude from the f64 heights, not R_g + h − R_g in f32.
        assert_eq!((g.eye_height, g.eye_altitude), (1302.5, 1302.5));
        assert_eq!(g.eye_radius, (6_360_000.0f64 + 1302.5) as f32);
        assert_eq!((g.steps, g.sun_light, g.flags), (1, 2, SKY_SUN_DISC));
        assert_eq!((g.view_width, g.transmittance_height), (8, 8));
        let beta = (6_360_000.0f64 / (6_360_000.0 + 1302.5)).asin();
        assert_eq!(g.horizon_nadir, beta as f32);
        assert_eq!(g.horizon_dip, (std::f64::consts::FRAC_PI_2 - beta) as f32);
        // The disc's edge: |d − s|² = 2 (1 − cos α).
        let alpha = SkySun::ANGULAR_RADIUS;
        assert!((f64::from(g.sun_direction[3]) - 2.0 * (1.0 - alpha.cos())).abs() < 1e-12);
        // Below the ground: on it; no sun light.
        let under = GpuSky::new(
            &sky,
            -5000.0,
            GpuSkyOptions {
                sun_light: None,
                ..options
            },
        );
        assert_eq!((under.eye_height, under.eye_altitude), (-3700.0, 0.0));
        assert_eq!(under.sun_light, NO_LIGHT);
        let fog = GpuFog::new(&FogLayer::default(), FogModel::Exact, 0.0);
        assert_eq!(
            (fog.sky_sun, fog.sky_sun_transmittance),
            (NO_LIGHT, [1.0; 4])
        );
        let lit = fog.with_sky_sun(1, DVec3::new(0.5, 0.25, 0.125));
        assert_eq!(
            (lit.sky_sun, lit.sky_sun_transmittance),
            (1, [0.5, 0.25, 0.125, 1.0])
        );
    }

    #[test]
    fn heights_are_relative_to_the_reference_in_f64() {
        let layer = FogLayer {
            base: 1.0e7,
            top: 1.0e7 + 0.25,
            falloff: Some(30.0),
            albedo: DVec3::new(0.9, 0.8, 0.7),
            phase: Phase::Printed { g: 0.5 },
            ..FogLayer::default()
        };
        let f = GpuFog::new(&layer, FogModel::Method, 1.0e7 + 1.0);
        assert_eq!((f.base, f.top, f.thickness), (-1.0, -0.75, 0.25));
        assert_eq!((f.phase, f.g, f.model), (PHASE_PRINTED, 0.5, FOG_METHOD));
        assert_eq!((f.scale_height, f.albedo[2]), (30.0, 0.7));
        let plain = GpuFog::new(&FogLayer::default(), FogModel::Exact, 0.0);
        assert_eq!((plain.scale_height, plain.model), (0.0, FOG_EXACT));
        assert_eq!(plain.phase, PHASE_HENYEY_GREENSTEIN);
    }
}
