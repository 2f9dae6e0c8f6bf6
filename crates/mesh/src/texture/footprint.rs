//! The footprint rule: how wide, in uv, the part of the texture seen by one pixel is — from the
//! pixel's world width at the hit ([`fray_core::PixelFootprint::at`]), the angle between the
//! ray and the surface, and the mapping's uv per world unit — and, for meshes, the uv per world
//! unit of a triangle.
//!
//! A pixel's cone meets a surface in an ellipse: `w` wide across (the pixel's width at the
//! hit) and `w / |cos θ|` long, `θ` between the ray and the normal. A single trilinear lookup
//! is isotropic, so it must pick one width; the rule takes the **longer axis** — the
//! conservative side, blurring along the shorter axis rather than aliasing along the longer —
//! but caps the stretch `1 / |cos θ|` at [`Footprint::max_anisotropy`] (default 8: at most
//! three levels coarser than the across width), so a surface seen edge-on is not filtered to
//! its 1 × 1 level at once. Past the cap (`|cos θ| < 1/8`, grazing beyond 82.8°) the longer axis
//! is under-filtered by `1 / (8 |cos θ|)`; distance still coarsens the level, so far pixels near
//! a horizon reach the coarse levels through `w`. Measured on a receding plane against a
//! supersampled reference (`tests/texture_aa.rs`): caps of 1, 2 and 4 alias on a checker seen
//! from just above the plane; 8, 16 and no cap are within 0.003 RMS of each other there, and 8
//! blurs the least.

use glam::{DVec2, DVec3};

/// The footprint rule (module documentation): the longer axis of the pixel's ellipse, its
/// stretch capped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// The largest stretch `1 / |cos θ|` of the longer axis over the pixel's width (≥ 1).
    pub max_anisotropy: f64,
}

impl Footprint {
    /// The default cap on the stretch: 8 (three levels).
    pub const DEFAULT_MAX_ANISOTROPY: f64 = 8.0;

    /// The rule with stretch capped at `max_anisotropy` (values below 1, or NaN, count as 1:
    /// the across width alone).
    pub fn new(max_anisotropy: f64) -> Self {
        Self {
            max_anisotropy: if max_anisotropy >= 1.0 {
                max_anisotropy
            } else {
                1.0
            },
        }
    }

    /// The stretch of the longer axis over the pixel's width: `1 / |cos θ|`, at most the cap.
    pub fn stretch(&self, cos_theta: f64) -> f64 {
        let cap = self.max_anisotropy.max(1.0);
        let c = cos_theta.abs();
        if c * cap > 1.0 { 1.0 / c } else { cap }
    }

    /// The footprint's width in uv: `pixel_width · stretch(cos θ) · uv_per_world`, with
    /// `pixel_width` the pixel's world width at the hit (`PixelFootprint::at(t)`), `cos_theta`
    /// the cosine between the ray and the normal (either sign) and `uv_per_world` the mapping's
    /// scale at the point ([`crate::texture::Projected::uv_per_world`],
    /// [`triangle_uv_per_world`]). Never NaN or negative (bad input reads 0: the base level);
    /// at most `f64::MAX`.
    pub fn uv_width(&self, pixel_width: f64, cos_theta: f64, uv_per_world: f64) -> f64 {
        let w = pixel_width * self.stretch(cos_theta) * uv_per_world;
        if w > 0.0 { w.min(f64::MAX) } else { 0.0 }
    }

    /// The footprint in base texels of a texture `texels_per_uv` texels across a uv unit
    /// ([`crate::texture::Texture::texels_per_uv`]): what the level of detail is the `log₂` of.
    pub fn texels(
        &self,
        pixel_width: f64,
        cos_theta: f64,
        uv_per_world: f64,
        texels_per_uv: f64,
    ) -> f64 {
        let t = self.uv_width(pixel_width, cos_theta, uv_per_world) * texels_per_uv;
        if t > 0.0 { t.min(f64::MAX) } else { 0.0 }
    }
}

impl Default for Footprint {
    fn default() -> Self {
        Self::new(Self::DEFAULT_MAX_ANISOTROPY)
    }
}

