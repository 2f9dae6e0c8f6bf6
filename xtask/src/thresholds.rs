//! Pass/fail thresholds for `regress`, per scene *and* per comparison (the CPU against the
//! references, the GPU against the references, the GPU against the CPU), read from
//! `data/reference/thresholds.ron`:
//!
//! ```ron
//! { "csg": (gpu: (rmse: 2.0, bad_fraction: 0.002), gpu_vs_cpu: (rmse: 2.0, bad_fraction: 0.002)) }
//! ```
//!
//! Every comparison a scene leaves out, and every scene without an entry, gets the row's
//! default ([`Thresholds::default_for`]): the CPU backend is deterministic, so its rows allow
//! no channel to move by more than 1/255 ([`Thresholds::CPU`]); the other rows get
//! [`Thresholds::default`]. The CPU rows stay that tight unless the file loosens them explicitly.

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
    /// Largest allowed difference of any channel of any pixel (0–255), if limited.
    #[serde(default)]
    pub max_abs: Option<u8>,
}

impl Default for Thresholds {
    fn default() -> Self {
        Self {
            rmse: 1.0,
            bad_fraction: 0.002,
            max_abs: None,
        }
    }
}

impl Thresholds {
    /// The CPU rows' default: the CPU backend is deterministic (the same bytes whatever the
    /// thread count), so against its own references no channel may move by more than 1/255
    /// (a rounding of the last code value) and no pixel may be bad.
    pub const CPU: Self = Self {
        rmse: 1.0,
        bad_fraction: 0.0,
        max_abs: Some(1),
    };

    /// The default of the regress row named `row`: [`Thresholds::CPU`] for `cpu`, else
    /// [`Thresholds::default`].
    pub fn default_for(row: &str) -> Self {
        if row == "cpu" {
            Self::CPU
        } else {
            Self::default()
        }
    }

    /// Whether `metrics` pass: RMSE, bad-pixel fraction and (if limited) the largest channel
    /// difference within their limits.
    pub fn pass(&self, metrics: &Metrics) -> bool {
        metrics.rmse <= self.rmse
            && metrics.bad_fraction <= self.bad_fraction
            && self.max_abs.is_none_or(|m| metrics.max_abs <= m)
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
    /// e.g. a backend compared with itself, gets the defaults): the file's entry, else
    /// [`Thresholds::default_for`] the row.
    pub fn for_row(&self, row: &str) -> Thresholds {
        match row {
            "cpu" => self.cpu,
            "gpu" => self.gpu,
            "gpu vs cpu" => self.gpu_vs_cpu,
            _ => None,
        }
        .unwrap_or_else(|| Thresholds::default_for(row))
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
                bad_fraction: 0.01,
                max_abs: None,
            }
        );
        assert_eq!(clouds.for_row("gpu vs cpu").rmse, 3.0);
        // The CPU row is not loosened by the GPU's entries: at most 1/255 anywhere.
        assert_eq!(clouds.for_row("cpu"), Thresholds::CPU);
        assert_eq!(Thresholds::CPU.max_abs, Some(1));
        assert_eq!(clouds.for_row("cpu vs cpu"), Thresholds::default());
        assert_eq!(t.get("fog").for_row("cpu").bad_fraction, 0.0);
        assert_eq!(t.get("fog").for_row("cpu").max_abs, None);
        let t =
            ThresholdTable::parse(r#"{ "x": (gpu: (rmse: 2.0, bad_fraction: 0.0, max_abs: 9)) }"#)
                .unwrap();
        assert_eq!(t.get("x").for_row("gpu").max_abs, Some(9));
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
        // The CPU rows: one pixel off by 2/255 fails, even with a tiny RMSE.
        let off_by = |max_abs| Metrics {
            rmse: 0.01,
            max_abs,
            bad_fraction: 0.0,
        };
        assert!(Thresholds::CPU.pass(&off_by(1)));
        assert!(!Thresholds::CPU.pass(&off_by(2)));
    }
}
