//! The scene's clouds: what a file's `clouds:` means once checked — a density grid placed over a
//! world box (a cloud layer baked from improved noise inside its envelope, or a volume read from
//! a file), its max grid for empty-space skipping, the droplets' optics and the march's knobs —
//! built once here and shared by the backends; errors name file, line and field.

use crate::checks::{Result, bounds, invalid, non_negative, positive};
use crate::description::{self, CloudDensity, CloudProfile};
use crate::path::FieldPath;
use crate::solid::bounding_solid;
use fray_clouds::bake::Region;
use fray_clouds::fractal::Fractal;
use fray_clouds::march::{DualLobe, GridVolume, MarchSettings};
use fray_clouds::{CloudField, Envelope, HeightProfile};
use fray_geometry::Solid;
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The largest grid side a layer may ask for (512³ is the top; 1024 leaves room).
pub const MAX_CLOUD_RESOLUTION: u32 = 1024;
/// The most steps a sun ray may take.
pub const MAX_SUN_STEPS: u32 = 256;
/// The largest max-grid block side.
pub const MAX_SKIP_BLOCK: u32 = 64;

/// A scene's cloud volume, built (baked or loaded) once.
#[derive(Clone, Debug)]
pub struct Clouds {
    /// The grid over its region, its samples times the extinction at density 1 (1/m), and its
    /// max grid when skipping is on.
    pub volume: GridVolume,
    /// Where the grid came from.
    pub source: CloudSource,
    /// Single-scattering albedo `σ_s / (σ_s + σ_a)`.
    pub albedo: f64,
    pub phase: DualLobe,
    /// The factor on the scene's ambient radiance scattered in.
    pub ambient: f64,
    /// Step, sun steps and the transmittance cut-off; `jitter` 0.5 (the backends offset it per
    /// pixel when [`Clouds::jitter`] is on).
    pub march: MarchSettings,
    pub jitter: bool,
    /// The max grid's block side (`None`: no skipping).
    pub skip_block: Option<u32>,
}

/// Where a cloud grid came from (for stats).
#[derive(Clone, Debug, PartialEq)]
pub enum CloudSource {
    /// Baked from noise, in this long.
    Layer { bake: Duration },
    /// Read from this file.
    Volume { path: PathBuf },
}

impl Clouds {
    /// A line for render stats: source, grid size, step counts.
    pub fn describe(&self) -> String {
        let [x, y, z] = self.volume.grid.size();
        let source = match &self.source {
            CloudSource::Layer { bake } => {
                format!("layer baked in {:.0} ms", bake.as_secs_f64() * 1e3)
            }
            CloudSource::Volume { path } => format!("volume {}", path.display()),
        };
        let skip = match self.skip_block {
            Some(b) => format!("skip blocks {b}³"),
            None => "no skipping".into(),
        };
        format!(
            "{source}, {x}×{y}×{z}, step {}, {} sun steps, {skip}",
            self.march.step, self.march.sun_steps
        )
    }
}

/// A free-form envelope: depth `F / |∇F|`, the first-order distance inside the surface.
struct SolidEnvelope(Solid);

/// How many of an envelope's leaves and perturbations cost a bake's depth query what one Perlin
/// octave does: measured (`examples/bake_cost.rs`, 96³ bakes) 25 ns a leaf and 10 ns a
/// perturbation against 36–77 ns an octave; 2 covers the leaves at the octave's cheapest.
pub const ENVELOPE_TERMS_PER_OCTAVE: u64 = 2;

impl Envelope for SolidEnvelope {
    fn cost(&self) -> u64 {
        let terms = self.0.leaves().len() + self.0.perturbation_count();
        (terms as u64).div_ceil(ENVELOPE_TERMS_PER_OCTAVE)
    }

    fn depth(&self, p: [f64; 3]) -> f64 {
        let (f, g) = self.0.eval_with_gradient(DVec3::from_array(p));
        let len = g.length();
        if len > 0.0 && len.is_finite() {
            f / len
        } else if f > 0.0 {
            f64::INFINITY
        } else {
            f
        }
    }
}

