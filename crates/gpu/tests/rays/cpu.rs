//! The f64 CPU backend: the model crates' own casters, media and marches.

use glam::DVec3;

/// `fray_geometry::RayCaster` at the scene's ε, `fray_mesh`'s BVHs, `fray_terrain`'s search,
/// `fray_atmosphere`'s fog and sky, `fray_clouds`' march.
pub struct Cpu;

/// The unit normal of a triangle by its winding.
pub fn triangle_normal(c: &[DVec3; 3]) -> DVec3 {
    (c[1] - c[0]).cross(c[2] - c[0]).normalize_or_zero()
}

impl crate::backend::Named for Cpu {
    fn name(&self) -> &'static str {
        "cpu"
    }
}
