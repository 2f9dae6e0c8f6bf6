//! The f64 CPU backend: the model crates' own casters, media and marches.

/// `fray_geometry::RayCaster` at the scene's ε, `fray_mesh`'s BVHs, `fray_terrain`'s search,
/// `fray_atmosphere`'s fog and sky, `fray_clouds`' march.
pub struct Cpu;

impl crate::backend::Named for Cpu {
    fn name(&self) -> &'static str {
        "cpu"
    }
}
