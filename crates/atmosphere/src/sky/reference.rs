//! The f64 numerical reference of the sky, independent of the tables: optical depth and single
//! scattering by adaptive Gauss–Kronrod quadrature, the sun's transmittance nested inside.
//!
//! Every function works in the observer-centred frame (see [`super`]): the eye is at
//! `(0, r_eye, 0)` from the planet's centre, `r_eye = SkyModel::observer_radius(eye.y)`, and a
//! point `eye + t·dir` is at `(0, r_eye, 0) + t·dir`. The model is assumed valid
//! ([`SkyModel::validate`]); a zero or non-finite direction gives an empty path
//! ([`ScatterTerms::EMPTY`], transmittance 1).
//!
//! Accuracy: the integrals split at every point where the integrand is not smooth — the
//! perigee, the ozone tent's kinks (where the view ray crosses them and where the sun rays'
//! lowest points do), the edges of the planet's shadow — and are refined until QUADPACK's error
//! estimate (`|K15 − G7|`, scaled) of each RGB channel is below [`Accuracy::tolerance`] relative
//! (the nested optical depths to 1/100 of that, with an absolute floor of 1/1000 of it on the
//! zenith columns). The view transmittance at a node is the sum, from the start, of the columns
//! between fixed anchors plus one short integral. With the default 1e-10 the results move by at
//! most 1e-13 relative when the tolerance goes to 1e-12 or the starting panels double, three
//! times (measured in `tests/sky.rs` on five rays, which asserts 1e-9). One evaluation takes
//! about 0.3–5 ms.

use super::geometry::{Planet, Segment};
use super::{ScatterTerms, SkyModel, SkySun, phase};
use crate::quadrature::integrate_rgb as integrate;
use glam::DVec3;

/// How finely the reference integrates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Accuracy {
    /// Relative tolerance on each channel of the outer integral (the inner optical depths get
    /// 1/100 of it, at least 1e-14).
    pub tolerance: f64,
    /// Panels each smooth piece starts with before adaptive refinement.
    pub min_panels: u32,
}

impl Accuracy {
    /// `tolerance` 1e-10, 1 panel per piece.
    pub const DEFAULT: Self = Self {
        tolerance: 1e-10,
        min_panels: 1,
    };
}

