//! A minimal reader for NumPy `.npy` arrays — the subset fray needs, with no dependency — and
//! [`encode`], the writer of that subset (for tools and tests that make height maps).
//!
//! Format (NumPy's `format.py`, versions 1.0–3.0): the magic `\x93NUMPY`, a major and a minor
//! version byte, the header length (`u16` little-endian in 1.0, `u32` in 2.0 and 3.0), then an
//! ASCII (3.0: UTF-8) Python dict literal such as
//! `{'descr': '<i2', 'fortran_order': False, 'shape': (344, 403), }`, padded with spaces and a
//! newline; the raw data follows. Accepted: a 2-D `shape` `(rows, columns)`, C order
//! (`fortran_order: False`) and the little-endian types `<i2`, `<u2`, `<f4`, `<f8` (`|i1`/`|u1`
//! and big-endian or other types are refused with a reason). Rows become height-map rows `v`.

/// A decoded `.npy` array: `rows × columns` values, row-major, as `f32`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct NpyArray {
    pub(crate) rows: usize,
    pub(crate) columns: usize,
    pub(crate) values: Vec<f32>,
}

/// The element types read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Descr {
    I2,
    U2,
    F4,
    F8,
}

impl Descr {
    fn size(self) -> usize {
        match self {
            Descr::I2 | Descr::U2 => 2,
            Descr::F4 => 4,
            Descr::F8 => 8,
        }
    }
}

/// A parsed `.npy` header: the shape, the element type and where the data start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct NpyHeader {
    pub(crate) rows: usize,
    pub(crate) columns: usize,
    descr: Descr,
    data_start: usize,
}

/// Parses a whole `.npy` file. `check` vets the shape before any allocation for the data.
#[cfg(test)]
pub(crate) fn parse(
    bytes: &[u8],
    check: impl Fn(usize, usize) -> Result<(), String>,
) -> Result<NpyArray, String> {
    let header = parse_header(bytes)?;
    check(header.columns, header.rows)?;
    decode(bytes, &header)
}

/// Parses the header of a `.npy` file (no allocation for the data).
pub(crate) fn parse_header(bytes: &[u8]) -> Result<NpyHeader, String> {
    const MAGIC: &[u8] = b"\x93NUMPY";
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err("not a .npy file (missing the \\x93NUMPY magic)".into());
    }
    let major = bytes[6];
    let (header_len, start): (usize, usize) = match major {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 => {
            if bytes.len() < 12 {
                return Err("truncated .npy header".into());
            }
            let n = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
            (n as usize, 12)
        }
        v => return Err(format!("unsupported .npy version {v}.{}", bytes[7])),
    };
    let header = bytes
        .get(start..start.saturating_add(header_len))
        .ok_or("truncated .npy header")?;
    let header = std::str::from_utf8(header).map_err(|_| "the .npy header is not text")?;
    let descr = match dict_value(header, "descr")? {
        "'<i2'" => Descr::I2,
        "'<u2'" => Descr::U2,
        "'<f4'" => Descr::F4,
        "'<f8'" => Descr::F8,
        other => {
            return Err(format!(
                "unsupported .npy dtype {other} (expected '<i2', '<u2', '<f4' or '<f8')"
            ));
        }
    };
    match dict_value(header, "fortran_order")? {
        "False" => {}
        "True" => {
            return Err("Fortran-order .npy arrays are not supported (save in C order)".into());
        }
        other => return Err(format!("bad fortran_order value {other}")),
    }
    let shape = dict_value(header, "shape")?;
    let dims: Vec<usize> = shape
        .trim_start_matches('(')
        .trim_end_matches(')')
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("bad .npy shape {shape}"))?;
    let [rows, columns] = dims[..] else {
        return Err(format!(
            "the .npy array has shape {shape}: a 2-D array (rows, columns) is needed"
        ));
    };
    Ok(NpyHeader {
        rows,
        columns,
        descr,
        data_start: start + header_len,
    })
}

/// Decodes the data of a `.npy` file whose header is `header` (its shape already vetted: this
/// allocates `rows × columns` `f32`s).
pub(crate) fn decode(bytes: &[u8], header: &NpyHeader) -> Result<NpyArray, String> {
    let NpyHeader {
        rows,
        columns,
        descr,
        data_start,
    } = *header;
    let data = &bytes[data_start.min(bytes.len())..];
    let count = rows.saturating_mul(columns);
    let need = count.saturating_mul(descr.size());
    if data.len() < need {
        return Err(format!(
            "truncated .npy data: {} bytes for {rows} × {columns} values of {} bytes",
            data.len(),
            descr.size()
        ));
    }
    let data = &data[..need];
    let values = match descr {
        Descr::I2 => data
            .chunks_exact(2)
            .map(|c| f32::from(i16::from_le_bytes([c[0], c[1]])))
            .collect(),
        Descr::U2 => data
            .chunks_exact(2)
            .map(|c| f32::from(u16::from_le_bytes([c[0], c[1]])))
            .collect(),
        Descr::F4 => data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        Descr::F8 => data
            .chunks_exact(8)
            .map(|c| {
                let b: [u8; 8] = [c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]];
                f64::from_le_bytes(b) as f32
            })
            .collect(),
    };
    Ok(NpyArray {
        rows,
        columns,
        values,
    })
}

