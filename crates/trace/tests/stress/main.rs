//! Numerical stress (issue 27): ≥ 10⁷ adversarial rays, in a bounded run with fixed seeds, over
//! every kind and medium — free forms (with CSG, perturbations, degenerate quadrics, extreme
//! form factors), terrains, meshes, fog, the sky and clouds — each answer checked for nonsense
//! (NaN, infinities, hits behind the range's start) and, against an independent reference,
//! for misses beyond the kind's stated bound. One module per kind; `docs/stress.md` lists the
//! families, the counts, the bounds and the run time.

mod clouds;
mod fog;
mod freeform;
mod mesh;
mod runner;
mod sky;
mod terrain;
