//! The sky-view table (Hillaire 2020): the sky's single-scattering radiance for one observer
//! altitude and sun, over view directions in a latitude/longitude layout whose rows crowd at the
//! horizon.
//!
//! The parameterisation (exactly; `r` the observer's radius, `R_g` the ground's, `W × H`
//! texels, `H` even, `h = H / 2`):
//!
//! ```text
//! β   = asin(R_g / r)          angle between the nadir and the horizon (π/2 on the ground)
//! θ_h = π − β                  zenith angle of the horizon (below 90° when above the ground)
//! φ   ∈ [0, π]                 azimuth from the sun's azimuth (the sky is symmetric in ±φ)
//! column x = φ / π · (W − 1)
//! sky (the ray misses the ground),  rows 0 … h − 1:
//!     c = 1 − √(1 − θ/θ_h),        row y = c · (h − 1)       (θ = θ_h (1 − (1 − c)²))
//! ground (the ray meets it),        rows h … H − 1:
//!     c = √((θ − θ_h) / β),        row y = h + c · (h − 1)   (θ = θ_h + β c²)
//! ```
//!
//! Texel centres sit at integer `(x, y)` (normalised GPU coordinates `((x + 0.5)/W,
//! (y + 0.5)/H)`). Row 0 is the zenith, row `h − 1` the horizon seen from above (the grazing
//! ray that goes on to the top of the atmosphere), row `h` the horizon seen from below (the ray
//! that ends on the tangent point) and row `H − 1` the nadir. A lookup first decides the half by
//! Bruneton's ground test (`μ < 0` and `r²(μ² − 1) + R_g² ≥ 0`) and interpolates bilinearly
//! within that half only (rows clamped to it), so the discontinuity at the horizon is never
//! blurred. The view direction of `(θ, φ)` is `cos θ · Y + sin θ (cos φ · s + sin φ · Y × s)`,
//! `s` the sun's horizontal direction (`+X` for a sun at the zenith).
//!
//! Each texel holds the [march](super::march) of its ray over the atmosphere (from the eye, or
//! from where the ray enters the shell for an observer above it, to the top or the ground).
//! The planet's surface itself is black: the ground half holds only the air in front of it.

use super::geometry::Planet;
use super::march::Marcher;
use super::texels::{bilinear, fill_rows};
use glam::DVec3;
use std::f64::consts::PI;

/// The sky's radiance over view directions for one observer and sun; see the module docs.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyViewTable {
    width: u32,
    height: u32,
    layout: Layout,
    texels: Vec<[f32; 4]>,
}

/// The mapping between view directions and texels.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Layout {
    width: u32,
    height: u32,
    planet: Planet,
    r: f64,
    beta: f64,
    theta_h: f64,
    sun_h: DVec3,
    side: DVec3,
}

impl SkyViewTable {
    /// Hillaire's size.
    pub const DEFAULT_WIDTH: u32 = 192;
    /// Hillaire's size.
    pub const DEFAULT_HEIGHT: u32 = 108;

    /// Fills the table for an observer at radius `r` (the caller has checked the sizes — `W ≥
    /// 2`, `H` even and `≥ 4` — and the budget).
    pub(crate) fn build(
        marcher: &Marcher<'_>,
        r: f64,
        width: u32,
        height: u32,
        steps: u32,
    ) -> Self {
        let planet = Planet::of(marcher.model);
        let beta = (planet.ground / r).min(1.0).asin();
        let l = marcher.toward_sun;
        let sun_h = DVec3::new(l.x, 0.0, l.z)
            .try_normalize()
            .unwrap_or(DVec3::X);
        let layout = Layout {
            width,
            height,
            planet,
            r,
            beta,
            theta_h: PI - beta,
            sun_h,
            side: DVec3::Y.cross(sun_h),
        };
        let mut texels = vec![[0.0; 4]; width as usize * height as usize];
        fill_rows(&mut texels, width as usize, |i, j| {
            let (dir, ground) = layout.texel_direction(i as u32, j as u32);
            let mu = dir.y;
            // The half decides the segment: the horizon rows are the two limits.
            let segment = if ground {
                let t_ground = planet.distance_to_ground(r, mu);
                planet
                    .segment(r, mu, f64::INFINITY, false)
                    .map(|s| super::geometry::Segment {
                        t0: s.t0,
                        t1: s.t1.min(t_ground),
                    })
            } else {
                planet.segment(r, mu, f64::INFINITY, false)
            };
            match segment {
                Some(s) => marcher.march(r, dir, s, steps).in_scatter,
                None => DVec3::ZERO,
            }
        });
        Self {
            width,
            height,
            layout,
            texels,
        }
    }