impl Default for Accuracy {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The most panels one outer (inner) integral may use.
const MAX_OUTER_PANELS: usize = 4000;
const MAX_INNER_PANELS: usize = 2000;

impl Accuracy {
    fn inner(&self) -> Self {
        Self {
            tolerance: (self.tolerance * 1e-2).max(1e-14),
            min_panels: self.min_panels,
        }
    }
}

/// Sorts `points`, keeps those strictly inside `(t0, t1)` and brackets them with the ends.
fn breakpoints(t0: f64, t1: f64, points: &mut Vec<f64>) {
    points.retain(|&t| t > t0 && t < t1);
    points.push(t0);
    points.push(t1);
    points.sort_by(f64::total_cmp);
}

/// The column densities `(∫ρ_R, ∫ρ_M, ∫ρ_O)` (m) over `[t0, t1]` of the ray from `(r, μ)`.
pub(crate) fn columns(
    model: &SkyModel,
    r: f64,
    mu: f64,
    t0: f64,
    t1: f64,
    accuracy: Accuracy,
) -> DVec3 {
    if t1.partial_cmp(&t0) != Some(std::cmp::Ordering::Greater) {
        return DVec3::ZERO;
    }
    let mut points = Vec::with_capacity(10);
    points.push(-r * mu);
    for radius in model.kink_radii() {
        Planet::crossings(r, mu, radius, &mut points);
    }
    breakpoints(t0, t1, &mut points);
    let mut density = |t: f64| model.densities(Planet::radius_at(r, mu, t) - model.ground_radius);
    // An absolute floor of 1/1000 of the tolerance on the zenith columns: a short piece's own
    // column need not be known to `tolerance` relative (near the ozone tent's feet its density
    // is a difference of nearly equal numbers, good to 1e-16 absolute only).
    let zenith = DVec3::new(
        model.rayleigh_scale_height,
        model.mie_scale_height,
        0.5 * model.ozone_width,
    );
    integrate(
        &mut density,
        &points,
        accuracy.tolerance,
        zenith * (1e-3 * accuracy.tolerance),
        accuracy.min_panels,
        MAX_INNER_PANELS,
    )
}

/// Transmittance from radius `r` toward `μ` to the top of the atmosphere, 0 if the ray meets
/// the ground (the quantity the transmittance table stores).
pub(crate) fn transmittance_to_top(model: &SkyModel, r: f64, mu: f64, accuracy: Accuracy) -> DVec3 {
    let planet = Planet::of(model);
    if planet.hits_ground(r, mu) {
        return DVec3::ZERO;
    }
    let length = planet.distance_to_top(r, mu);
    let c = columns(model, r, mu, 0.0, length, accuracy);
    (-model.optical_depth_of_columns(c)).exp()
}

/// The eye's radius, the unit direction and its cosine with `+Y`, or `None` for a zero or
/// non-finite direction.
fn observer_ray(model: &SkyModel, eye: DVec3, dir: DVec3) -> Option<(f64, DVec3, f64)> {
    let d = dir.try_normalize()?;
    Some((model.observer_radius(eye.y), d, d.y.clamp(-1.0, 1.0)))
}

/// Optical depth (RGB) along `eye + t·dir`, `t ∈ [0, length]` clipped to the atmosphere and
/// stopped on the ground; `length = ∞` goes to the top of the atmosphere or the ground.
pub fn optical_depth(model: &SkyModel, eye: DVec3, dir: DVec3, length: f64) -> DVec3 {
    optical_depth_with(model, eye, dir, length, Accuracy::DEFAULT)
}

/// [`optical_depth`] at a chosen accuracy (the optical depth itself to `accuracy.tolerance`).
pub fn optical_depth_with(
    model: &SkyModel,
    eye: DVec3,
    dir: DVec3,
    length: f64,
    accuracy: Accuracy,
) -> DVec3 {
    let Some((r, _, mu)) = observer_ray(model, eye, dir) else {
        return DVec3::ZERO;
    };
    match Planet::of(model).segment(r, mu, length, true) {
        Some(Segment { t0, t1 }) => {
            model.optical_depth_of_columns(columns(model, r, mu, t0, t1, accuracy))
        }
        None => DVec3::ZERO,
    }
}

/// Transmittance `exp(−τ)` of [`optical_depth`].
pub fn transmittance(model: &SkyModel, eye: DVec3, dir: DVec3, length: f64) -> DVec3 {
    (-optical_depth(model, eye, dir, length)).exp()
}

/// [`transmittance`] at a chosen accuracy.
pub fn transmittance_with(
    model: &SkyModel,
    eye: DVec3,
    dir: DVec3,
    length: f64,
    accuracy: Accuracy,
) -> DVec3 {
    (-optical_depth_with(model, eye, dir, length, accuracy)).exp()
}

/// The planet-centred radius and sun cosine of the world point `p` seen by an observer at
/// `eye` (the radius at least the ground's).
pub(crate) fn point_radius_and_cosine(
    model: &SkyModel,
    p: DVec3,
    eye: DVec3,
    toward_sun: DVec3,
) -> (f64, f64) {
    let rel = p - eye;
    let rel = if rel.is_finite() { rel } else { DVec3::ZERO };
    let q = rel + DVec3::new(0.0, model.observer_radius(eye.y), 0.0);
    let length = q.length();
    let mu = if length > 0.0 {
        (q.dot(toward_sun) / length).clamp(-1.0, 1.0)
    } else {
        1.0
    };
    (length.max(model.ground_radius), mu)
}

/// Transmittance of sunlight from the top of the atmosphere to the world point `p` (seen from
/// `eye`, which fixes the planet's centre), 0 where the planet is in the way.
pub fn transmittance_to_sun(model: &SkyModel, sun: &SkySun, p: DVec3, eye: DVec3) -> DVec3 {
    let (r, mu) = point_radius_and_cosine(model, p, eye, sun.unit_direction());
    transmittance_to_top(model, r, mu, Accuracy::DEFAULT)
}

/// Single scattering toward the eye along `eye + t·dir`, `t ∈ [0, t_max]` clipped to the
/// atmosphere and stopped on the ground (`t_max = ∞` for a ray that hits no object):
///
/// `L = ∫ T_view(t) (σ_R(t) p_R(ν) + σ_M(t) p_M(ν)) E T_sun(t) dt`,
///
/// `ν = dir · sun`, `T_sun = 0` where the sun ray from the point meets the planet. The sun's
/// disc is not included. Also returns the path's transmittance.
pub fn single_scattering(
    model: &SkyModel,
    sun: &SkySun,
    eye: DVec3,
    dir: DVec3,
    t_max: f64,
) -> ScatterTerms {
    single_scattering_with(model, sun, eye, dir, t_max, Accuracy::DEFAULT)
}

/// [`single_scattering`] at a chosen accuracy.
pub fn single_scattering_with(
    model: &SkyModel,
    sun: &SkySun,
    eye: DVec3,
    dir: DVec3,
    t_max: f64,
    accuracy: Accuracy,
) -> ScatterTerms {
    let Some((r0, d, mu)) = observer_ray(model, eye, dir) else {
        return ScatterTerms::EMPTY;
    };
    let planet = Planet::of(model);
    let Some(Segment { t0, t1 }) = planet.segment(r0, mu, t_max, true) else {
        return ScatterTerms::EMPTY;
    };
    let l = sun.unit_direction();
    let nu = d.dot(l).clamp(-1.0, 1.0);
    let (p_r, p_m) = (phase::rayleigh(nu), phase::cornette_shanks(nu, model.mie_g));
    let inner = accuracy.inner();

    let mut points = Vec::with_capacity(16);
    points.push(-r0 * mu);
    for radius in model.kink_radii() {
        Planet::crossings(r0, mu, radius, &mut points);
    }
    planet.shadow_crossings(r0, mu, l.y, nu, &mut points);
    for radius in model.kink_radii() {
        Planet::sun_tangent_crossings(r0, mu, l.y, nu, radius, &mut points);
    }
    breakpoints(t0, t1, &mut points);

    let view = ViewColumns::new(model, r0, mu, &points, inner);
    let mut integrand = |t: f64| {
        let r = Planet::radius_at(r0, mu, t);
        let h = r - model.ground_radius;
        let mu_sun = ((r0 * l.y + t * nu) / r).clamp(-1.0, 1.0);
        let sun_t = transmittance_to_top(model, r, mu_sun, inner);
        if sun_t == DVec3::ZERO {
            return DVec3::ZERO;
        }
        let view_t = (-model.optical_depth_of_columns(view.at(model, r0, mu, t, inner))).exp();
        let scattering =
            model.rayleigh_scattering_at(h) * p_r + DVec3::splat(model.mie_scattering_at(h) * p_m);
        view_t * scattering * sun_t
    };
    let in_scatter = integrate(
        &mut integrand,
        &points,
        accuracy.tolerance,
        DVec3::ZERO,
        accuracy.min_panels,
        MAX_OUTER_PANELS,
    ) * sun.irradiance;
    let transmittance = (-model.optical_depth_of_columns(view.total())).exp();
    ScatterTerms {
        in_scatter,
        transmittance,
    }
}

/// Column densities from the segment's start at fixed anchors (every breakpoint, and 16 equal
/// parts between), so that the view transmittance at a node is the anchor's sum plus a short
/// integral instead of one over the whole way from the eye.
#[derive(Debug)]
struct ViewColumns {
    anchors: Vec<f64>,
    cumulative: Vec<DVec3>,
}

impl ViewColumns {
    const PARTS: u32 = 16;

