//! `fray-render`: the thin facade over fray's backends — pick a backend, render a scene, get a
//! [`Frame`](fray_core::Frame), write it as PNG or EXR.

pub mod output;
