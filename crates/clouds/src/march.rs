//! The cloud march (docs/methods.md §6), the CPU reference: a ray is clipped to the volume's box, then
//! marched in equidistant steps (offset by a per-pixel jitter against banding); at each sample with
//! density a secondary ray toward the sun of a few steps gives the light that reaches it
//! (Beer–Lambert), scattered by a Henyey–Greenstein phase (a dual-lobe mix as an option) plus an
//! ambient term. Each step's in-scatter integrates `σ e^{−σ s}` over the step exactly for the
//! step's density (`1 − e^{−σΔ}`), so thick steps do not overshoot; the march ends early once
//! the transmittance is below a threshold, and at `t_max` (the opaque hit inside the cloud).

use crate::bake::Region;
use crate::{DensityGrid, MaxGrid};

/// Extinction anywhere in a box: what the march samples.
pub trait Density: Sync {
    /// Extinction (1/m) at `p`; 0 outside [`Density::region`].
    fn density(&self, p: [f64; 3]) -> f64;
    /// The box outside which the density is zero.
    fn region(&self) -> Region;

    /// Empty-space skipping: if the density is provably zero from `p` along `d` (unit) for some
    /// distance, that distance (the march skips its samples there, which would all be zero:
    /// lossless); `None` where it is not known to be zero.
    fn empty_for(&self, _p: [f64; 3], _d: [f64; 3]) -> Option<f64> {
        None
    }
}

/// A baked or loaded grid placed in the world over `region`, its samples times `scale` (1/m);
/// with `skip`, its max grid for empty-space skipping.
#[derive(Clone, Debug, PartialEq)]
pub struct GridVolume {
    pub grid: DensityGrid,
    pub region: Region,
    pub scale: f64,
    pub skip: Option<MaxGrid>,
}

impl Density for GridVolume {
    fn density(&self, p: [f64; 3]) -> f64 {
        let r = &self.region;
        if (0..3).any(|a| !(r.min[a]..=r.max[a]).contains(&p[a])) {
            return 0.0;
        }
        let unit = std::array::from_fn(|a| (p[a] - r.min[a]) / (r.max[a] - r.min[a]));
        self.scale * self.grid.sample(unit)
    }

    fn region(&self) -> Region {
        self.region
    }

    fn empty_for(&self, p: [f64; 3], d: [f64; 3]) -> Option<f64> {
        let skip = self.skip.as_ref()?;
        let r = &self.region;
        let extent: [f64; 3] = std::array::from_fn(|a| r.max[a] - r.min[a]);
        let unit = std::array::from_fn(|a| (p[a] - r.min[a]) / extent[a]);
        let (bound, lo, hi) = skip.block_at(unit);
        if bound > 0.0 {
            return None;
        }
        // Every trilinear sample in the block is ≤ its bound 0 (and ≥ 0 for a grid of
        // non-negative densities): zero until the ray leaves the block's box.
        let block = Region {
            min: std::array::from_fn(|a| r.min[a] + lo[a] * extent[a]),
            max: std::array::from_fn(|a| r.min[a] + hi[a] * extent[a]),
        };
        clip(&block, p, d, 0.0, f64::INFINITY).map(|(_, out)| out)
    }
}

/// The phase function of cloud droplets: `(1 − w)·HG(g₁) + w·HG(g₂)` (one lobe: `w = 0`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualLobe {
    pub g1: f64,
    pub g2: f64,
    pub weight: f64,
}

impl DualLobe {
    /// A single Henyey–Greenstein lobe.
    pub const fn single(g: f64) -> Self {
        Self {
            g1: g,
            g2: 0.0,
            weight: 0.0,
        }
    }

    /// `p(cos θ)` in 1/sr, θ between the light's travel and the scattered direction.
    pub fn eval(&self, cos_theta: f64) -> f64 {
        let hg = |g: f64| {
            let d = (1.0 + g * g - 2.0 * g * cos_theta.clamp(-1.0, 1.0)).max(1e-300);
            (1.0 - g * g) / (4.0 * std::f64::consts::PI * d * d.sqrt())
        };
        (1.0 - self.weight) * hg(self.g1) + self.weight * hg(self.g2)
    }
}

