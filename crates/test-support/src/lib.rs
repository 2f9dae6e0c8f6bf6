//! Helpers fray's tests share across crates (`publish = false`, a dev-dependency only): a seeded
//! random stream ([`Rng`]), the text of scenes two crates' tests render ([`scenes`]) and image
//! fixtures ([`images`]), and the f64 triangle test and cube the mesh tests share ([`triangles`]), and reference root finding
//! along a ray ([`roots`]). It depends on no fray crate, so the model crates' tests may use it and
//! stay independent of each other.

pub mod images;
pub mod rng;
pub mod roots;
pub mod scenes;
pub mod triangles;

pub use rng::Rng;
