//! Field paths into a scene file, like `objects[1].shape.perturbations[0].quadric.radius`.

use std::fmt;

/// One step of a [`FieldPath`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Segment {
    /// A struct field or a map key: `.name`.
    Field(String),
    /// A list or tuple element: `[i]`.
    Index(usize),
}

/// The path of a field from the top of the scene file. Enum variant names are not part of it:
/// `shape: Sphere(radius: -1)` is at `shape.radius`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub(crate) struct FieldPath {
    pub(crate) segments: Vec<Segment>,
}

impl FieldPath {
    pub(crate) fn root() -> Self {
        Self::default()
    }

    /// This path extended by the field `name`.
    pub(crate) fn field(&self, name: &str) -> Self {
        let mut p = self.clone();
        p.segments.push(Segment::Field(name.to_owned()));
        p
    }

    /// This path extended by element `i`.
    pub(crate) fn index(&self, i: usize) -> Self {
        let mut p = self.clone();
        p.segments.push(Segment::Index(i));
        p
    }

    /// The path that `serde_path_to_error` tracked, without enum variant names.
    pub(crate) fn from_serde(path: &serde_path_to_error::Path) -> Self {
        let segments = path
            .iter()
            .filter_map(|s| match s {
                serde_path_to_error::Segment::Seq { index } => Some(Segment::Index(*index)),
                serde_path_to_error::Segment::Map { key } => Some(Segment::Field(key.clone())),
                _ => None, // enum variants and unknown steps
            })
            .collect();
        Self { segments }
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.segments.is_empty() {
            return f.write_str("(scene)");
        }
        for (i, s) in self.segments.iter().enumerate() {
            match s {
                Segment::Field(name) if i == 0 => f.write_str(name)?,
                Segment::Field(name) => write!(f, ".{name}")?,
                Segment::Index(k) => write!(f, "[{k}]")?,
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displays_like_rust_field_access() {
        let p = FieldPath::root()
            .field("objects")
            .index(1)
            .field("shape")
            .field("radius");
        assert_eq!(p.to_string(), "objects[1].shape.radius");
        assert_eq!(FieldPath::root().to_string(), "(scene)");
    }
}