/// How the cloud is lit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CloudLight {
    /// Unit vector toward the sun and its irradiance (W/m², RGB).
    pub sun_direction: [f64; 3],
    pub sun_irradiance: [f64; 3],
    /// Uniform ambient radiance (RGB), scattered isotropically.
    pub ambient: [f64; 3],
    /// Single-scattering albedo (cloud droplets: close to 1).
    pub albedo: f64,
    pub phase: DualLobe,
}

/// The march's knobs: what trades time for error.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchSettings {
    /// The view ray's step length (world units); the steps are equal, the last shortened.
    pub step: f64,
    /// Steps of each sun ray (over its whole path in the box).
    pub sun_steps: u32,
    /// Where in each step the sample lies, in `[0, 1)` (per pixel: a jitter; 0.5: midpoints).
    pub jitter: f64,
    /// The march stops once the transmittance is below this.
    pub min_transmittance: f64,
}

impl Default for MarchSettings {
    fn default() -> Self {
        Self {
            step: 50.0,
            sun_steps: 6,
            jitter: 0.5,
            min_transmittance: 1e-3,
        }
    }
}

/// What the cloud does to a ray: `L = transmittance · L_behind + in_scatter`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarchResult {
    pub transmittance: f64,
    pub in_scatter: [f64; 3],
    /// Density samples taken (view ray), for stats.
    pub samples: u32,
}

/// The part `[lo, hi]` of `[t0, t1]` where `o + t·d` is inside `region` (`None` if nowhere).
pub fn clip(region: &Region, o: [f64; 3], d: [f64; 3], t0: f64, t1: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (t0, t1);
    for a in 0..3 {
        if d[a] == 0.0 {
            if !(region.min[a]..=region.max[a]).contains(&o[a]) {
                return None;
            }
            continue;
        }
        let (ta, tb) = ((region.min[a] - o[a]) / d[a], (region.max[a] - o[a]) / d[a]);
        lo = lo.max(ta.min(tb));
        hi = hi.min(ta.max(tb));
    }
    (lo <= hi).then_some((lo, hi))
}

/// Marches `o + t·d` (`d` unit) over `[t0, t_max]` through `volume`.
pub fn march(
    volume: &dyn Density,
    o: [f64; 3],
    d: [f64; 3],
    (t0, t_max): (f64, f64),
    settings: &MarchSettings,
    light: &CloudLight,
) -> MarchResult {
    let mut result = MarchResult {
        transmittance: 1.0,
        in_scatter: [0.0; 3],
        samples: 0,
    };
    let region = volume.region();
    let Some((lo, hi)) = clip(&region, o, d, t0, t_max) else {
        return result;
    };
    let length = hi - lo;
    if length.is_nan() || length <= 0.0 || settings.step.is_nan() || settings.step <= 0.0 {
        return result;
    }
    let steps = (length / settings.step).ceil().min(1e7) as u64;
    let dt = length / steps as f64;
    let s = light.sun_direction;
    // The light travels along −s and is scattered toward the eye, along −d: cos θ = s · d.
    let phase = light.phase.eval(s[0] * d[0] + s[1] * d[1] + s[2] * d[2]);
    let jitter = settings.jitter.clamp(0.0, 1.0 - f64::EPSILON);
    for p in Samples::new(volume, o, d, (lo, dt, jitter), steps) {
        let sigma = volume.density(p);
        result.samples += 1;
        if sigma <= 0.0 {
            continue;
        }
        let sun = sun_transmittance(volume, &region, p, s, settings.sun_steps);
        // ∫ over the step of σ e^{−σ u} du, exactly for this step's σ.
        let step_extinction = -(-sigma * dt).exp_m1();
        let weight = result.transmittance * step_extinction * light.albedo;
        for c in 0..3 {
            result.in_scatter[c] +=
                weight * (phase * light.sun_irradiance[c] * sun + light.ambient[c]);
        }
        result.transmittance *= (-sigma * dt).exp();
        if result.transmittance < settings.min_transmittance {
            break;
        }
    }
    result
}