fn whole(path: &FieldPath, x: f64, lo: u32, hi: u32) -> Result<u32> {
    if x.fract() == 0.0 && x >= f64::from(lo) && x <= f64::from(hi) {
        Ok(x as u32)
    } else {
        invalid(
            path,
            format!("must be a whole number in {lo}..={hi}, got {x}"),
        )
    }
}

fn unit(path: &FieldPath, x: f64) -> Result<f64> {
    if (0.0..=1.0).contains(&x) {
        Ok(x)
    } else {
        invalid(path, format!("must be in [0, 1], got {x}"))
    }
}

fn asymmetry(path: &FieldPath, g: f64) -> Result<f64> {
    if g.is_finite() && g.abs() < 1.0 {
        Ok(g)
    } else {
        invalid(path, format!("must be in (−1, 1), got {g}"))
    }
}

/// Checks and builds `d` (at `path`, the file's `clouds`); files are relative to `base`.
pub(crate) fn resolve(
    path: &FieldPath,
    d: &description::Clouds,
    base: &Path,
    options: &crate::BuildOptions,
) -> Result<Clouds> {
    let budget = &options.budget;
    let region_path = path.field("region");
    let aabb = bounds(&region_path, &d.region)?;
    let extent = aabb.max - aabb.min;
    if extent.min_element() <= 0.0 {
        return invalid(
            &region_path,
            "must have a positive size on every axis".to_string(),
        );
    }
    let region = Region {
        min: aabb.min.to_array(),
        max: aabb.max.to_array(),
    };
    let scattering = non_negative(&path.field("scattering"), d.scattering)?;
    let absorption = non_negative(&path.field("absorption"), d.absorption)?;
    let extinction = scattering + absorption;
    let albedo = if extinction > 0.0 {
        scattering / extinction
    } else {
        1.0
    };
    let phase_path = path.field("phase");
    let phase = DualLobe {
        g1: asymmetry(&phase_path.field("g"), d.phase.g)?,
        g2: asymmetry(&phase_path.field("back_g"), d.phase.back_g)?,
        weight: unit(&phase_path.field("back_weight"), d.phase.back_weight)?,
    };
    let ambient = non_negative(&path.field("ambient"), d.ambient)?;
    let step = match d.step {
        Some(s) => positive(&path.field("step"), s)?,
        None => extent.min_element() / 32.0,
    };
    let sun_steps = whole(&path.field("sun_steps"), d.sun_steps, 1, MAX_SUN_STEPS)?;
    let min_transmittance = d.min_transmittance;
    if !(0.0..1.0).contains(&min_transmittance) {
        return invalid(
            &path.field("min_transmittance"),
            format!("must be in [0, 1), got {min_transmittance}"),
        );
    }
    let march = MarchSettings {
        step,
        sun_steps,
        jitter: 0.5,
        min_transmittance,
    };
    // Refused before anything is built: the sun steps are to blame only where the view steps
    // alone would fit with a single sun step each.
    march.cost(&region).or_else(|e| {
        let view_steps = (region.diagonal() / step).ceil();
        let (field, note) = if view_steps * 2.0 > fray_clouds::cost::MAX_RAY_SAMPLES as f64 {
            let note = if d.step.is_none() {
                " (the default step: the region's smallest side / 32)"
            } else {
                ""
            };
            ("step", note)
        } else {
            ("sun_steps", "")
        };
        invalid(&path.field(field), format!("{e}{note}"))
    })?;
    let skip_block = match whole(&path.field("skip_block"), d.skip_block, 0, MAX_SKIP_BLOCK)? {
        0 => None,
        b => Some(b),
    };

    let density_path = path.field("density");
    let (grid, scale, source) = match &d.density {
        CloudDensity::Layer(layer) => {
            // Located through the variant (`Layer((…))`): the path names the fields inside.
            let at = density_path.clone();
            let started = std::time::Instant::now();
            let grid = bake_layer(&at, layer, region, options)?;
            (
                grid,
                1.0,
                CloudSource::Layer {
                    bake: started.elapsed(),
                },
            )
        }
        CloudDensity::Volume {
            path: file,
            scale,
            threshold,
        } => {
            let at = density_path.clone();
            let scale = non_negative(&at.field("scale"), *scale)?;
            let threshold = crate::checks::finite(&at.field("threshold"), *threshold)?;
            let full = base.join(file);
            let volume = fray_clouds::inr::load(&full, budget)
                .or_else(|e| invalid(&at.field("path"), e.to_string()))?;
            if volume
                .grid
                .data()
                .iter()
                .any(|v| !v.is_finite() || *v < 0.0)
            {
                return invalid(
                    &at.field("path"),
                    format!(
                        "{}: densities must be finite and ≥ 0 (the march and its empty-space \
                         bounds assume it)",
                        full.display()
                    ),
                );
            }
            let grid = if threshold == 0.0 {
                volume.grid
            } else {
                // What lies below the threshold is empty (and skipped); above it, the excess.
                let cut = threshold as f32;
                let data = volume
                    .grid
                    .data()
                    .iter()
                    .map(|v| (v - cut).max(0.0))
                    .collect();
                fray_clouds::DensityGrid::from_data(volume.grid.size(), data)
                    .or_else(|e| invalid(&at.field("path"), e.to_string()))?
            };
            (grid, scale, CloudSource::Volume { path: full })
        }
    };
    let skip = skip_block.map(|b| grid.max_grid(b as usize));
    Ok(Clouds {
        volume: GridVolume {
            grid,
            region,
            scale: scale * extinction,
            skip,
        },
        source,
        albedo,
        phase,
        ambient,
        march,
        jitter: d.jitter,
        skip_block,
    })
}

