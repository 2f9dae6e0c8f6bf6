//! The transmittance table: transmittance from radius `r` toward `μ` to the top of the
//! atmosphere, in Bruneton's (2017) `(r, μ)` parameterisation, texels computed in f64 by the
//! reference's quadrature and stored as f32.
//!
//! The texels hold the **optical depth** `τ` (RGB), and a lookup is `exp(−bilinear(τ))`: near
//! the horizon the transmittance falls off exponentially across a texel, and interpolating its
//! logarithm instead of itself cuts the table's worst error over the grid of `tests/sky.rs`
//! from 69 % to 6 % and the sky's at sunset from 3 % to 0.2 % (the march with the table against
//! the integral; `docs/sky.md`). A WGSL twin filters `τ` (four `textureLoad`s, or a filtering
//! sampler) and takes `exp(−τ)`.
//!
//! The parameterisation (exactly; `R_g`, `R_t` the ground and top radii, `W × H` texels):
//!
//! ```text
//! H_top = √(R_t² − R_g²)              distance to the top along the horizon ray from the ground
//! ρ     = √(r² − R_g²)                distance to the horizon from radius r
//! d     = −rμ + √(r²(μ² − 1) + R_t²)  distance to the top along (r, μ)
//! d_min = R_t − r,  d_max = ρ + H_top
//! x_μ = (d − d_min) / (d_max − d_min),  x_r = ρ / H_top      both in [0, 1]
//! u = 0.5/W + x_μ (1 − 1/W),  v = 0.5/H + x_r (1 − 1/H)      (texel-centre mapping)
//! ```
//!
//! so texel column `i` (row `j`) holds exactly `x_μ = i / (W − 1)` (`x_r = j / (H − 1)`): the
//! first column looks straight up (`μ = 1`), the last along the horizon; the first row is the
//! ground, the last the top. The inverse, for filling: `ρ = H_top x_r`, `r = √(ρ² + R_g²)`,
//! `d = d_min + x_μ (d_max − d_min)`, `μ = (H_top² − ρ² − d²) / (2 r d)` (`μ = 1` for `d = 0`),
//! clamped to `[−1, 1]`. Rays that meet the ground are not in the table: [`lookup`] answers 0
//! for them (`μ < 0` and `r²(μ² − 1) + R_g² ≥ 0`). `r` is clamped to `[R_g, R_t]`.
//!
//! [`lookup`]: TransmittanceTable::lookup

use super::geometry::Planet;
use super::reference::{Accuracy, columns};
use super::texels::{bilinear, fill_rows};
use super::{MAX_TABLE_SIDE, SkyModel};
use crate::AtmosphereError;
use fray_core::MemoryBudget;
use glam::DVec3;

/// Transmittance to the top of the atmosphere over `(r, μ)`, stored as optical depth; see the
/// module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct TransmittanceTable {
    width: u32,
    height: u32,
    planet: Planet,
    /// `H_top = √(R_t² − R_g²)`.
    h_top: f64,
    texels: Vec<[f32; 4]>,
}

/// The accuracy the texels are integrated to (far below the interpolation error).
const TEXEL_ACCURACY: Accuracy = Accuracy {
    tolerance: 1e-9,
    min_panels: 1,
};

impl TransmittanceTable {
    /// Bruneton's size.
    pub const DEFAULT_WIDTH: u32 = 256;
    /// Bruneton's size.
    pub const DEFAULT_HEIGHT: u32 = 64;

    /// Builds the table for `model` (validated here) at `width × height` texels, each side in
    /// `2..=4096`, checked against `budget` before allocating.
    pub fn new(
        model: &SkyModel,
        width: u32,
        height: u32,
        budget: &MemoryBudget,
    ) -> Result<Self, AtmosphereError> {
        model.validate()?;
        check_side("sky.tables.transmittance_width", width)?;
        check_side("sky.tables.transmittance_height", height)?;
        let count = u64::from(width) * u64::from(height);
        budget.charge_elements(
            "the sky's transmittance table",
            count,
            std::mem::size_of::<[f32; 4]>() as u64,
        )?;
        let mut table = Self {
            width,
            height,
            planet: Planet::of(model),
            h_top: ((model.top_radius - model.ground_radius)
                * (model.top_radius + model.ground_radius))
                .sqrt(),
            texels: vec![[0.0; 4]; count as usize],
        };
        let params = table.clone_params();
        fill_rows(&mut table.texels, width as usize, |i, j| {
            let (r, mu) = params.texel_parameters(i as u32, j as u32);
            // The texels stand for rays that do not meet the ground (the last column grazes
            // it), so integrate to the top whatever `hits_ground` says at the horizon.
            let length = params.planet.distance_to_top(r, mu);
            let c = columns(model, r, mu, 0.0, length, TEXEL_ACCURACY);
            // exp(−1e30) is 0 already; a bounded τ keeps the f32 texels (and the bilinear
            // weights' products) finite for any valid model.
            model.optical_depth_of_columns(c).min(DVec3::splat(1e30))
        });
        Ok(table)
    }

