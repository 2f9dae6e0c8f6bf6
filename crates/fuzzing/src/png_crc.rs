//! PNG chunk checksums recomputed before a PNG input is loaded. A mutation almost always breaks
//! a chunk's CRC-32, and the decoder refuses such a chunk before it reads its contents, so
//! without this the PNG targets would fuzz little but the checksum test; with it, every mutated
//! chunk's contents reach the header checks, the size checks and the decoder.

/// The PNG signature.
const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

/// `data` with the CRC-32 of every whole chunk (length, type, contents, CRC) recomputed over its
/// type and contents; bytes that do not start with the PNG signature, and a last chunk cut
/// short, are left as they are.
pub fn fix_png_crcs(data: &[u8]) -> Vec<u8> {
    let mut out = data.to_vec();
    if !out.starts_with(SIGNATURE) {
        return out;
    }
    let mut at = SIGNATURE.len();
    while let Some(len_bytes) = out.get(at..at + 4) {
        let len = u32::from_be_bytes([len_bytes[0], len_bytes[1], len_bytes[2], len_bytes[3]]);
        let Some(body_end) = (at + 8).checked_add(len as usize) else {
            break;
        };
        let Some(body) = out.get(at + 4..body_end) else {
            break;
        };
        let crc = crc32fast::hash(body).to_be_bytes();
        let Some(slot) = out.get_mut(body_end..body_end + 4) else {
            break;
        };
        slot.copy_from_slice(&crc);
        at = body_end + 4;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The IEND chunk, whose CRC is the well-known AE 42 60 82.
    #[test]
    fn recomputes_a_known_crc_and_leaves_other_bytes_alone() {
        let mut png = SIGNATURE.to_vec();
        png.extend_from_slice(b"\0\0\0\0IEND\0\0\0\0");
        let fixed = fix_png_crcs(&png);
        assert_eq!(&fixed[fixed.len() - 4..], [0xAE, 0x42, 0x60, 0x82]);
        assert_eq!(fixed[..fixed.len() - 4], png[..png.len() - 4]);
        // Cut short: left as it is.
        assert_eq!(fix_png_crcs(&png[..png.len() - 2]), &png[..png.len() - 2]);
        assert_eq!(fix_png_crcs(b"not a png"), b"not a png");
    }
}
