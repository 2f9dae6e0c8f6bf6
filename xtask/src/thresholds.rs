//! Pass/fail thresholds for `regress`, per scene *and* per comparison (the CPU against the
//! references, the GPU against the references, the GPU against the CPU), read from
//! `data/reference/thresholds.ron`:
//!
//! ```ron
//! { "csg": (gpu: (rmse: 2.0, bad_fraction: 0.002), gpu_vs_cpu: (rmse: 2.0, bad_fraction: 0.002)) }
//! ```
//!
//! Every comparison a scene leaves out, and every scene without an entry, gets
//! [`Thresholds::default`]; so the CPU rows stay tight unless the file loosens them explicitly.

use crate::compare::Metrics;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

/// The file, inside the reference directory, that holds the thresholds.
pub const FILE_NAME: &str = "thresholds.ron";

/// The limits an image's [`Metrics`] must stay within to pass.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Thresholds {
    /// Largest allowed RMSE (0–255 scale).
    pub rmse: f64,
    /// Largest allowed fraction of bad pixels.
    pub bad_fraction: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self {
            rmse: 1.0,
            bad_fraction: 0.002,
        }
    }
}

impl Thresholds {
    /// Whether `metrics` pass: both RMSE and bad-pixel fraction within their limits.
    pub fn pass(&self, metrics: &Metrics) -> bool {
        metrics.rmse <= self.rmse && metrics.bad_fraction <= self.bad_fraction
    }
}

/// One scene's thresholds per comparison (regress row); `None` is the default.
#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneThresholds {
    /// The CPU backend against the reference images (row `cpu`).
    #[serde(default)]
    pub cpu: Option<Thresholds>,
    /// The GPU backend against the reference images (row `gpu`).
    #[serde(default)]
    pub gpu: Option<Thresholds>,
    /// The GPU backend against the CPU backend (row `gpu vs cpu`).
    #[serde(default)]
    pub gpu_vs_cpu: Option<Thresholds>,
}

impl SceneThresholds {
    /// The thresholds of the regress row named `row` (`cpu`, `gpu`, `gpu vs cpu`; any other row,
    /// e.g. a backend compared with itself, gets the defaults).
    pub fn for_row(&self, row: &str) -> Thresholds {
        match row {
            "cpu" => self.cpu,
            "gpu" => self.gpu,
            "gpu vs cpu" => self.gpu_vs_cpu,
            _ => None,
        }
        .unwrap_or_default()
    }
}

/// Thresholds by scene stem; scenes without an entry get [`Thresholds::default`] everywhere.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThresholdTable(BTreeMap<String, SceneThresholds>);

impl ThresholdTable {
    /// Parses the RON map `{ "stem": (gpu: (rmse: 1.5, bad_fraction: 0.01)), ... }` (see the
    /// module docs); limits must be finite and non-negative.
    pub fn parse(text: &str) -> Result<Self, String> {
        // `gpu: (rmse: …)` rather than `gpu: Some((rmse: …))`.
        let table: BTreeMap<String, SceneThresholds> = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .from_str(text)
            .map_err(|e| e.to_string())?;
        for (stem, scene) in &table {
            for (row, t) in [
                ("cpu", scene.cpu),
                ("gpu", scene.gpu),
                ("gpu_vs_cpu", scene.gpu_vs_cpu),
            ] {
                if let Some(t) = t {
                    for (field, v) in [("rmse", t.rmse), ("bad_fraction", t.bad_fraction)] {
                        if !(v.is_finite() && v >= 0.0) {
                            return Err(format!(
                                "\"{stem}\".{row}.{field}: must be finite and >= 0, got {v}"
                            ));
                        }
                    }
                }
            }
        }
        Ok(Self(table))
    }

    /// Reads `<dir>/thresholds.ron`; a missing file means defaults for every scene.
    pub fn load(dir: &Path) -> Result<Self, String> {
        let path = dir.join(FILE_NAME);
        match std::fs::read_to_string(&path) {
            Ok(text) => Self::parse(&text).map_err(|e| format!("{}: {e}", path.display())),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Self::default()),
            Err(e) => Err(format!("cannot read {}: {e}", path.display())),
        }
    }

    /// The thresholds of scene `stem`, per comparison.
    pub fn get(&self, stem: &str) -> SceneThresholds {
        self.0.get(stem).copied().unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_entries_per_backend_and_defaults_the_rest() {
        let t = ThresholdTable::parse(
            r#"{ "clouds": (gpu: (rmse: 2.5, bad_fraction: 0.01), gpu_vs_cpu: (rmse: 3.0, bad_fraction: 0.02)),
                 "fog": (cpu: (rmse: 0.5, bad_fraction: 0.0)), "empty": () }"#,
        )
        .unwrap();
        let clouds = t.get("clouds");
        assert_eq!(
            clouds.for_row("gpu"),
            Thresholds {
                rmse: 2.5,
                bad_fraction: 0.01
            }
        );
        assert_eq!(clouds.for_row("gpu vs cpu").rmse, 3.0);
        // The CPU row is not loosened by the GPU's entries.
        assert_eq!(clouds.for_row("cpu"), Thresholds::default());
        assert_eq!(clouds.for_row("cpu vs cpu"), Thresholds::default());
        assert_eq!(t.get("fog").for_row("cpu").bad_fraction, 0.0);
        assert_eq!(t.get("fog").for_row("gpu"), Thresholds::default());
        assert_eq!(t.get("empty"), SceneThresholds::default());
        assert_eq!(t.get("sphere").for_row("gpu"), Thresholds::default());
        assert_eq!(Thresholds::default().rmse, 1.0);
        assert_eq!(Thresholds::default().bad_fraction, 0.002);
    }

    #[test]
    fn rejects_malformed_files_with_clear_errors() {
        assert!(ThresholdTable::parse(r#"{ "x": (gpu: (rmse: 1.0)) }"#).is_err());
        assert!(
            ThresholdTable::parse(r#"{ "x": (gpu: (rmse: 1.0, bad_fraction: 0.1, max: 3)) }"#)
                .is_err()
        );
        // The old per-scene form and unknown backends are refused, naming the field.
        let e = ThresholdTable::parse(r#"{ "x": (rmse: 1.0, bad_fraction: 0.1) }"#).unwrap_err();
        assert!(e.contains("rmse"), "{e}");
        let e = ThresholdTable::parse(r#"{ "x": (gpus: (rmse: 1.0, bad_fraction: 0.1)) }"#)
            .unwrap_err();
        assert!(e.contains("gpus") && e.contains("gpu_vs_cpu"), "{e}");
        let e = ThresholdTable::parse(r#"{ "x": (gpu: (rmse: -1.0, bad_fraction: 0.1)) }"#)
            .unwrap_err();
        assert_eq!(e, "\"x\".gpu.rmse: must be finite and >= 0, got -1");
        assert!(ThresholdTable::parse("nonsense").is_err());
    }

    #[test]
    fn pass_needs_both_limits() {
        let t = Thresholds::default();
        let m = |rmse, bad_fraction| Metrics {
            rmse,
            max_abs: 0,
            bad_fraction,
        };
        assert!(t.pass(&m(1.0, 0.002)));
        assert!(!t.pass(&m(1.01, 0.0)));
        assert!(!t.pass(&m(0.0, 0.003)));
        assert!(!t.pass(&m(f64::NAN, 0.0)));
    }
}
