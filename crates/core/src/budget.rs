//! Memory budgets: every allocation whose size grows with the input (height maps, pyramids,
//! frames, work lists, GPU buffers) is estimated before it is made and refused over a budget,
//! with an error that says what, how much and the limit — instead of the allocator aborting the
//! process.
//!
//! The default budget is [`MemoryBudget::DEFAULT_BYTES`] (4 GiB), or the `FRAY_MEMORY_BUDGET`
//! environment variable (bytes, with an optional `K`/`M`/`G`/`T` binary suffix, e.g. `12G`).
//! Libraries take a budget where they allocate ([`MemoryBudget::check`]); `Default` reads the
//! environment.

use std::fmt;

/// A limit in bytes on one allocation (or one group of allocations made together).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct MemoryBudget {
    bytes: u64,
}

/// An allocation that would exceed its budget (or whose size overflows `u64`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} would need {} ({needed} bytes), over the memory budget of {} ({limit} bytes); \
     raise it with FRAY_MEMORY_BUDGET or --memory-budget",
    human(*.needed),
    human(*.limit)
)]
pub struct BudgetError {
    /// What was to be allocated, e.g. `"the terrain's max pyramid"`.
    pub what: String,
    /// Its size in bytes (`u64::MAX` where the size itself overflows).
    pub needed: u64,
    /// The budget in bytes.
    pub limit: u64,
}

/// Why a budget could not be read from text.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "a memory budget is a positive number of bytes with an optional K, M, G or T suffix (binary), e.g. 4G; got {0:?}"
)]
pub struct BudgetParseError(pub String);

impl MemoryBudget {
    /// The default budget: 4 GiB.
    pub const DEFAULT_BYTES: u64 = 4 << 30;
    /// No limit (for callers that check elsewhere).
    pub const UNLIMITED: Self = Self { bytes: u64::MAX };

    /// A budget of `bytes`.
    pub const fn new(bytes: u64) -> Self {
        Self { bytes }
    }

    /// The budget in bytes.
    pub const fn bytes(&self) -> u64 {
        self.bytes
    }

    /// `FRAY_MEMORY_BUDGET` if it is set and valid, else [`MemoryBudget::DEFAULT_BYTES`]. An
    /// invalid value is an error, so a typo does not silently mean the default.
    pub fn from_env() -> Result<Self, BudgetParseError> {
        match std::env::var("FRAY_MEMORY_BUDGET") {
            Ok(text) => text.parse(),
            Err(_) => Ok(Self::new(Self::DEFAULT_BYTES)),
        }
    }

    /// `Ok` if `bytes` fits the budget, else a [`BudgetError`] naming `what`.
    pub fn check(&self, what: impl Into<String>, bytes: u64) -> Result<(), BudgetError> {
        if bytes <= self.bytes {
            Ok(())
        } else {
            Err(BudgetError {
                what: what.into(),
                needed: bytes,
                limit: self.bytes,
            })
        }
    }

    /// [`MemoryBudget::check`] for `count` elements of `element_bytes` each (overflow is over
    /// any budget).
    pub fn check_elements(
        &self,
        what: impl Into<String>,
        count: u64,
        element_bytes: u64,
    ) -> Result<(), BudgetError> {
        self.check(what, count.saturating_mul(element_bytes))
    }
}

impl Default for MemoryBudget {
    /// [`MemoryBudget::from_env`], falling back to the default on an invalid variable.
    fn default() -> Self {
        Self::from_env().unwrap_or(Self::new(Self::DEFAULT_BYTES))
    }
}

impl std::str::FromStr for MemoryBudget {
    type Err = BudgetParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let text = s.trim();
        let bad = || BudgetParseError(s.to_owned());
        let (digits, shift) = match text.char_indices().last() {
            Some((i, c)) if c.is_ascii_alphabetic() => {
                let shift = match c.to_ascii_uppercase() {
                    'K' => 10,
                    'M' => 20,
                    'G' => 30,
                    'T' => 40,
                    _ => return Err(bad()),
                };
                (&text[..i], shift)
            }
            _ => (text, 0),
        };
        let value: u64 = digits.trim().parse().map_err(|_| bad())?;
        if value == 0 {
            return Err(bad());
        }
        value
            .checked_mul(1u64 << shift)
            .map(Self::new)
            .ok_or_else(bad)
    }
}

impl fmt::Display for MemoryBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&human(self.bytes))
    }
}

/// `bytes` in binary units with three significant figures, e.g. `"5.66 GiB"`.
pub fn human(bytes: u64) -> String {
    if bytes == u64::MAX {
        return "more than 16 EiB".to_owned();
    }
    const UNITS: [&str; 7] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut value = bytes as f64;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{bytes} bytes")
    } else if value >= 100.0 {
        format!("{value:.0} {}", UNITS[unit])
    } else if value >= 10.0 {
        format!("{value:.1} {}", UNITS[unit])
    } else {
        format!("{value:.2} {}", UNITS[unit])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_suffixes_and_refuses_nonsense() {
        assert_eq!("4G".parse::<MemoryBudget>().unwrap().bytes(), 4 << 30);
        assert_eq!("512m".parse::<MemoryBudget>().unwrap().bytes(), 512 << 20);
        assert_eq!(" 1000 ".parse::<MemoryBudget>().unwrap().bytes(), 1000);
        for bad in ["", "0", "-1", "4X", "G", "1.5G", "99999999999T"] {
            assert!(bad.parse::<MemoryBudget>().is_err(), "{bad:?}");
        }
    }

    #[test]
    fn check_names_what_how_much_and_the_limit() {
        let b = MemoryBudget::new(1 << 30);
        assert!(b.check("x", 1 << 30).is_ok());
        let e = b
            .check("the terrain's max pyramid", 6_079_206_656)
            .unwrap_err();
        let text = e.to_string();
        assert!(text.contains("the terrain's max pyramid"), "{text}");
        assert!(
            text.contains("5.66 GiB") && text.contains("1.00 GiB"),
            "{text}"
        );
        let overflow = b.check_elements("a frame", u64::MAX / 2, 32).unwrap_err();
        assert_eq!(overflow.needed, u64::MAX);
        assert!(overflow.to_string().contains("more than 16 EiB"));
    }
}
