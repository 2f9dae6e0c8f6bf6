//! Memory budgets: one account per render. Everything whose size grows with the input (scene
//! objects after includes, meshes and their BVHs, textures and their mips, height maps and
//! pyramids, cloud grids, frames, work lists, GPU buffers) is charged to the account before it
//! is allocated, and refused when the render's total would pass the limit, with an error that
//! says what, how much, the total so far and the limit — instead of the allocator aborting the
//! process.
//!
//! A [`MemoryBudget`] is a handle: its clones share one account, so the scene loader, the
//! renderer and the GPU upload of one render all charge the same total. What lives as long as
//! the scene is [`MemoryBudget::charge`]d (it stays charged: make one account per render);
//! what lives for a frame is [`MemoryBudget::reserve`]d (released when the reservation drops);
//! a peak that is gone when the call returns (a file's bytes while they are decoded) is
//! [`MemoryBudget::check`]ed against what is left.
//!
//! The default limit is [`MemoryBudget::DEFAULT_BYTES`] (4 GiB), or the `FRAY_MEMORY_BUDGET`
//! environment variable (bytes, with an optional `K`/`M`/`G`/`T` binary suffix, e.g. `12G`).

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// A render's memory account: a limit in bytes and what has been charged to it. Clones share
/// the account.
#[derive(Clone)]
pub struct MemoryBudget {
    limit: u64,
    account: Arc<Account>,
}

/// The shared part of a [`MemoryBudget`]: the running total and the ledger of permanent charges.
#[derive(Default)]
struct Account {
    /// Bytes charged or reserved now.
    total: AtomicU64,
    /// The permanent charges, summed by what they were for, in the order first charged.
    ledger: Mutex<Vec<(String, u64)>>,
}

/// An allocation that would take a render past its budget (or whose size overflows `u64`).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{}", describe(self))]
pub struct BudgetError {
    /// What was to be allocated, e.g. `"the terrain's max pyramid"`.
    pub what: String,
    /// Its size in bytes (`u64::MAX` where the size itself overflows).
    pub needed: u64,
    /// What the render had already charged to its account when this was refused.
    pub charged: u64,
    /// The budget in bytes.
    pub limit: u64,
}

fn describe(e: &BudgetError) -> String {
    let so_far = if e.charged == 0 {
        String::new()
    } else {
        format!(
            "; the render had already charged {} ({} bytes) to it",
            human(e.charged),
            e.charged
        )
    };
    format!(
        "{} would need {} ({} bytes), over the memory budget of {} ({} bytes){so_far}; \
         raise it with FRAY_MEMORY_BUDGET or --memory-budget",
        e.what,
        human(e.needed),
        e.needed,
        human(e.limit),
        e.limit
    )
}

/// Why a budget could not be read from text.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "a memory budget is a positive number of bytes with an optional K, M, G or T suffix (binary), e.g. 4G; got {0:?}"
)]
pub struct BudgetParseError(pub String);

/// Bytes reserved on an account for as long as this value lives (a frame, a work list).
#[must_use = "a reservation is released when it is dropped"]
pub struct Reservation {
    bytes: u64,
    account: Arc<Account>,
}

impl Reservation {
    /// The bytes held.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }
}

impl Drop for Reservation {
    fn drop(&mut self) {
        self.account.total.fetch_sub(self.bytes, Ordering::Relaxed);
    }
}

impl fmt::Debug for Reservation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Reservation")
            .field("bytes", &self.bytes)
            .finish()
    }
}

impl MemoryBudget {
    /// The default budget: 4 GiB.
    pub const DEFAULT_BYTES: u64 = 4 << 30;

    /// A new, empty account of `bytes`.
    pub fn new(bytes: u64) -> Self {
        Self {
            limit: bytes,
            account: Arc::default(),
        }
    }

    /// A new account with no limit (for callers that check elsewhere).
    pub fn unlimited() -> Self {
        Self::new(u64::MAX)
    }

    /// The limit in bytes.
    pub fn bytes(&self) -> u64 {
        self.limit
    }

    /// Whether `other` charges the same account (a clone of this budget, or this one).
    pub fn same_account(&self, other: &MemoryBudget) -> bool {
        Arc::ptr_eq(&self.account, &other.account)
    }

    /// What is charged or reserved on the account now.
    pub fn charged(&self) -> u64 {
        self.account.total.load(Ordering::Relaxed)
    }

    /// What is left before the limit.
    pub fn remaining(&self) -> u64 {
        self.limit.saturating_sub(self.charged())
    }

    /// The permanent charges so far, summed by what they were for, in the order first charged.
    pub fn ledger(&self) -> Vec<(String, u64)> {
        self.account
            .ledger
            .lock()
            .map(|l| l.clone())
            .unwrap_or_default()
    }

    /// `FRAY_MEMORY_BUDGET` if it is set and valid, else [`MemoryBudget::DEFAULT_BYTES`]. An
    /// invalid value is an error, so a typo does not silently mean the default.
    pub fn from_env() -> Result<Self, BudgetParseError> {
        match std::env::var("FRAY_MEMORY_BUDGET") {
            Ok(text) => text.parse(),
            Err(_) => Ok(Self::new(Self::DEFAULT_BYTES)),
        }
    }

