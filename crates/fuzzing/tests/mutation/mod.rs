//! Deterministic mutations of seed inputs for the bounded run: the byte-level moves a fuzzer
//! makes (bit flips, interesting bytes and words, insertions, deletions, repeats, splices) and
//! one for text formats — a number in the text replaced by an extreme one, the shortest way to a
//! huge declared size or count.

use proptest::prelude::*;
use proptest::sample::select;

/// Numbers a text mutation writes: zero, signs, the edges of 16-, 32- and 64-bit integers,
/// powers of two near fray's limits, and the floats that break arithmetic.
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "0.5",
    "-0",
    "255",
    "1024",
    "16384",
    "32768",
    "65535",
    "65536",
    "100000",
    "1000000",
    "2147483648",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "99999999999999999999",
    "1e308",
    "-1e308",
    "1e-308",
    "1e400",
    "NaN",
    "inf",
    "-inf",
];

/// Bytes a byte mutation writes.
const BYTES: &[u8] = &[
    0x00, 0x01, 0x02, 0x7F, 0x80, 0xFE, 0xFF, b'\n', b'0', b'9', b'-',
];

/// 32-bit words a word mutation writes (either byte order).
const WORDS: &[u32] = &[
    0,
    1,
    2,
    0xFF,
    0x100,
    0x7FFF,
    0x8000,
    0xFFFF,
    0x1_0000,
    0x7FFF_FFFF,
    0x8000_0000,
    0xFFFF_FFFE,
    0xFFFF_FFFF,
];

/// One mutation; positions are taken modulo the input's length.
#[derive(Clone, Debug)]
pub enum Mutation {
    FlipBit {
        at: usize,
        bit: u8,
    },
    SetByte {
        at: usize,
        value: u8,
    },
    Insert {
        at: usize,
        bytes: Vec<u8>,
    },
    Delete {
        at: usize,
        len: usize,
    },
    Truncate {
        at: usize,
    },
    /// The `len` bytes at `at` written `times` more times after themselves.
    Repeat {
        at: usize,
        len: usize,
        times: usize,
    },
    SetWord {
        at: usize,
        value: u32,
        big_endian: bool,
    },
    /// The `nth` number of the text (a run of digits, signs, points and exponents) replaced.
    ReplaceNumber {
        nth: usize,
        text: &'static str,
    },
    /// `len` bytes of seed `seed` (from `from`) inserted at `at`.
    Splice {
        seed: usize,
        from: usize,
        len: usize,
        at: usize,
    },
}

impl Mutation {
    /// Any mutation.
    pub fn strategy() -> impl Strategy<Value = Mutation> {
        let at = any::<usize>();
        prop_oneof![
            (at, 0u8..8).prop_map(|(at, bit)| Mutation::FlipBit { at, bit }),
            (at, select(BYTES)).prop_map(|(at, value)| Mutation::SetByte { at, value }),
            (at, proptest::collection::vec(any::<u8>(), 1..16))
                .prop_map(|(at, bytes)| Mutation::Insert { at, bytes }),
            (at, 1usize..64).prop_map(|(at, len)| Mutation::Delete { at, len }),
            at.prop_map(|at| Mutation::Truncate { at }),
            (at, 1usize..64, 1usize..16).prop_map(|(at, len, times)| Mutation::Repeat {
                at,
                len,
                times
            }),
            (at, select(WORDS), any::<bool>()).prop_map(|(at, value, big_endian)| {
                Mutation::SetWord {
                    at,
                    value,
                    big_endian,
                }
            }),
            (any::<usize>(), select(NUMBERS))
                .prop_map(|(nth, text)| Mutation::ReplaceNumber { nth, text }),
            (any::<usize>(), any::<usize>(), 1usize..256, at).prop_map(|(seed, from, len, at)| {
                Mutation::Splice {
                    seed,
                    from,
                    len,
                    at,
                }
            }),
        ]
    }

