//! Per-scene pass/fail thresholds for `regress`, read from `data/reference/thresholds.ron`.

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

/// Thresholds by scene stem; scenes without an entry get [`Thresholds::default`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ThresholdTable(BTreeMap<String, Thresholds>);

impl ThresholdTable {
    /// Parses the RON map `{ "stem": (rmse: 1.5, bad_fraction: 0.01), ... }`.
    pub fn parse(text: &str) -> Result<Self, String> {
        ron::from_str(text).map(Self).map_err(|e| e.to_string())
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

    /// The thresholds for scene `stem`.
    pub fn get(&self, stem: &str) -> Thresholds {
        self.0.get(stem).copied().unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_entries_and_defaults_the_rest() {
        let t = ThresholdTable::parse(
            r#"{ "clouds": (rmse: 2.5, bad_fraction: 0.01), "fog": (rmse: 1.5, bad_fraction: 0.0) }"#,
        )
        .unwrap();
        assert_eq!(
            t.get("clouds"),
            Thresholds {
                rmse: 2.5,
                bad_fraction: 0.01
            }
        );
        assert_eq!(t.get("fog").bad_fraction, 0.0);
        assert_eq!(t.get("sphere"), Thresholds::default());
        assert_eq!(Thresholds::default().rmse, 1.0);
        assert_eq!(Thresholds::default().bad_fraction, 0.002);
    }

    #[test]
    fn rejects_malformed_files() {
        assert!(ThresholdTable::parse(r#"{ "x": (rmse: 1.0) }"#).is_err());
        assert!(
            ThresholdTable::parse(r#"{ "x": (rmse: 1.0, bad_fraction: 0.1, max: 3) }"#).is_err()
        );
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