    /// `points`: the sorted breakpoints, first and last the segment's ends.
    fn new(model: &SkyModel, r: f64, mu: f64, points: &[f64], accuracy: Accuracy) -> Self {
        let mut anchors = Vec::with_capacity(points.len() * Self::PARTS as usize);
        for w in points.windows(2) {
            for k in 0..Self::PARTS {
                anchors.push(w[0] + (w[1] - w[0]) * f64::from(k) / f64::from(Self::PARTS));
            }
        }
        anchors.extend(points.last());
        let mut cumulative = Vec::with_capacity(anchors.len());
        let mut sum = DVec3::ZERO;
        cumulative.push(sum);
        for w in anchors.windows(2) {
            sum += columns(model, r, mu, w[0], w[1], accuracy);
            cumulative.push(sum);
        }
        Self {
            anchors,
            cumulative,
        }
    }

    /// The columns from the start to `t`.
    fn at(&self, model: &SkyModel, r: f64, mu: f64, t: f64, accuracy: Accuracy) -> DVec3 {
        let k = self.anchors.partition_point(|&a| a <= t).saturating_sub(1);
        let (Some(&a), Some(&sum)) = (self.anchors.get(k), self.cumulative.get(k)) else {
            return DVec3::ZERO;
        };
        sum + columns(model, r, mu, a, t, accuracy)
    }

    /// The columns of the whole segment.
    fn total(&self) -> DVec3 {
        self.cumulative.last().copied().unwrap_or(DVec3::ZERO)
    }
}
