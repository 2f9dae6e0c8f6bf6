//! Input files read through a size check: only regular files, their size charged against the
//! render's memory budget before a byte is read, so that `/dev/zero`, a FIFO or a directory
//! given as an asset is refused at once instead of being read until memory runs out.

use std::io::Read;
use std::path::Path;

use crate::{BudgetError, MemoryBudget};

/// Why an input file was not read. Callers name the path; this says the reason.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file could not be opened or read.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// A device, FIFO, socket or directory: nothing fray reads is one.
    #[error("not a regular file ({0}): fray reads scenes and assets from regular files only")]
    NotAFile(&'static str),
    /// The file is larger than what is left of the memory budget.
    #[error(transparent)]
    Budget(#[from] BudgetError),
    /// The file grew while it was read.
    #[error("the file grew while it was read (past the {0} bytes it had when opened)")]
    Grew(u64),
}

/// The size of the regular file at `path`, checked to fit in what is left of `budget` (a file is
/// read whole at least once, so its size is a lower bound on what reading it needs).
pub fn checked_file_size(path: &Path, budget: &MemoryBudget) -> Result<u64, InputError> {
    let meta = std::fs::metadata(path)?;
    let kind = meta.file_type();
    if !kind.is_file() {
        return Err(InputError::NotAFile(file_kind(&kind)));
    }
    let size = meta.len();
    budget.check(format!("the file {}", path.display()), size)?;
    Ok(size)
}

/// The bytes of the regular file at `path`, its size checked against `budget` first and the read
/// bounded by that size.
pub fn read_file(path: &Path, budget: &MemoryBudget) -> Result<Vec<u8>, InputError> {
    let size = checked_file_size(path, budget)?;
    let file = std::fs::File::open(path)?;
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    // One byte past the size it had tells a file that grows from one that does not.
    file.take(size.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > size {
        return Err(InputError::Grew(size));
    }
    Ok(bytes)
}

/// Where text stops being UTF-8: the 1-based line and column (in characters) and the byte
/// offset of the first bad byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{line}:{column}: invalid UTF-8 at byte {byte}")]
pub struct InvalidUtf8 {
    pub line: usize,
    pub column: usize,
    pub byte: usize,
}

/// `bytes` as a `String`, or where they stop being UTF-8.
pub fn utf8(bytes: Vec<u8>) -> Result<String, InvalidUtf8> {
    String::from_utf8(bytes).map_err(|e| {
        let byte = e.utf8_error().valid_up_to();
        let before = &e.as_bytes()[..byte];
        let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
        let line_start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        // The valid prefix is UTF-8, so its characters can be counted for the column.
        let column =
            std::str::from_utf8(&before[line_start..]).map_or(0, |s| s.chars().count()) + 1;
        InvalidUtf8 { line, column, byte }
    })
}

/// [`read_file`] as UTF-8 text; invalid UTF-8 is an `InvalidData` error naming the line, the
/// column and the byte offset of the first bad byte.
pub fn read_text(path: &Path, budget: &MemoryBudget) -> Result<String, InputError> {
    utf8(read_file(path, budget)?)
        .map_err(|e| InputError::Io(std::io::Error::new(std::io::ErrorKind::InvalidData, e)))
}

fn file_kind(kind: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    if kind.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endless_and_special_files_are_refused_at_once() {
        let budget = MemoryBudget::new(1 << 20);
        #[cfg(unix)]
        {
            let e = read_file(Path::new("/dev/zero"), &budget).unwrap_err();
            assert!(e.to_string().contains("character device"), "{e}");
        }
        let dir = std::env::temp_dir();
        let e = read_file(&dir, &budget).unwrap_err();
        assert!(e.to_string().contains("directory"), "{e}");
    }

    #[test]
    fn a_file_over_what_is_left_is_refused_before_it_is_read() {
        let dir = std::env::temp_dir().join(format!("fray-core-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("big.bin");
        std::fs::write(&path, vec![7u8; 5000]).unwrap();
        let budget = MemoryBudget::new(8000);
        assert_eq!(read_file(&path, &budget).unwrap().len(), 5000);
        budget.charge("something else", 4000).unwrap();
        let e = read_file(&path, &budget).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("big.bin") && text.contains("4000 bytes"),
            "{text}"
        );
        std::fs::write(&path, b"ok\n\xffbad").unwrap();
        let e = read_text(&path, &budget).unwrap_err().to_string();
        assert!(e.contains("2:1: invalid UTF-8 at byte 3"), "{e}");
        let mut bytes = "é\nab\u{e9}c".as_bytes().to_vec();
        bytes.push(0xff);
        assert_eq!(
            utf8(bytes),
            Err(InvalidUtf8 {
                line: 2,
                column: 5,
                byte: 8
            })
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