    /// Applies the mutation to `data`; `seeds` are the splice sources.
    pub fn apply(&self, data: &mut Vec<u8>, seeds: &[Vec<u8>]) {
        let n = data.len();
        let pick = |at: usize| if n == 0 { 0 } else { at % n };
        match *self {
            Mutation::FlipBit { at, bit } if n > 0 => data[pick(at)] ^= 1 << bit,
            Mutation::SetByte { at, value } if n > 0 => data[pick(at)] = value,
            Mutation::Insert { at, ref bytes } => {
                let at = at % (n + 1);
                data.splice(at..at, bytes.iter().copied());
            }
            Mutation::Delete { at, len } if n > 0 => {
                let at = pick(at);
                data.drain(at..(at + len).min(n));
            }
            Mutation::Truncate { at } => data.truncate(at % (n + 1)),
            Mutation::Repeat { at, len, times } if n > 0 => {
                let at = pick(at);
                let piece = data[at..(at + len).min(n)].to_vec();
                let end = at + piece.len();
                let copies = piece.repeat(times);
                data.splice(end..end, copies);
            }
            Mutation::SetWord {
                at,
                value,
                big_endian,
            } if n >= 4 => {
                let at = at % (n - 3);
                let bytes = if big_endian {
                    value.to_be_bytes()
                } else {
                    value.to_le_bytes()
                };
                data[at..at + 4].copy_from_slice(&bytes);
            }
            Mutation::ReplaceNumber { nth, text } => {
                let numbers = number_runs(data);
                if !numbers.is_empty() {
                    let (start, end) = numbers[nth % numbers.len()];
                    data.splice(start..end, text.bytes());
                }
            }
            Mutation::Splice {
                seed,
                from,
                len,
                at,
            } if !seeds.is_empty() => {
                let source = &seeds[seed % seeds.len()];
                if !source.is_empty() {
                    let from = from % source.len();
                    let piece = &source[from..(from + len).min(source.len())];
                    let at = at % (n + 1);
                    data.splice(at..at, piece.iter().copied());
                }
            }
            // A move that needs bytes the input does not have leaves it as it is.
            _ => {}
        }
    }
}

/// The `(start, end)` of every run of `0-9 . - + e E` that holds a digit.
fn number_runs(data: &[u8]) -> Vec<(usize, usize)> {
    let part = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E');
    let mut runs = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if part(data[i]) {
            let start = i;
            while i < data.len() && part(data[i]) {
                i += 1;
            }
            if data[start..i].iter().any(u8::is_ascii_digit) {
                runs.push((start, i));
            }
        } else {
            i += 1;
        }
    }
    runs
}

#[test]
fn mutations_do_what_they_say() {
    let seeds = vec![b"xyz".to_vec()];
    let run = |m: Mutation, data: &[u8]| {
        let mut d = data.to_vec();
        m.apply(&mut d, &seeds);
        d
    };
    assert_eq!(
        run(
            Mutation::ReplaceNumber {
                nth: 1,
                text: "1e400"
            },
            b"a 12, b -3.5e2, e"
        ),
        b"a 12, b 1e400, e"
    );
    assert_eq!(
        run(
            Mutation::Repeat {
                at: 1,
                len: 2,
                times: 2
            },
            b"abcd"
        ),
        b"abcbcbcd"
    );
    assert_eq!(
        run(
            Mutation::SetWord {
                at: 0,
                value: 0x0102_0304,
                big_endian: true
            },
            b"....."
        ),
        b"\x01\x02\x03\x04."
    );
    assert_eq!(
        run(
            Mutation::Splice {
                seed: 0,
                from: 1,
                len: 9,
                at: 7
            },
            b"ab"
        ),
        b"ayzb"
    );
    assert_eq!(run(Mutation::Delete { at: 5, len: 9 }, b"abc"), b"ab");
    assert_eq!(run(Mutation::FlipBit { at: 0, bit: 0 }, b""), b"");
}
