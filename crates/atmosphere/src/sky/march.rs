//! The tables' ray march: single scattering along a ray segment in `N` steps, the sun's
//! transmittance and the planet's shadow from the transmittance table (Hillaire 2020's
//! integration, with steps that crowd toward the segment's lowest point).
//!
//! Exactly (for a twin): the segment `[t0, t1]` of the ray from radius `r₀` with direction
//! cosine `μ` is cut at its perigee `t_p = −r₀μ` when `t0 < t_p < t1` (and `N ≥ 2`): the part
//! before gets `n₁ = clamp(round(N (t_p − t0)/(t1 − t0)), 1, N − 1)` steps, the part after
//! `N − n₁`; otherwise the whole segment gets `N`. Each piece `[a, b]` (length `L`) is densest at
//! the end nearer the perigee, `e`: its step `k` of `n` spans `x ∈ [k/n, (k+1)/n]` and samples at
//! `x = (k + ½)/n`, with `t(x) = e ± L xᵖ` measured from `e` into the piece. The exponent
//! `p = 1 + min(Δr / (2 H_R), 1)`, `Δr` the difference of the radii at the piece's ends, crowds
//! steps only as much as the density changes (uniform steps along a level path, quadratic ones
//! up or down through two Rayleigh scale heights or more). A step that contains an edge of the
//! planet's shadow — where the sun's transmittance drops to 0: the first root, inside the step,
//! of `(P·l)² − |P|² + R_g² = 0` with `P·l < 0`, `P` the point, `l` toward the sun — is taken as
//! two, split at the edge, each sampled at its middle.
//!
//! Per sample, with `σ_t`, `σ_s p = σ_R ρ_R p_R(ν) + σ_M ρ_M p_M(ν)` and `T_sun` (from the
//! transmittance table, 0 if the sun ray meets the ground) at the sample and `Δ` the step's
//! length, the step's in-scatter is integrated exactly for constant coefficients,
//! `L += T · σ_s p · T_sun · (1 − e^{−σ_t Δ}) / σ_t` (`Δ` where `σ_t Δ ≤ 10⁻¹²`), and then
//! `T ← T e^{−σ_t Δ}`. The result is `(L · E, T)`.

use super::geometry::{Planet, Segment};
use super::transmittance_table::TransmittanceTable;
use super::{ScatterTerms, SkyModel, phase};
use glam::DVec3;

/// What a march needs besides the ray.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Marcher<'a> {
    pub model: &'a SkyModel,
    pub table: &'a TransmittanceTable,
    /// Unit vector toward the sun.
    pub toward_sun: DVec3,
    pub irradiance: DVec3,
}

/// The running sums of a march.
#[derive(Clone, Copy, Debug)]
struct Sums {
    in_scatter: DVec3,
    transmittance: DVec3,
}