/// The transmittance from `p` toward the sun out of the box, by `steps` midpoint samples. Not
/// skipped: with a few steps a block lookup costs about what the sample it saves does (measured:
/// skipping here made the envelope scene 1.3× slower).
fn sun_transmittance(
    volume: &dyn Density,
    region: &Region,
    p: [f64; 3],
    s: [f64; 3],
    steps: u32,
) -> f64 {
    let Some((_, out)) = clip(region, p, s, 0.0, f64::INFINITY) else {
        return 1.0;
    };
    if out.is_nan() || out <= 0.0 || steps == 0 {
        return 1.0;
    }
    let ds = out / f64::from(steps);
    let mut depth = 0.0;
    for k in 0..steps {
        let u = (f64::from(k) + 0.5) * ds;
        depth += volume.density([p[0] + u * s[0], p[1] + u * s[1], p[2] + u * s[2]]) * ds;
    }
    (-depth).exp()
}

/// `Σ σ(o + t·d)·dt` over the midpoints `t = lo + (k + ½)·dt`, `k < steps`, jumping over the
/// stretches `volume` proves empty: their terms would be exactly zero, so the sum is the same
/// bit for bit.
fn midpoint_depth(
    volume: &dyn Density,
    o: [f64; 3],
    d: [f64; 3],
    lo: f64,
    dt: f64,
    steps: u64,
) -> f64 {
    // Folded from +0 in order: the same bits as summing every sample, zeros included.
    Samples::new(volume, o, d, (lo, dt, 0.5), steps)
        .fold(0.0, |depth, p| depth + volume.density(p) * dt)
}

/// The equidistant samples `lo + (k + offset)·dt`, `k < steps`, of the ray `o + t·d`, less
/// those in stretches the volume proves empty: at a sample in such a stretch the next one is the
/// first at or past its end (the samples skipped would all be zero, so sums over the rest are
/// the same bit for bit).
struct Samples<'a> {
    volume: &'a dyn Density,
    o: [f64; 3],
    d: [f64; 3],
    lo: f64,
    dt: f64,
    offset: f64,
    steps: u64,
    k: u64,
}

impl<'a> Samples<'a> {
    fn new(
        volume: &'a dyn Density,
        o: [f64; 3],
        d: [f64; 3],
        (lo, dt, offset): (f64, f64, f64),
        steps: u64,
    ) -> Self {
        Self {
            volume,
            o,
            d,
            lo,
            dt,
            offset,
            steps,
            k: 0,
        }
    }
}

impl Iterator for Samples<'_> {
    type Item = [f64; 3];

    fn next(&mut self) -> Option<[f64; 3]> {
        let (o, d) = (self.o, self.d);
        while self.k < self.steps {
            let t = self.lo + (self.k as f64 + self.offset) * self.dt;
            let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
            if let Some(empty) = self.volume.empty_for(p, d) {
                let next = ((t + empty - self.lo) / self.dt - self.offset).ceil();
                self.k = if next > self.k as f64 {
                    next.min(self.steps as f64) as u64
                } else {
                    self.k + 1
                };
                continue;
            }
            self.k += 1;
            return Some(p);
        }
        None
    }
}

/// The optical depth `∫ σ dt` along `o + t·d` (`d` unit) over `[t0, t1]` by midpoint samples of
/// about `step` (equal steps, at least one), skipping the stretches `volume` proves empty (the
/// samples there would all be zero: lossless). What a shadow ray toward a light meets.
pub fn optical_depth(
    volume: &dyn Density,
    o: [f64; 3],
    d: [f64; 3],
    (t0, t1): (f64, f64),
    step: f64,
) -> f64 {
    let Some((lo, hi)) = clip(&volume.region(), o, d, t0, t1) else {
        return 0.0;
    };
    let length = hi - lo;
    if length.is_nan() || length <= 0.0 || step.is_nan() || step <= 0.0 {
        return 0.0;
    }
    let steps = (length / step).ceil().clamp(1.0, 1e7) as u64;
    midpoint_depth(volume, o, d, lo, length / steps as f64, steps)
}

/// The per-pixel jitter of the march's samples: Jimenez's interleaved gradient noise
/// `fract(52.9829189 · fract(0.06711056·x + 0.00583715·y))` of pixel `(x, y)`, in `[0, 1)`. Its
/// neighbouring pixels take well-spread offsets, so the banding of equal steps becomes a fine,
/// even pattern (stated sequence; the GPU computes the same in f32).
pub fn pixel_jitter(x: u32, y: u32) -> f64 {
    let fract = |v: f64| v - v.floor();
    let v = fract(52.982_918_9 * fract(0.067_110_56 * f64::from(x) + 0.005_837_15 * f64::from(y)));
    v.min(1.0 - f64::EPSILON)
}
