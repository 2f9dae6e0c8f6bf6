//! The sky under stress: Earth's atmosphere and variants (no Mie, no ozone, thin or thick
//! air, the ground raised `±10⁴`), suns from under the horizon to the zenith; eyes on the
//! ground, a millimetre above it, inside, at the top (±1 µm), above it up to the clamp
//! (`10⁹`) and beyond; directions exactly horizontal, grazing (`|d_y| = 10^[−16, −3]`),
//! vertical and random; ranges `0`, `10^[−3, 8]` m and `∞` — `Sky::aerial_perspective`
//! (1 to 64 steps), `transmittance_to_sun` and the reference optical depth.
//!
//! The reference is the model's definition: the part of the ray inside the atmosphere and above
//! the ground (the sphere crossings, computed here) of length `L`, and the extinction's least
//! and greatest values over the altitudes it spans, `σ_lo ≤ σ_t ≤ σ_hi` per channel (Rayleigh
//! and Mie fall with altitude, the ozone tent peaks once). Per ray:
//! - **no nonsense**: transmittances in `[0, 1]`, in-scatter finite and `≥ 0`;
//! - **bracket**: the march's `τ = −ln T` in `[σ_lo L, σ_hi L]` (every sample of a positive
//!   quadrature lies on the segment), relative `1e-9`, plus the rounding of the crossings and
//!   of `T`, a product of a factor per step (`(2N + 16) ε` of `τ`);
//! - **additive** (one ray in 16): the adaptive-quadrature reference over `[0, t]` equals its two
//!   parts split at `m` (the second from the point at `m`, in its own observer frame) within
//!   `1e-8` relative (its tolerance is `1e-10`) plus the rounding of the split point's radius
//!   (`16 ε r σ_hi / |μ|`), and lies in the bracket.

use super::runner::{self, Family, Tally};
use fray_atmosphere::sky::reference::optical_depth;
use fray_atmosphere::sky::{Sky, SkyModel, SkySun, SkyTables};
use fray_core::MemoryBudget;
use fray_test_support::Rng;
use glam::DVec3;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

const FAMILIES: [&str; 6] = ["ground", "inside", "top", "above", "horizontal", "grazing"];
const RAYS_PER_CASE: usize = 4096;
const REL: f64 = 1e-9;

fn sky_case() -> impl Strategy<Value = (Sky, u64)> {
    (
        0..4u8,
        -0.3..1.0f64,
        prop::option::of(-4.0..4.0f64),
        any::<u64>(),
    )
        .prop_map(|(variant, sun, ground, seed)| {
            let mut model = SkyModel::earth();
            match variant {
                0 => model.mie_scattering = 0.0,
                1 => model.ozone_absorption = DVec3::ZERO,
                2 => {
                    model.rayleigh_scattering *= 10.0;
                    model.mie_absorption *= 10.0;
                }
                _ => {}
            }
            if let Some(g) = ground {
                model.ground_elevation = g.signum() * 10f64.powf(g.abs());
            }
            let tables = SkyTables {
                transmittance_width: 32,
                transmittance_height: 16,
                sky_view_width: 16,
                sky_view_height: 12,
                sky_view_steps: 12,
            };
            let sun = SkySun::from_angles(sun * std::f64::consts::FRAC_PI_2, 0.3, DVec3::ONE);
            let sky = Sky::new(model, sun, tables, &MemoryBudget::unlimited()).expect("valid");
            (sky, seed)
        })
}

/// Where `|r₀ Y + t d| = radius` (the two roots, `None` if the line misses the sphere).
fn crossings(r0: f64, mu: f64, radius: f64) -> Option<(f64, f64)> {
    let disc = r0 * r0 * (mu * mu - 1.0) + radius * radius;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some((-r0 * mu - s, -r0 * mu + s))
}

/// The part of `[0, t]` of the ray from radius `r0` with cosine `mu` inside the atmosphere
/// and before the ground.
fn segment(m: &SkyModel, r0: f64, mu: f64, t: f64) -> Option<(f64, f64)> {
    let (a, b) = crossings(r0, mu, m.top_radius)?;
    let mut end = b.min(t);
    // The eye is never under the ground (`observer_radius` clamps it), so a ray down that
    // meets the ground's sphere meets it first at `g ≥ 0` (rounding aside).
    if let Some((g, _)) = crossings(r0, mu, m.ground_radius)
        && mu < 0.0
    {
        end = end.min(g.max(0.0));
    }
    let start = a.max(0.0);
    (end > start).then_some((start, end))
}