/// The uv per world unit of a triangle's texture map: the largest stretch (largest singular
/// value) of the affine map from the triangle's plane to uv, so a world length `ℓ` in the
/// triangle never spans more than `ℓ ·` this in uv — the conservative side. For a conformal map
/// (uv a rotated, uniformly scaled copy of the triangle) it is `√(uv area / world area)`; a
/// stretched map gives more. A triangle of zero world area (never hit) or a non-finite input
/// gives 0 (the base level).
pub fn triangle_uv_per_world(positions: [DVec3; 3], uvs: [DVec2; 3]) -> f64 {
    let (e1, e2) = (positions[1] - positions[0], positions[2] - positions[0]);
    let (d1, d2) = (uvs[1] - uvs[0], uvs[2] - uvs[0]);
    let Some(a) = e1.try_normalize() else {
        return 0.0;
    };
    let Some(b) = (e2 - a * e2.dot(a)).try_normalize() else {
        return 0.0;
    };
    // The edges in the plane's frame (a, b): e1 = (l, 0), e2 = (p, q).
    let (l, p, q) = (e1.dot(a), e2.dot(a), e2.dot(b));
    let det = l * q;
    if det == 0.0 || !det.is_finite() {
        return 0.0;
    }
    // J = D · E⁻¹ with D = [d1 d2], E = [[l, p], [0, q]]: E⁻¹ = [[1/l, −p/(l q)], [0, 1/q]].
    let c0 = d1 / l;
    let c1 = (d2 - d1 * (p / l)) / q;
    // σ²max of J = [c0 c1]: the larger eigenvalue of JᵀJ.
    let (m00, m01, m11) = (c0.dot(c0), c0.dot(c1), c1.dot(c1));
    let half = 0.5 * (m00 + m11);
    let disc = (0.25 * (m00 - m11) * (m00 - m11) + m01 * m01).sqrt();
    let s = (half + disc).max(0.0).sqrt();
    if s.is_finite() { s } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stretch is `1/|cos|` up to the cap; bad input never gives NaN.
    #[test]
    fn stretch_is_capped_and_widths_are_never_nan() {
        let f = Footprint::default();
        assert_eq!(f.stretch(1.0), 1.0);
        assert_eq!(f.stretch(-0.5), 2.0);
        assert_eq!(f.stretch(0.0), 8.0);
        assert_eq!(f.stretch(f64::NAN), 8.0);
        assert_eq!(f.uv_width(0.01, 0.5, 2.0), 0.04);
        for bad in [f64::NAN, f64::INFINITY, -1.0, 0.0] {
            for w in [
                f.uv_width(bad, 0.5, 1.0),
                f.uv_width(1.0, bad, 1.0),
                f.uv_width(1.0, 0.5, bad),
            ] {
                assert!(w.is_finite() && w >= 0.0, "{w}");
            }
        }
        assert_eq!(Footprint::new(0.2).max_anisotropy, 1.0);
    }

    /// A conformal map's stretch is the square root of the area ratio; a map stretched 3× along
    /// one edge gives 3× the world scale; degenerate triangles give 0.
    #[test]
    fn triangle_scale_is_the_largest_stretch() {
        let p = [
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 2.0),
        ];
        // uv = rotated by 90° and scaled by 0.25.
        let uv = [DVec2::ZERO, DVec2::new(0.0, 0.5), DVec2::new(-0.5, 0.0)];
        let s = triangle_uv_per_world(p, uv);
        assert!((s - 0.25).abs() < 1e-15, "{s}");
        let area = |a: DVec2, b: DVec2| (a.perp_dot(b)).abs();
        let ratio = area(uv[1] - uv[0], uv[2] - uv[0]) / (p[1] - p[0]).cross(p[2] - p[0]).length();
        assert!((s - ratio.sqrt()).abs() < 1e-15);
        let stretched = [DVec2::ZERO, DVec2::new(1.5, 0.0), DVec2::new(0.0, 0.5)];
        assert!((triangle_uv_per_world(p, stretched) - 0.75).abs() < 1e-15);
        assert_eq!(triangle_uv_per_world([DVec3::ZERO; 3], uv), 0.0);
        let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert_eq!(triangle_uv_per_world(line, uv), 0.0);
        let nan = [DVec3::ZERO, DVec3::X, DVec3::splat(f64::NAN)];
        assert_eq!(triangle_uv_per_world(nan, uv), 0.0);
    }
}
