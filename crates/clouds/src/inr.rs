//! INRIMAGE-4 volumes (the CT scan in `data/volumes/`): a text header `#INRIMAGE-4#{ … ##}` of
//! `KEY=value` lines padded to a multiple of 256 bytes, then the voxels, x fastest. Read here:
//! one channel (`VDIM=1`) of 32-bit floats (`TYPE=float`, `PIXSIZE=32 bits`) in either byte
//! order (`CPU=decm`/`pc`/`alpha` little-endian, `sun`/`sgi` big-endian).

use crate::{CloudsError, DensityGrid};
use fray_core::MemoryBudget;
use std::path::Path;

/// A loaded volume: its grid and its voxel size (world units per voxel along x, y, z).
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    pub grid: DensityGrid,
    pub voxel_size: [f64; 3],
}

/// Reads the INRIMAGE-4 file at `path`; every failure names the path and the reason, and the
/// voxels are checked against `budget` before they are read.
pub fn load(path: &Path, budget: &MemoryBudget) -> Result<Volume, CloudsError> {
    let fail = |reason: String| CloudsError::Volume {
        path: path.to_owned(),
        reason,
    };
    let bytes = fray_core::input::read_file(path, budget).map_err(|e| match e {
        fray_core::input::InputError::Budget(b) => CloudsError::Budget(b),
        other => fail(format!("cannot read the file: {other}")),
    })?;
    parse(&bytes, budget).map_err(|e| match e {
        Parse::Reason(r) => fail(r),
        // The budget's error names the volume by its size; the user needs the file too.
        Parse::Clouds(CloudsError::Budget(mut b)) => {
            b.what = format!("{} ({})", b.what, path.display());
            CloudsError::Budget(b)
        }
        Parse::Clouds(c) => c,
    })
}

enum Parse {
    Reason(String),
    Clouds(CloudsError),
}

fn parse(bytes: &[u8], budget: &MemoryBudget) -> Result<Volume, Parse> {
    let reason = |r: &str| Parse::Reason(r.to_owned());
    const MAGIC: &[u8] = b"#INRIMAGE-4#{";
    if !bytes.starts_with(MAGIC) {
        return Err(reason(
            "not an INRIMAGE-4 file (no `#INRIMAGE-4#{` at its start)",
        ));
    }
    let end = bytes
        .windows(3)
        .position(|w| w == b"##}")
        .ok_or_else(|| reason("the header never ends (no `##}`)"))?;
    // The header is padded to a multiple of 256 bytes (the end marker's line included).
    let header_len = (end + 4).div_ceil(256) * 256;
    let text = std::str::from_utf8(&bytes[MAGIC.len()..end])
        .map_err(|_| reason("the header is not text"))?;
    let mut size = [0usize; 3];
    let mut voxel = [1.0f64; 3];
    let (mut vdim, mut kind, mut bits, mut big_endian) = (1usize, None, None, false);
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        let Some((key, value)) = line.split_once('=') else {
            continue;
        };
        let number = |v: &str| -> Result<usize, Parse> {
            v.trim()
                .parse()
                .map_err(|_| Parse::Reason(format!("{key}: not a whole number: {v:?}")))
        };
        let real = |v: &str| -> Result<f64, Parse> {
            v.trim()
                .parse()
                .map_err(|_| Parse::Reason(format!("{key}: not a number: {v:?}")))
        };
        match key.trim() {
            "XDIM" => size[0] = number(value)?,
            "YDIM" => size[1] = number(value)?,
            "ZDIM" => size[2] = number(value)?,
            "VDIM" => vdim = number(value)?,
            "TYPE" => kind = Some(value.trim().to_owned()),
            "PIXSIZE" => bits = Some(value.trim().to_owned()),
            "VX" => voxel[0] = real(value)?,
            "VY" => voxel[1] = real(value)?,
            "VZ" => voxel[2] = real(value)?,
            "CPU" => {
                big_endian = match value.trim() {
                    "decm" | "pc" | "alpha" => false,
                    "sun" | "sgi" => true,
                    other => {
                        return Err(Parse::Reason(format!("CPU: unknown byte order {other:?}")));
                    }
                }
            }
            _ => {}
        }
    }
    if size.contains(&0) {
        return Err(reason("XDIM, YDIM and ZDIM must all be given and ≥ 1"));
    }
    if vdim != 1 {
        return Err(Parse::Reason(format!(
            "VDIM={vdim}: only one channel is read"
        )));
    }
    if kind.as_deref() != Some("float") || bits.as_deref() != Some("32 bits") {
        return Err(Parse::Reason(format!(
            "only TYPE=float with PIXSIZE=32 bits is read, got TYPE={} PIXSIZE={}",
            kind.as_deref().unwrap_or("(none)"),
            bits.as_deref().unwrap_or("(none)")
        )));
    }
    if !voxel.iter().all(|v| v.is_finite() && *v > 0.0) {
        return Err(reason("VX, VY and VZ must be finite and > 0"));
    }
    let count = size.iter().try_fold(1u64, |n, &s| n.checked_mul(s as u64));
    let Some(count) = count else {
        return Err(reason("XDIM × YDIM × ZDIM overflows"));
    };
    // The file's bytes and the voxels are alive together while they are converted.
    budget
        .check(
            format!(
                "reading the {} × {} × {} volume (the file and its f32 voxels together)",
                size[0], size[1], size[2]
            ),
            count.saturating_mul(4).saturating_add(bytes.len() as u64),
        )
        .map_err(|e| Parse::Clouds(e.into()))?;
    budget
        .charge_elements(
            format!("the {} × {} × {} volume", size[0], size[1], size[2]),
            count,
            4,
        )
        .map_err(|e| Parse::Clouds(e.into()))?;
    let needed = count * 4;
    let body = &bytes[header_len.min(bytes.len())..];
    if (body.len() as u64) < needed {
        return Err(Parse::Reason(format!(
            "truncated: the header promises {needed} bytes of voxels after its {header_len}, the file has {}",
            body.len()
        )));
    }
    let data = body[..needed as usize]
        .chunks_exact(4)
        .map(|b| {
            let b = [b[0], b[1], b[2], b[3]];
            if big_endian {
                f32::from_be_bytes(b)
            } else {
                f32::from_le_bytes(b)
            }
        })
        .collect();
    let grid = DensityGrid::from_data(size, data).map_err(Parse::Clouds)?;
    Ok(Volume {
        grid,
        voxel_size: voxel,
    })
}