/// The layer's field inside its envelope, baked over `region`.
fn bake_layer(
    path: &FieldPath,
    d: &description::CloudLayer,
    region: Region,
    options: &crate::BuildOptions,
) -> Result<fray_clouds::DensityGrid> {
    let res_path = path.field("resolution");
    let mut size = [0usize; 3];
    for (a, side) in size.iter_mut().enumerate() {
        *side = whole(&res_path.index(a), d.resolution[a], 1, MAX_CLOUD_RESOLUTION)? as usize;
    }
    let feature_size = positive(&path.field("feature_size"), d.feature_size)?;
    let octaves = whole(&path.field("octaves"), d.octaves, 1, 12)?;
    let lacunarity = positive(&path.field("lacunarity"), d.lacunarity)?;
    let gain = unit(&path.field("gain"), d.gain)?;
    let coverage = unit(&path.field("coverage"), d.coverage)?;
    let threshold = d.threshold;
    if !(0.0..1.0).contains(&threshold) {
        return invalid(
            &path.field("threshold"),
            format!("must be in [0, 1), got {threshold}"),
        );
    }
    let profile = match d.profile {
        CloudProfile::Cumulus => HeightProfile::CUMULUS,
        CloudProfile::Stratus => HeightProfile::STRATUS,
        CloudProfile::Cumulonimbus => HeightProfile::CUMULONIMBUS,
        CloudProfile::Custom {
            base_ramp,
            top_start,
        } => {
            let at = path.field("profile");
            let base_ramp = unit(&at.field("base_ramp"), base_ramp)?;
            let top_start = unit(&at.field("top_start"), top_start)?;
            if top_start < base_ramp {
                return invalid(
                    &at.field("top_start"),
                    format!("must be ≥ base_ramp ({base_ramp}), got {top_start}"),
                );
            }
            HeightProfile {
                base_ramp,
                top_start,
            }
        }
    };
    let envelope_fade = non_negative(&path.field("envelope_fade"), d.envelope_fade)?;
    let worley = unit(&path.field("worley"), d.worley)?;
    let field = CloudField {
        base: region.min[1],
        top: region.max[1],
        frequency: 1.0 / feature_size,
        noise: Fractal {
            octaves,
            lacunarity,
            gain,
        },
        seed: d.seed,
        coverage,
        threshold,
        density_scale: 1.0,
        profile,
        envelope_fade,
        worley,
    };
    let bake = |envelope: &dyn Envelope| {
        let progress = |done, total| options.report("baking clouds", done, total);
        fray_clouds::bake::bake(&field, envelope, region, size, &options.budget, progress)
            .or_else(|e| invalid(&res_path, e.to_string()))
    };
    match &d.envelope {
        None => bake(&fray_clouds::Unbounded),
        Some(shape) => {
            let solid = bounding_solid(&path.field("envelope"), shape)?;
            bake(&SolidEnvelope(solid))
        }
    }
}
