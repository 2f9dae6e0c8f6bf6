//! A sweep's CPU frames: rendered on a fixed number of threads and timed (the median of the
//! repeats), and a frame's colour error against a reference frame — per pixel the largest
//! channel's `|Δ|` of the linear colour, its max, mean and RMS over the frame.

use fray_core::Frame;
use fray_scene::Scene;
use fray_trace::TraceSettings;
use std::time::Instant;

/// One CPU render on `threads` threads with the scene's own settings: its wall time (ms) and
/// the frame.
pub fn render_once(scene: &Scene, threads: usize) -> Result<(f64, Frame), String> {
    let settings = TraceSettings {
        threads: Some(threads),
        ..TraceSettings::for_scene(scene)
    };
    let start = Instant::now();
    let frame = fray_trace::render(scene, &settings, None).map_err(|e| e.to_string())?;
    Ok((start.elapsed().as_secs_f64() * 1e3, frame))
}

/// The median of `v` (NaN when empty).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// The median wall time of `repeats` renders (ms) and the last frame.
pub fn timed(scene: &Scene, threads: usize, repeats: usize) -> Result<(f64, Frame), String> {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let (ms, frame) = render_once(scene, threads)?;
        times.push(ms);
        last = Some(frame);
    }
    let frame = last.ok_or("no frame rendered")?;
    Ok((median(times), frame))
}

/// A frame slower than this (ms) is timed once by [`timed_unless_slow`] (and a sky table build
/// by `bench_sky`), to keep `cargo xtask bench all` within its few minutes.
pub const SLOW_MS: f64 = 1000.0;

/// [`timed`], but a frame whose first render takes over [`SLOW_MS`] is timed once.
pub fn timed_unless_slow(
    scene: &Scene,
    threads: usize,
    repeats: usize,
) -> Result<(f64, Frame), String> {
    let (ms, mut frame) = render_once(scene, threads)?;
    let mut times = vec![ms];
    if ms <= SLOW_MS {
        for _ in 1..repeats {
            let (ms, f) = render_once(scene, threads)?;
            times.push(ms);
            frame = f;
        }
    }
    Ok((median(times), frame))
}

/// A frame's error against a reference: over pixels, the largest channel's `|Δ|` in linear
/// colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    pub max: f64,
    pub mean: f64,
    pub rms: f64,
}

impl ImageError {
    /// The error of `got` against `reference`; frames of different sizes are an error.
    pub fn of(reference: &Frame, got: &Frame) -> Result<Self, String> {
        let (a, b) = (&reference.colour, &got.colour);
        if (a.width(), a.height()) != (b.width(), b.height()) {
            return Err(format!(
                "frames of different sizes: {}×{} against {}×{}",
                a.width(),
                a.height(),
                b.width(),
                b.height()
            ));
        }
        let (mut max, mut sum, mut sum_sq) = (0.0f64, 0.0f64, 0.0f64);
        for (r, g) in a.pixels().iter().zip(b.pixels()) {
            let d = f64::from((*r - *g).abs().max_element());
            max = max.max(d);
            sum += d;
            sum_sq += d * d;
        }
        let n = a.pixels().len().max(1) as f64;
        Ok(Self {
            max,
            mean: sum / n,
            rms: (sum_sq / n).sqrt(),
        })
    }

    /// The error in units of `scale` (e.g. the reference's brightest pixel).
    pub fn relative(self, scale: f64) -> Self {
        let s = scale.max(1e-30);
        Self {
            max: self.max / s,
            mean: self.mean / s,
            rms: self.rms / s,
        }
    }
}

/// The largest channel of the frame's brightest pixel.
pub fn brightest(frame: &Frame) -> f64 {
    frame
        .colour
        .pixels()
        .iter()
        .map(|c| f64::from(c.max_element()))
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::{Image, Rgb};

    fn frame(pixels: &[Rgb]) -> Frame {
        let mut colour = Image::filled(pixels.len() as u32, 1, Rgb::ZERO);
        for (x, p) in pixels.iter().enumerate() {
            colour.set(x as u32, 0, *p);
        }
        Frame {
            colour,
            depth: Image::filled(pixels.len() as u32, 1, 0.0),
            normals: Image::filled(pixels.len() as u32, 1, glam::Vec3::ZERO),
            stats: Default::default(),
        }
    }

    /// Hand-computed: per-pixel differences (largest channel) 0.5, 0, 0.25, 0.25 — the sign of a
    /// difference and the other channels do not count; max 0.5, mean 0.25, RMS √(0.375/4).
    #[test]
    fn the_error_is_the_largest_channel_per_pixel() {
        let reference = frame(&[
            Rgb::new(1.0, 0.0, 0.0),
            Rgb::new(0.2, 0.2, 0.2),
            Rgb::new(0.0, 2.0, 0.0),
            Rgb::new(0.5, 0.5, 0.5),
        ]);
        let got = frame(&[
            Rgb::new(0.5, 0.1, 0.0),
            Rgb::new(0.2, 0.2, 0.2),
            Rgb::new(0.1, 2.25, 0.0),
            Rgb::new(0.25, 0.5, 0.4),
        ]);
        let e = ImageError::of(&reference, &got).unwrap();
        assert_eq!(e.max, 0.5);
        assert_eq!(e.mean, 0.25);
        assert!((e.rms - (0.375f64 / 4.0).sqrt()).abs() < 1e-15, "{}", e.rms);
        assert_eq!(brightest(&reference), 2.0);
        let r = e.relative(2.0);
        assert_eq!((r.max, r.mean), (0.25, 0.125));
        assert_eq!(ImageError::of(&reference, &reference).unwrap().max, 0.0);
        assert!(ImageError::of(&reference, &frame(&[Rgb::ONE])).is_err());
    }
}