impl Marcher<'_> {
    /// Single scattering and transmittance over `segment` of the ray from radius `r0` in the
    /// unit direction `d` (observer frame), in `steps` steps (at least 1).
    pub fn march(&self, r0: f64, d: DVec3, segment: Segment, steps: u32) -> ScatterTerms {
        let Segment { t0, t1 } = segment;
        // (NaN ends are an empty path too.)
        if t1.partial_cmp(&t0) != Some(std::cmp::Ordering::Greater) {
            return ScatterTerms::EMPTY;
        }
        let steps = steps.max(1);
        let mu = d.y.clamp(-1.0, 1.0);
        let nu = d.dot(self.toward_sun).clamp(-1.0, 1.0);
        let ray = Ray {
            r0,
            mu,
            nu,
            p_r: phase::rayleigh(nu),
            p_m: phase::cornette_shanks(nu, self.model.mie_g),
        };
        let mut sums = Sums {
            in_scatter: DVec3::ZERO,
            transmittance: DVec3::ONE,
        };
        // Where the planet's shadow starts or stops along the ray: the ground-tangent roots
        // whose sun ray leaves the point toward the planet (`P·l < 0`).
        let mut edges = Vec::with_capacity(2);
        Planet::sun_tangent_crossings(
            r0,
            mu,
            self.toward_sun.y,
            nu,
            self.model.ground_radius,
            &mut edges,
        );
        edges.retain(|&t| t > t0 && t < t1 && r0 * self.toward_sun.y + t * nu < 0.0);
        edges.sort_by(f64::total_cmp);
        let tp = -r0 * mu;
        if steps >= 2 && tp > t0 && tp < t1 {
            let share = (f64::from(steps) * (tp - t0) / (t1 - t0)).round();
            let n1 = (share as u32).clamp(1, steps - 1);
            self.piece(&ray, t0, tp, false, n1, &edges, &mut sums);
            self.piece(&ray, tp, t1, true, steps - n1, &edges, &mut sums);
        } else {
            // Rising all the way (dense at the start) or falling (dense at the end).
            self.piece(&ray, t0, t1, tp <= t0, steps, &edges, &mut sums);
        }
        ScatterTerms {
            in_scatter: sums.in_scatter * self.irradiance,
            transmittance: sums.transmittance,
        }
    }

    /// `n` steps over `[a, b]`, traversed from `a`, crowded toward `a` (`dense_at_start`) or `b`;
    /// a step that contains a shadow edge (`edges`, sorted) is taken as two, split there.
    #[allow(clippy::too_many_arguments)]
    fn piece(
        &self,
        ray: &Ray,
        a: f64,
        b: f64,
        dense_at_start: bool,
        n: u32,
        edges: &[f64],
        sums: &mut Sums,
    ) {
        let length = b - a;
        let n_f = f64::from(n);
        // Crowd only as much as the density changes: the exponent goes from 1 (uniform steps)
        // for a piece that keeps its altitude to 2 for one that climbs two Rayleigh scale
        // heights or more.
        let climb =
            (Planet::radius_at(ray.r0, ray.mu, b) - Planet::radius_at(ray.r0, ray.mu, a)).abs();
        let p = 1.0 + (climb / (2.0 * self.model.rayleigh_scale_height)).min(1.0);
        let at = |x: f64| {
            let xp = x.powf(p);
            if dense_at_start {
                a + length * xp
            } else {
                b - length * xp
            }
        };
        // Step k spans x ∈ [k/n, (k+1)/n] (from the dense end), sampled at x = (k + ½)/n; a
        // piece crowded toward its far end is walked from x = 1 down.
        let x_of = |k: f64| {
            if dense_at_start {
                k / n_f
            } else {
                1.0 - k / n_f
            }
        };
        let mut lo = at(x_of(0.0));
        for k in 0..n {
            let k_f = f64::from(k);
            let hi = at(x_of(k_f + 1.0));
            match edges.iter().find(|&&e| e > lo && e < hi) {
                // At most one edge per step matters; a second one in the same step (a ray
                // grazing the shadow) is left to the sampling.
                Some(&e) => {
                    self.step(ray, 0.5 * (lo + e), e - lo, sums);
                    self.step(ray, 0.5 * (e + hi), hi - e, sums);
                }
                None => self.step(ray, at(x_of(k_f + 0.5)), (hi - lo).abs(), sums),
            }
            lo = hi;
        }
    }

    /// One step of length `step` sampled at `t`.
    fn step(&self, ray: &Ray, t: f64, step: f64, sums: &mut Sums) {
        let model = self.model;
        let r = Planet::radius_at(ray.r0, ray.mu, t);
        let h = r - model.ground_radius;
        let mu_sun = if r > 0.0 {
            (ray.r0 * self.toward_sun.y + t * ray.nu) / r
        } else {
            1.0
        };
        let sun_t = self.table.lookup(r, mu_sun);
        let rho = model.densities(h);
        let extinction = model.optical_depth_of_columns(rho);
        let scattering = model.rayleigh_scattering * (rho.x * ray.p_r)
            + DVec3::splat(model.mie_scattering * rho.y * ray.p_m);
        // e^{−σ_t Δ} − 1 per channel: the step's transmittance and, over σ_t, its in-scatter
        // weight ∫₀^Δ e^{−σ_t s} ds (Δ where σ_t vanishes).
        let em1 = DVec3::from_array(std::array::from_fn(|c| (-extinction[c] * step).exp_m1()));
        let weight = DVec3::from_array(std::array::from_fn(|c| {
            let sigma = extinction[c];
            if sigma * step > 1e-12 {
                -em1[c] / sigma
            } else {
                step
            }
        }));
        sums.in_scatter += sums.transmittance * scattering * sun_t * weight;
        sums.transmittance *= DVec3::ONE + em1;
    }
}

/// The per-ray constants of a march.
#[derive(Clone, Copy, Debug)]
struct Ray {
    r0: f64,
    mu: f64,
    nu: f64,
    p_r: f64,
    p_m: f64,
}