/// The literal text of `key`'s value in a flat Python dict literal (a quoted string, a word, or
/// a parenthesised tuple).
fn dict_value<'a>(header: &'a str, key: &str) -> Result<&'a str, String> {
    let pattern = format!("'{key}'");
    let at = header
        .find(&pattern)
        .ok_or_else(|| format!("the .npy header has no '{key}'"))?;
    let rest = header[at + pattern.len()..].trim_start();
    let rest = rest
        .strip_prefix(':')
        .ok_or_else(|| format!("bad .npy header near '{key}'"))?
        .trim_start();
    let end = if rest.starts_with('(') {
        rest.find(')').map(|k| k + 1)
    } else if let Some(body) = rest.strip_prefix('\'') {
        body.find('\'').map(|k| k + 2)
    } else {
        rest.find([',', '}'])
    };
    let end = end.ok_or_else(|| format!("bad .npy header near '{key}'"))?;
    Ok(rest[..end].trim())
}

/// The bytes of a 2-D `.npy` file (format 1.0, C order): a header naming the dtype `descr`
/// (e.g. `"<f4"`) and the shape `(rows, columns)`, then `data` as given (row-major samples in
/// that dtype — not checked against the shape, so that broken files can be written too). What
/// [`crate::Heightmap::load`] reads from a `.npy` path.
pub fn encode(descr: &str, rows: usize, columns: usize, data: &[u8]) -> Vec<u8> {
    let mut header =
        format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': ({rows}, {columns}), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(data);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `bytes` with the first `from` replaced by `to` (same length, so the header stays valid).
    fn replace(bytes: &[u8], from: &[u8], to: &[u8]) -> Vec<u8> {
        let k = bytes.windows(from.len()).position(|w| w == from).unwrap();
        let mut out = bytes.to_vec();
        out[k..k + to.len()].copy_from_slice(to);
        out
    }

    fn ok(_: usize, _: usize) -> Result<(), String> {
        Ok(())
    }

    #[test]
    fn reads_every_accepted_dtype() {
        let i2: Vec<u8> = [-3i16, 7, 1000, 0]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let a = parse(&encode("<i2", 2, 2, &i2), ok).unwrap();
        assert_eq!((a.rows, a.columns), (2, 2));
        assert_eq!(a.values, [-3.0, 7.0, 1000.0, 0.0]);
        let u2: Vec<u8> = [65535u16, 1].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(
            parse(&encode("<u2", 1, 2, &u2), ok).unwrap().values,
            [65535.0, 1.0]
        );
        let f4: Vec<u8> = [1.5f32, -2.25]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        assert_eq!(
            parse(&encode("<f4", 2, 1, &f4), ok).unwrap().values,
            [1.5, -2.25]
        );
        let f8: Vec<u8> = [0.1f64, 3.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(
            parse(&encode("<f8", 1, 2, &f8), ok).unwrap().values,
            [0.1f32, 3.0]
        );
    }

    #[test]
    fn refuses_what_it_does_not_read() {
        let e = parse(b"hello world", ok).unwrap_err();
        assert!(e.contains("magic"), "{e}");
        let e = parse(&encode(">i2", 1, 1, &[0, 0]), ok).unwrap_err();
        assert!(e.contains("unsupported .npy dtype '>i2'"), "{e}");
        let e = parse(&encode("<f4", 2, 2, &[0; 12]), ok).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let three_d = replace(&encode("<f4", 1, 22, &[0; 88]), b"(1, 22)", b"(1,2,3)");
        let e = parse(&three_d, ok).unwrap_err();
        assert!(e.contains("2-D"), "{e}");
        let fortran = replace(&encode("<f4", 1, 1, &[0; 4]), b"False", b"True ");
        assert!(parse(&fortran, ok).unwrap_err().contains("Fortran"));
        let e = parse(&encode("<f4", 1, 1, &[0; 4]), |_, _| Err("too big".into())).unwrap_err();
        assert_eq!(e, "too big");
    }
}