    /// Texels per row (the azimuth axis).
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows (the zenith-angle axis; the horizon between rows `H/2 − 1` and `H/2`).
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row-major (`[j * width + i]`): RGB radiance (W/(m² sr)) and 1.
    pub fn texels(&self) -> &[[f32; 4]] {
        &self.texels
    }

    /// The observer's planet-centred radius the table is for.
    pub fn observer_radius(&self) -> f64 {
        self.layout.r
    }

    /// The zenith angle of the horizon, `θ_h = π − asin(R_g / r)`.
    pub fn horizon_zenith_angle(&self) -> f64 {
        self.layout.theta_h
    }

    /// The unit view direction texel `(i, j)`'s centre stands for, and whether it is in the
    /// ground half.
    pub fn texel_direction(&self, i: u32, j: u32) -> (DVec3, bool) {
        self.layout.texel_direction(i, j)
    }

    /// Continuous texel coordinates `(x, y)` of the view direction `dir` and the rows of its
    /// half, `(x, y, first_row, last_row)`.
    pub fn texel_coordinates(&self, dir: DVec3) -> (f64, f64, u32, u32) {
        self.layout.texel_coordinates(dir)
    }

    /// The sky's in-scattered radiance toward the eye along `dir` (world space; normalised
    /// here; a zero direction looks up), bilinear within its half of the table.
    pub fn lookup(&self, dir: DVec3) -> DVec3 {
        let (x, y, lo, hi) = self.layout.texel_coordinates(dir);
        bilinear(
            &self.texels,
            self.width as usize,
            x,
            y,
            lo as usize,
            hi as usize,
        )
    }
}

impl Layout {
    fn half(&self) -> u32 {
        self.height / 2
    }

    fn texel_direction(&self, i: u32, j: u32) -> (DVec3, bool) {
        let half = self.half();
        let phi = PI * f64::from(i.min(self.width - 1)) / f64::from(self.width - 1);
        let ground = j >= half;
        let c = f64::from(if ground { j - half } else { j }.min(half - 1)) / f64::from(half - 1);
        let theta = if ground {
            self.theta_h + self.beta * c * c
        } else {
            self.theta_h * (1.0 - (1.0 - c) * (1.0 - c))
        };
        let (st, ct) = theta.min(PI).sin_cos();
        let (sp, cp) = phi.sin_cos();
        let dir = DVec3::Y * ct + (self.sun_h * cp + self.side * sp) * st;
        (dir, ground)
    }

    fn texel_coordinates(&self, dir: DVec3) -> (f64, f64, u32, u32) {
        let d = dir.try_normalize().unwrap_or(DVec3::Y);
        let mu = d.y.clamp(-1.0, 1.0);
        let theta = mu.acos();
        let half = self.half();
        let rows = f64::from(half - 1);
        let dot = d.dot(self.sun_h);
        let cross = d.dot(self.side);
        let phi = cross.abs().atan2(dot);
        let x = phi / PI * f64::from(self.width - 1);
        if self.planet.hits_ground(self.r, mu) {
            let c = ((theta - self.theta_h) / self.beta).clamp(0.0, 1.0).sqrt();
            (x, f64::from(half) + c * rows, half, self.height - 1)
        } else {
            let c = 1.0 - (1.0 - theta / self.theta_h).max(0.0).sqrt();
            (x, c * rows, 0, half - 1)
        }
    }
}
