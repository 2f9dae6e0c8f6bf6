//! Rays in the planet-centred frame, by radius `r` and direction cosine `μ` (Bruneton 2017):
//! a point at distance `t` along a ray from radius `r` with `μ = cos(zenith angle)` is at radius
//! `√(t² + 2rμt + r²)`. Where rays meet the ground and the top of the atmosphere, and where a
//! ray's sun rays start meeting the planet (its shadow).

use super::SkyModel;

/// The two spheres of a [`SkyModel`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Planet {
    pub ground: f64,
    pub top: f64,
}

/// The part of a ray inside the atmosphere: `[t0, t1]`, ending on the ground or not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Segment {
    pub t0: f64,
    pub t1: f64,
}

impl Planet {
    pub fn of(model: &SkyModel) -> Self {
        Self {
            ground: model.ground_radius,
            top: model.top_radius,
        }
    }

    /// `r²(μ² − 1) + R²`, written `(rμ)² − (r − R)(r + R)` to avoid cancellation: the ray meets
    /// the sphere of radius `R` where this is ≥ 0.
    pub fn discriminant(r: f64, mu: f64, radius: f64) -> f64 {
        (r * mu) * (r * mu) - (r - radius) * (r + radius)
    }

    /// Whether the ray from `(r, μ)`, `r ≥ ground`, meets the ground (Bruneton's
    /// `RayIntersectsGround`; a ray exactly tangent counts as meeting it).
    pub fn hits_ground(&self, r: f64, mu: f64) -> bool {
        mu < 0.0 && Self::discriminant(r, mu, self.ground) >= 0.0
    }

    /// Distance to the ground along a ray that meets it (`(r² − R²) / (−rμ + √disc)`, stable
    /// for an eye on the ground: 0 there).
    pub fn distance_to_ground(&self, r: f64, mu: f64) -> f64 {
        let disc = Self::discriminant(r, mu, self.ground).max(0.0);
        let den = -r * mu + disc.sqrt();
        let num = ((r - self.ground) * (r + self.ground)).max(0.0);
        if den > 0.0 { num / den } else { 0.0 }
    }

    /// Distance from `(r, μ)` with `r ≤ top` to the top of the atmosphere (0 above it).
    pub fn distance_to_top(&self, r: f64, mu: f64) -> f64 {
        let disc = Self::discriminant(r, mu, self.top).max(0.0);
        let num = ((self.top - r) * (self.top + r)).max(0.0);
        if mu >= 0.0 {
            // (top² − r²) / (rμ + √disc): no cancellation looking up.
            let den = r * mu + disc.sqrt();
            if den > 0.0 { num / den } else { 0.0 }
        } else {
            -r * mu + disc.sqrt()
        }
    }

    /// Radius at distance `t` along the ray from `(r, μ)`.
    pub fn radius_at(r: f64, mu: f64, t: f64) -> f64 {
        (t * t + 2.0 * r * mu * t + r * r).max(0.0).sqrt()
    }

    /// The part of the ray from `(r, μ)`, `r ≥ ground`, inside the atmosphere, stopped on the
    /// ground and at `t_max` if `ground_stops`; `None` if it does not cross the shell before
    /// `t_max`. An eye above the top enters the shell later, or never.
    pub fn segment(&self, r: f64, mu: f64, t_max: f64, ground_stops: bool) -> Option<Segment> {
        let (t0, mut t1) = if r <= self.top {
            (0.0, self.distance_to_top(r, mu))
        } else {
            let disc = Self::discriminant(r, mu, self.top);
            if mu >= 0.0 || disc < 0.0 {
                return None;
            }
            let root = disc.sqrt();
            let num = (r - self.top) * (r + self.top);
            (num / (-r * mu + root), -r * mu + root)
        };
        if ground_stops && self.hits_ground(r, mu) {
            t1 = t1.min(self.distance_to_ground(r, mu));
        }
        // `!(t_max > 0)` also catches NaN: an empty path.
        let t_max = if t_max > 0.0 { t_max } else { 0.0 };
        t1 = t1.min(t_max);
        (t1 > t0).then_some(Segment { t0, t1 })
    }

    /// The distances along the ray from `(r, μ)` where it crosses the sphere of `radius`
    /// (0, 1 or 2 roots, written into `out`).
    pub fn crossings(r: f64, mu: f64, radius: f64, out: &mut Vec<f64>) {
        let disc = Self::discriminant(r, mu, radius);
        if disc < 0.0 {
            return;
        }
        let root = disc.sqrt();
        out.push(-r * mu - root);
        out.push(-r * mu + root);
    }

