//! The scene target's input: a main scene file and the files it includes or names, in one byte
//! string. The text before the first [`SEPARATOR`] is [`MAIN_FILE`]; each later part starts with
//! a file name on its own line, and the rest of the part is that file:
//!
//! ```text
//! Scene(include: ["parts.ron"], ...)
//! --- parts.ron
//! (objects: [(name: "m", material: "m", shape: Mesh(path: "tiny.obj"))], ...)
//! --- tiny.obj
//! v 0 0 0
//! ...
//! ```
//!
//! A part whose name is not a plain file name ([`is_plain_name`]) is dropped, so every file lands
//! in the input's scratch folder; a later part of the same name replaces an earlier one.

/// What separates the files of a bundle: a line starting with `--- ` (the name follows).
pub const SEPARATOR: &[u8] = b"\n--- ";

/// The name of the bundle's first file, the scene that is loaded.
pub const MAIN_FILE: &str = "scene.ron";

/// The longest file name a bundle part may give: 64 bytes (plenty for `turboprop.ron`, short
/// enough that a mutated name cannot pass the file system's 255-byte limit).
const MAX_NAME: usize = 64;

/// A scene bundle split into its files, the main one first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Bundle {
    /// `(file name, bytes)`, [`MAIN_FILE`] first, names unique.
    pub files: Vec<(String, Vec<u8>)>,
}

impl Bundle {
    /// Splits a fuzz input into its files.
    pub fn split(data: &[u8]) -> Self {
        let mut parts = split_at_separator(data).into_iter();
        let main = parts.next().unwrap_or_default();
        let mut files = vec![(MAIN_FILE.to_owned(), main.to_vec())];
        for part in parts {
            let (name, bytes) = match part.iter().position(|&b| b == b'\n') {
                Some(end) => (&part[..end], &part[end + 1..]),
                None => (part, &[][..]),
            };
            let Some(name) = std::str::from_utf8(name).ok().filter(|n| is_plain_name(n)) else {
                continue;
            };
            match files.iter_mut().find(|(n, _)| n == name) {
                Some(file) => file.1 = bytes.to_vec(),
                None => files.push((name.to_owned(), bytes.to_vec())),
            }
        }
        Self { files }
    }

    /// The bundle as one input, the inverse of [`Bundle::split`] (for writing seeds).
    pub fn join(&self) -> Vec<u8> {
        let mut out = Vec::new();
        for (i, (name, bytes)) in self.files.iter().enumerate() {
            if i > 0 {
                out.extend_from_slice(SEPARATOR);
                out.extend_from_slice(name.as_bytes());
                out.push(b'\n');
            }
            out.extend_from_slice(bytes);
        }
        out
    }
}

/// A plain file name: 1 to 64 ASCII letters, digits, `_`, `-` and `.`, not starting with `.`
/// (no folder, no `..`, nothing hidden).
pub fn is_plain_name(name: &str) -> bool {
    (1..=MAX_NAME).contains(&name.len())
        && !name.starts_with('.')
        && name
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.'))
}

fn split_at_separator(data: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while let Some(at) = rest.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
        parts.push(&rest[..at]);
        rest = &rest[at + SEPARATOR.len()..];
    }
    parts.push(rest);
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_a_main_file_and_named_parts_and_joins_them_back() {
        let data = b"Scene()\n--- a.ron\n(objects: [])\n--- b.obj\nv 0 0 0\n";
        let b = Bundle::split(data);
        let names: Vec<&str> = b.files.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, [MAIN_FILE, "a.ron", "b.obj"]);
        assert_eq!(b.files[0].1, b"Scene()");
        assert_eq!(b.files[1].1, b"(objects: [])");
        assert_eq!(b.files[2].1, b"v 0 0 0\n");
        assert_eq!(b.join(), data);
    }

    #[test]
    fn names_that_leave_the_folder_are_dropped_and_repeats_replace() {
        let data = b"x\n--- ../up.ron\nA\n--- /abs\nB\n--- .hidden\nC\n--- a\nD\n--- a\nE";
        let b = Bundle::split(data);
        assert_eq!(
            b.files,
            [
                (MAIN_FILE.to_owned(), b"x".to_vec()),
                ("a".to_owned(), b"E".to_vec())
            ]
        );
        assert!(!is_plain_name(&"n".repeat(65)));
        assert_eq!(Bundle::split(b"").files, [(MAIN_FILE.to_owned(), vec![])]);
    }
}
