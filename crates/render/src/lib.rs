//! `fray-render`: the thin facade over fray's backends — pick a backend, render a scene, get a
//! [`Frame`](fray_core::Frame), write it as PNG or EXR.
//!
//! ```
//! use fray_render::{RenderOptions, Renderer};
//!
//! let scene = fray_scene::parse(
//!     "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
//!     "inline.ron",
//! )?;
//! let frame = Renderer::new(RenderOptions { width: Some(40), ..Default::default() }).render(&scene)?;
//! assert_eq!((frame.colour.width(), frame.colour.height()), (40, 30)); // aspect kept
//! assert!(frame.stats.hits > 0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod output;
mod renderer;

/// What of a scene the GPU backend does not draw yet (`Auto` renders such scenes on the CPU).
pub use fray_gpu::unsupported_feature as gpu_unsupported_feature;
pub use renderer::{Backend, RenderError, RenderOptions, Renderer, available_backends};