/// The least and greatest extinction (RGB) over altitudes `[h0, h1]`.
fn extinction_range(m: &SkyModel, h0: f64, h1: f64) -> (DVec3, DVec3) {
    let (h0, h1) = (h0.max(0.0), h1.max(0.0));
    let ozone_tent = |h: f64| (1.0 - (h - m.ozone_centre).abs() / (0.5 * m.ozone_width)).max(0.0);
    let peak = if h0 <= m.ozone_centre && m.ozone_centre <= h1 {
        1.0
    } else {
        ozone_tent(h0).max(ozone_tent(h1))
    };
    let falling = |h: f64| {
        m.rayleigh_scattering * m.rayleigh_density(h)
            + DVec3::splat(m.mie_extinction() * m.mie_density(h))
    };
    (
        falling(h1) + m.ozone_absorption * ozone_tent(h0).min(ozone_tent(h1)),
        falling(h0) + m.ozone_absorption * peak,
    )
}

fn run_case(sky: &Sky, seed: u64, tally: &Tally) -> Result<(), TestCaseError> {
    let mut rng = Rng(seed);
    let m = *sky.model();
    let top = m.top_radius - m.ground_radius;
    let mut families = [Family::default(); FAMILIES.len()];
    for i in 0..RAYS_PER_CASE {
        let k = i % FAMILIES.len();
        let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        let altitude = match k {
            0 => [0.0, 1e-3, -1.0][rng.below(3)],
            1 | 4 | 5 => rng.range(0.0, top),
            2 => top + sign * rng.log_uniform(-6.0, 0.0),
            _ => [rng.log_uniform(5.0, 9.0), 1e12][usize::from(rng.unit() < 0.1)],
        };
        let eye = DVec3::new(rng.range(-1e5, 1e5), m.ground_elevation + altitude, 0.0);
        let d = match k {
            4 => {
                let a = rng.range(0.0, std::f64::consts::TAU);
                DVec3::new(a.cos(), 0.0, a.sin())
            }
            5 => {
                let a = rng.range(0.0, std::f64::consts::TAU);
                DVec3::new(a.cos(), sign * rng.log_uniform(-16.0, -3.0), a.sin()).normalize()
            }
            _ if rng.unit() < 0.1 => DVec3::Y * sign,
            _ => rng.direction(),
        };
        let t = match rng.below(4) {
            0 => f64::INFINITY,
            1 => 0.0,
            _ => rng.log_uniform(-3.0, 8.0),
        };
        let steps = 1 + rng.below(64) as u32;
        let fail = |what: String| {
            TestCaseError::fail(format!(
                "{} ray: {what} for eye {eye:?}, dir {d:?}, t {t}, {steps} steps, {m:?}",
                FAMILIES[k]
            ))
        };
        let a = sky.aerial_perspective(eye, d, t, steps);
        let tr = a.transmittance;
        if !(tr.is_finite() && tr.min_element() >= 0.0 && tr.max_element() <= 1.0) {
            return Err(fail(format!("T = {tr:?}")));
        }
        if !(a.in_scatter.is_finite() && a.in_scatter.min_element() >= 0.0) {
            return Err(fail(format!("in-scatter {:?}", a.in_scatter)));
        }
        let p = eye + d * t.min(1e4);
        let to_sun = sky.transmittance_to_sun(p, eye);
        if !(to_sun.is_finite() && to_sun.min_element() >= 0.0 && to_sun.max_element() <= 1.0) {
            return Err(fail(format!(
                "transmittance to the sun {to_sun:?} at {p:?}"
            )));
        }
        let r0 = m.observer_radius(eye.y);
        let mu = d.y.clamp(-1.0, 1.0);
        let span = segment(&m, r0, mu, t);
        let (lo, hi, len) = span.map_or((DVec3::ZERO, DVec3::ZERO, 0.0), |(a, b)| {
            let r = |s: f64| (r0 * r0 + 2.0 * r0 * mu * s + s * s).max(0.0).sqrt();
            let perigee = (-r0 * mu).clamp(a, b);
            let radii = [r(a), r(b), r(perigee)];
            let h0 = radii.iter().copied().fold(f64::INFINITY, f64::min) - m.ground_radius;
            let h1 = radii.iter().copied().fold(0.0, f64::max) - m.ground_radius;
            let (lo, hi) = extinction_range(&m, h0, h1);
            (lo, hi, b - a)
        });
        // The crossings' rounding: the discriminant `r₀²(μ² − 1) + R²` loses `ε r₀²`, which
        // moves a crossing by `ε r₀² / √disc`.
        let sqrt_disc = |radius: f64| (r0 * r0 * (mu * mu - 1.0) + radius * radius).abs().sqrt();
        let conditioning = sqrt_disc(m.top_radius)
            .min(sqrt_disc(m.ground_radius))
            .max(1.0);
        let slack =
            hi * (64.0 * f64::EPSILON * m.top_radius * m.top_radius / conditioning).min(len);
        let bracket = |tau: DVec3, extra: DVec3, what: &str| -> Result<f64, TestCaseError> {
            let slack = slack + extra;
            let (low, high) = (
                lo * len * (1.0 - REL) - slack,
                hi * len * (1.0 + REL) + slack,
            );
            for c in 0..3 {
                if !(tau[c] >= low[c] && tau[c] <= high[c]) {
                    return Err(fail(format!(
                        "{what} τ = {tau:?} outside [{low:?}, {high:?}] (L = {len})"
                    )));
                }
            }
            Ok((0..3)
                .map(|c| {
                    (tau[c] - hi[c] * len).max(lo[c] * len - tau[c]).max(0.0)
                        / tau[c].max(slack[c]).max(1e-300)
                })
                .fold(0.0, f64::max))
        };
        // −ln T where T keeps digits (an opaque path's τ is only known to be large).
        if tr.min_element() > 1e-300 {
            let tau = -DVec3::new(tr.x.ln(), tr.y.ln(), tr.z.ln());
            families[k].worst = families[k].worst.max(bracket(
                tau,
                DVec3::splat(f64::from(2 * steps + 16) * f64::EPSILON),
                "the march's",
            )?);
        }
        if i % 16 == 0 && span.is_some() {
            let whole = optical_depth(&m, eye, d, t);
            bracket(whole, DVec3::ZERO, "the reference's")?;
            if t.is_finite() {
                let s = t * rng.unit();
                // The point at s, in its own observer frame: its radius and the ray's cosine there.
                let q = DVec3::Y * r0 + d * s;
                let (r1, mu1) = (q.length(), (q.dot(d) / q.length()).clamp(-1.0, 1.0));
                let eye1 = DVec3::new(0.0, m.ground_elevation + (r1 - m.ground_radius), 0.0);
                let d1 = DVec3::new((1.0 - mu1 * mu1).sqrt(), mu1, 0.0);
                let parts = optical_depth(&m, eye, d, s) + optical_depth(&m, eye1, d1, t - s);
                let ground =
                    mu < 0.0 && crossings(r0, mu, m.ground_radius).is_some_and(|(g, _)| g < t);
                let err = (parts - whole).abs().max_element();
                // The split point's radius is rounded (`ε r₀`), which moves the second part's
                // crossings by that over its cosine.
                let moved = hi.max_element() * 16.0 * f64::EPSILON * r1 / mu1.abs().max(1e-6);
                // Past the ground the first part stops there and the second starts under it.
                if !ground && r1 - m.ground_radius > 1.0 && err > 1e-8 * whole.max_element() + moved
                {
                    return Err(fail(format!(
                        "the reference's τ = {whole:?} but its parts at {s} sum to {parts:?}"
                    )));
                }
            }
        }
        families[k].count(span.is_some());
    }
    tally.add(&families);
    Ok(())
}

#[test]
fn sky() {
    let name = "sky";
    let cases = 48;
    let tally = Tally::new(
        name,
        &FAMILIES,
        "the march's τ outside [σ_lo L, σ_hi L], relative",
    );
    runner::run(name, cases, sky_case(), |(sky, seed)| {
        run_case(&sky, seed, &tally)
    });
    let total = tally.report();
    let planned = runner::cases(cases) * RAYS_PER_CASE as u64;
    assert!(total >= planned, "{name}: {total} rays, planned {planned}");
}