    /// The table's geometry without its texels (to share with the filling threads).
    fn clone_params(&self) -> Params {
        Params {
            width: self.width,
            height: self.height,
            planet: self.planet,
            h_top: self.h_top,
        }
    }

    /// Texels per row (the `μ` axis).
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Rows (the `r` axis).
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row-major (`[j * width + i]`): RGB optical depth `τ` (the transmittance is
    /// `exp(−τ)`) and 1.
    pub fn texels(&self) -> &[[f32; 4]] {
        &self.texels
    }

    /// The `(r, μ)` texel `(i, j)`'s centre stands for (indices clamped to the table).
    pub fn texel_parameters(&self, i: u32, j: u32) -> (f64, f64) {
        self.clone_params().texel_parameters(i, j)
    }

    /// Continuous texel coordinates `(x, y) = (x_μ (W − 1), x_r (H − 1))` of `(r, μ)` (texel
    /// centres at integers; the GPU's normalised coordinates are `((x + 0.5)/W, (y + 0.5)/H)`).
    pub fn texel_coordinates(&self, r: f64, mu: f64) -> (f64, f64) {
        self.clone_params().texel_coordinates(r, mu)
    }

    /// Transmittance from `(r, μ)` to the top of the atmosphere, `exp(−τ)` of the bilinear
    /// optical depth; 0 if the ray meets the ground.
    pub fn lookup(&self, r: f64, mu: f64) -> DVec3 {
        // NaN falls to the ground looking up (`clamp` would keep it); ground < top is the
        // model's validation.
        let r = if r.is_nan() {
            self.planet.ground
        } else {
            r.clamp(self.planet.ground, self.planet.top)
        };
        let mu = if mu.is_nan() {
            1.0
        } else {
            mu.clamp(-1.0, 1.0)
        };
        if self.planet.hits_ground(r, mu) {
            return DVec3::ZERO;
        }
        let (x, y) = self.texel_coordinates(r, mu);
        let tau = bilinear(
            &self.texels,
            self.width as usize,
            x,
            y,
            0,
            self.height as usize - 1,
        );
        (-tau).exp()
    }
}

/// The table's geometry: what maps texels to `(r, μ)` and back.
#[derive(Clone, Copy, Debug)]
struct Params {
    width: u32,
    height: u32,
    planet: Planet,
    h_top: f64,
}

impl Params {
    fn texel_parameters(&self, i: u32, j: u32) -> (f64, f64) {
        let Planet { ground, top } = self.planet;
        let x_mu = f64::from(i.min(self.width - 1)) / f64::from(self.width - 1);
        let x_r = f64::from(j.min(self.height - 1)) / f64::from(self.height - 1);
        let h_top = self.h_top;
        let rho = h_top * x_r;
        let r = (rho * rho + ground * ground).sqrt().min(top);
        let d_min = top - r;
        let d_max = rho + h_top;
        let d = d_min + x_mu * (d_max - d_min);
        let mu = if d > 0.0 {
            (h_top * h_top - rho * rho - d * d) / (2.0 * r * d)
        } else {
            1.0
        };
        (r, mu.clamp(-1.0, 1.0))
    }

    fn texel_coordinates(&self, r: f64, mu: f64) -> (f64, f64) {
        let Planet { ground, top } = self.planet;
        let h_top = self.h_top;
        let rho = ((r - ground) * (r + ground)).max(0.0).sqrt();
        let d = self.planet.distance_to_top(r, mu);
        let d_min = top - r;
        let d_max = rho + h_top;
        let x_mu = if d_max > d_min {
            (d - d_min) / (d_max - d_min)
        } else {
            0.0
        };
        let x_r = rho / h_top;
        (
            x_mu.clamp(0.0, 1.0) * f64::from(self.width - 1),
            x_r.clamp(0.0, 1.0) * f64::from(self.height - 1),
        )
    }
}

/// A table side must be in `2..=MAX_TABLE_SIDE`.
pub(crate) fn check_side(field: &'static str, side: u32) -> Result<(), AtmosphereError> {
    AtmosphereError::check(
        field,
        f64::from(side),
        (2..=MAX_TABLE_SIDE).contains(&side),
        "a table side must lie in 2..=4096",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texel_centres_round_trip() {
        let model = SkyModel::earth();
        let t = TransmittanceTable::new(&model, 16, 8, &MemoryBudget::unlimited()).unwrap();
        for j in 0..8 {
            for i in 0..16 {
                let (r, mu) = t.texel_parameters(i, j);
                let (x, y) = t.texel_coordinates(r, mu);
                assert!((x - f64::from(i)).abs() < 1e-6, "({i}, {j}): x = {x}");
                assert!((y - f64::from(j)).abs() < 1e-9, "({i}, {j}): y = {y}");
            }
        }
        // The corners: the ground looking up, and the horizon from the ground.
        assert_eq!(t.texel_parameters(0, 0), (model.ground_radius, 1.0));
        let (r, mu) = t.texel_parameters(15, 0);
        assert_eq!(r, model.ground_radius);
        assert!(mu.abs() < 1e-12);
    }
}