    /// The distances along the ray from `(r, μ)` (direction `d`) where the sun rays from its
    /// points (toward the sun, of elevation cosine `mu_sun = l.y`, `nu = d·l`) are tangent to
    /// the sphere of `radius`: the roots of `(P·l)² − |P|² + radius² = 0`, `P` the point. For
    /// the ground radius these bound the planet's shadow; for the ozone kinks they are where the
    /// sun's optical depth is not smooth.
    pub fn sun_tangent_crossings(
        r: f64,
        mu: f64,
        mu_sun: f64,
        nu: f64,
        radius: f64,
        out: &mut Vec<f64>,
    ) {
        let a = nu * nu - 1.0;
        let b = 2.0 * (r * mu_sun * nu - r * mu);
        let c = (r * mu_sun) * (r * mu_sun) - (r - radius) * (r + radius);
        quadratic_roots(a, b, c, out);
    }

    /// [`Planet::sun_tangent_crossings`] of the ground and the root of `P·l = 0` (where the sun
    /// ray's lowest point leaves the point itself): where the planet's shadow starts or stops.
    pub fn shadow_crossings(&self, r: f64, mu: f64, mu_sun: f64, nu: f64, out: &mut Vec<f64>) {
        Self::sun_tangent_crossings(r, mu, mu_sun, nu, self.ground, out);
        if nu != 0.0 {
            out.push(-r * mu_sun / nu);
        }
    }
}

/// Real roots of `a t² + b t + c` (the stable form; a vanishing `a` or `b` handled).
fn quadratic_roots(a: f64, b: f64, c: f64, out: &mut Vec<f64>) {
    let disc = b * b - 4.0 * a * c;
    if disc.is_nan() || disc < 0.0 {
        return;
    }
    let q = -0.5 * (b + b.signum() * disc.sqrt());
    if a != 0.0 {
        out.push(q / a);
    }
    if q != 0.0 {
        out.push(c / q);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: Planet = Planet {
        ground: 6_360_000.0,
        top: 6_460_000.0,
    };

    #[test]
    fn distances_on_axis() {
        let r = P.ground + 1000.0;
        assert!((P.distance_to_top(r, 1.0) - 99_000.0).abs() < 1e-6);
        assert!((P.distance_to_ground(r, -1.0) - 1000.0).abs() < 1e-6);
        assert!(P.hits_ground(r, -1.0));
        assert!(!P.hits_ground(r, 0.0));
        assert_eq!(P.distance_to_ground(P.ground, -0.3), 0.0);
        assert!(P.segment(P.ground, -0.3, f64::INFINITY, true).is_none());
        let s = P
            .segment(P.top + 50_000.0, -1.0, f64::INFINITY, true)
            .unwrap();
        assert!((s.t0 - 50_000.0).abs() < 1e-6 && (s.t1 - 150_000.0).abs() < 1e-6);
        assert!(
            P.segment(P.top + 50_000.0, 0.0, f64::INFINITY, true)
                .is_none()
        );
        assert!(P.segment(P.top, 1.0, f64::INFINITY, true).is_none());
    }

    #[test]
    fn shadow_crossing_is_where_sun_rays_graze() {
        // Eye on the ground looking horizontally toward a sun 10° below the horizon: the
        // points nearer than R(1 − cos β)/sin β are in the planet's shadow.
        let beta = 10f64.to_radians();
        let (mu_s, nu) = (-beta.sin(), beta.cos());
        let mut roots = Vec::new();
        P.shadow_crossings(P.ground, 0.0, mu_s, nu, &mut roots);
        let expected = P.ground * (1.0 - beta.cos()) / beta.sin();
        let t = roots
            .iter()
            .copied()
            .min_by(|a, b| (a - expected).abs().total_cmp(&(b - expected).abs()))
            .unwrap();
        assert!((t - expected).abs() < 1e-6, "{t} vs {expected}");
        let lit = |t: f64| {
            let r = Planet::radius_at(P.ground, 0.0, t);
            !P.hits_ground(r, (P.ground * mu_s + t * nu) / r)
        };
        assert!(!lit(t - 1.0) && lit(t + 1.0));
    }
}