    /// `Ok` if `bytes` fit in what is left on the account, else a [`BudgetError`] naming
    /// `what`. Charges nothing: for a peak that is gone when the caller returns.
    pub fn check(&self, what: impl Into<String>, bytes: u64) -> Result<(), BudgetError> {
        let charged = self.charged();
        if charged.checked_add(bytes).is_some_and(|t| t <= self.limit) {
            Ok(())
        } else {
            Err(self.refuse(what, bytes, charged))
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

    /// Charges `bytes` for `what` to the account for good (what lives as long as the scene), or
    /// refuses them if the total would pass the limit, charging nothing.
    pub fn charge(&self, what: impl Into<String>, bytes: u64) -> Result<(), BudgetError> {
        let what = what.into();
        self.add(&what, bytes)?;
        if let Ok(mut ledger) = self.account.ledger.lock() {
            match ledger.iter_mut().find(|(w, _)| *w == what) {
                Some((_, b)) => *b = b.saturating_add(bytes),
                None => ledger.push((what, bytes)),
            }
        }
        Ok(())
    }

    /// [`MemoryBudget::charge`] for `count` elements of `element_bytes` each.
    pub fn charge_elements(
        &self,
        what: impl Into<String>,
        count: u64,
        element_bytes: u64,
    ) -> Result<(), BudgetError> {
        self.charge(what, count.saturating_mul(element_bytes))
    }

    /// Reserves `bytes` for `what` until the returned [`Reservation`] drops (what lives for a
    /// frame), or refuses them if the total would pass the limit.
    pub fn reserve(&self, what: impl Into<String>, bytes: u64) -> Result<Reservation, BudgetError> {
        let what = what.into();
        self.add(&what, bytes)?;
        Ok(Reservation {
            bytes,
            account: Arc::clone(&self.account),
        })
    }

    /// [`MemoryBudget::reserve`] for `count` elements of `element_bytes` each.
    pub fn reserve_elements(
        &self,
        what: impl Into<String>,
        count: u64,
        element_bytes: u64,
    ) -> Result<Reservation, BudgetError> {
        self.reserve(what, count.saturating_mul(element_bytes))
    }

    /// Adds `bytes` to the total if it stays within the limit (atomically: threads charging at
    /// once cannot pass it together).
    fn add(&self, what: &str, bytes: u64) -> Result<(), BudgetError> {
        let total = &self.account.total;
        let mut charged = total.load(Ordering::Relaxed);
        loop {
            let after = match charged.checked_add(bytes) {
                Some(after) if after <= self.limit => after,
                _ => return Err(self.refuse(what, bytes, charged)),
            };
            match total.compare_exchange_weak(charged, after, Ordering::Relaxed, Ordering::Relaxed)
            {
                Ok(_) => return Ok(()),
                Err(now) => charged = now,
            }
        }
    }

    fn refuse(&self, what: impl Into<String>, bytes: u64, charged: u64) -> BudgetError {
        BudgetError {
            what: what.into(),
            needed: bytes,
            charged,
            limit: self.limit,
        }
    }
}

impl Default for MemoryBudget {
    /// [`MemoryBudget::from_env`], falling back to the default on an invalid variable.
    fn default() -> Self {
        Self::from_env().unwrap_or(Self::new(Self::DEFAULT_BYTES))
    }
}

impl fmt::Debug for MemoryBudget {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("MemoryBudget")
            .field("limit", &self.limit)
            .field("charged", &self.charged())
            .finish()
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
        f.write_str(&human(self.limit))
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

    #[test]
    fn charges_add_up_to_one_total_and_reservations_are_released() {
        let b = MemoryBudget::new(1000);
        let shared = b.clone();
        b.charge("a height map", 400).unwrap();
        shared.charge("a texture", 300).unwrap();
        shared.charge("a texture", 100).unwrap();
        assert_eq!(b.charged(), 800);
        assert_eq!(
            b.ledger(),
            vec![
                ("a height map".to_owned(), 400),
                ("a texture".to_owned(), 400)
            ]
        );
        // Each of these fits the limit alone; together they do not.
        let e = b.charge("a cloud grid", 300).unwrap_err();
        assert_eq!((e.needed, e.charged, e.limit), (300, 800, 1000));
        let text = e.to_string();
        assert!(
            text.contains("a cloud grid") && text.contains("800 bytes"),
            "{text}"
        );
        assert_eq!(b.charged(), 800, "a refused charge charges nothing");
        assert!(b.check("a peak", 200).is_ok() && b.check("a peak", 201).is_err());
        {
            let frame = b.reserve("a frame", 150).unwrap();
            assert_eq!(frame.bytes(), 150);
            assert_eq!(b.charged(), 950);
            assert!(b.reserve("a work list", 51).is_err());
        }
        assert_eq!(b.charged(), 800, "a dropped reservation is released");
        assert!(b.charge_elements("overflow", u64::MAX, 2).is_err());
        assert_eq!(b.remaining(), 200);
    }

    #[test]
    fn threads_charging_at_once_never_pass_the_limit() {
        let b = MemoryBudget::new(10_000);
        let accepted: u64 = std::thread::scope(|s| {
            let handles: Vec<_> = (0..8)
                .map(|_| {
                    let b = b.clone();
                    s.spawn(move || (0..1000).filter(|_| b.charge("x", 7).is_ok()).count() as u64)
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).sum()
        });
        assert_eq!(accepted, 10_000 / 7);
        assert_eq!(b.charged(), accepted * 7);
    }
}
