//! Loading scene files: read → parse (RON, `implicit_some` on) → validate → resolve.

use crate::description;
use crate::locate::{LineColumn, locate};
use crate::path::{FieldPath, Segment};
use crate::resolve::resolve;
use crate::{Scene, SceneError};
use fray_core::MemoryBudget;
use ron::error::{Error as RonError, SpannedError};
use ron::extensions::Extensions;
use std::cell::Cell;
use std::path::Path;

/// Reads, parses, validates and resolves the scene file at `path`. Errors name the file.
/// What it builds (height maps and pyramids, cloud grids, sky tables) is checked against the
/// default [`MemoryBudget`].
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    load_with(path, &BuildOptions::default())
}

/// [`load`] building as `options` say: within their memory budget, reporting long builds.
pub fn load_with(path: &Path, options: &BuildOptions) -> Result<Scene, SceneError> {
    let source = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    parse_with(&source, &path.display().to_string(), options)
}

/// Parses, validates and resolves scene text; `file` is the name errors report, and asset paths
/// are relative to its folder.
pub fn parse(source: &str, file: &str) -> Result<Scene, SceneError> {
    parse_with(source, file, &BuildOptions::default())
}

/// [`parse`] building as `options` say.
pub fn parse_with(source: &str, file: &str, options: &BuildOptions) -> Result<Scene, SceneError> {
    parse_at_depth(source, file, 0, &Cell::new(0), options).map(|(scene, _)| scene)
}

/// A report of a long build's progress: what, steps done, steps in all (from any thread).
pub type BuildProgress<'a> = &'a (dyn Fn(&str, usize, usize) + Sync);

/// How a scene builds what it needs while it loads.
#[derive(Clone, Default)]
pub struct BuildOptions<'a> {
    /// What every grid, map and table is checked against before it is allocated.
    pub budget: MemoryBudget,
    /// Called as long builds progress (a cloud layer's bake: `("baking clouds", slices done,
    /// slices)`), from any thread.
    pub progress: Option<BuildProgress<'a>>,
}

impl std::fmt::Debug for BuildOptions<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BuildOptions")
            .field("budget", &self.budget)
            .field("progress", &self.progress.is_some())
            .finish()
    }
}

impl BuildOptions<'_> {
    /// The default options with `budget`.
    pub fn within(budget: MemoryBudget) -> Self {
        Self {
            budget,
            progress: None,
        }
    }

    /// Reports progress, if anyone listens.
    pub(crate) fn report(&self, what: &str, done: usize, total: usize) {
        if let Some(progress) = self.progress {
            progress(what, done, total);
        }
    }
}

/// How deep `include`s may nest (a file that includes itself stops here).
const MAX_INCLUDE_DEPTH: usize = 8;

/// How many files one scene may read through `include`s, all levels together: far more than a
/// scene made of parts needs (the data scenes include one), few enough that includes fanning out
/// — each file including the next several times, `k^depth` files from a few lines — are refused
/// at once instead of read and resolved one by one.
const MAX_INCLUDED_FILES: usize = 64;

/// [`parse`] of a file `depth` includes deep; `included` counts the files read through includes
/// so far. Also returns its description with its includes merged, for the file that includes it.
fn parse_at_depth(
    source: &str,
    file: &str,
    depth: usize,
    included: &Cell<usize>,
    options: &BuildOptions,
) -> Result<(Scene, description::Scene), SceneError> {
    let mut d = parse_description(source, file)?;
    // Assets (height maps) are found relative to the scene file.
    let base = Path::new(file).parent().unwrap_or(Path::new(""));
    let located = |path: FieldPath, message: String| {
        let LineColumn { line, column } = locate(source, &path);
        SceneError::Invalid {
            file: file.to_owned(),
            line,
            column,
            field: path.to_string(),
            message,
        }
    };
    let includes = std::mem::take(&mut d.include);
    for (i, name) in includes.iter().enumerate() {
        let at = FieldPath::root().field("include").index(i);
        if depth >= MAX_INCLUDE_DEPTH {
            return Err(located(
                at,
                format!("includes nest deeper than {MAX_INCLUDE_DEPTH} files (a cycle?)"),
            ));
        }
        included.set(included.get() + 1);
        if included.get() > MAX_INCLUDED_FILES {
            return Err(located(
                at,
                format!(
                    "this would be file {} read through includes, past the limit of \
                     {MAX_INCLUDED_FILES} per scene (files included many times over?)",
                    included.get()
                ),
            ));
        }
        let path = base.join(name);
        let text = std::fs::read_to_string(&path)
            .map_err(|e| located(at.clone(), format!("cannot read {}: {e}", path.display())))?;
        let (_, mut included) = parse_at_depth(
            &text,
            &path.display().to_string(),
            depth + 1,
            included,
            options,
        )?;
        rebase_assets(&mut included, path.parent().unwrap_or(Path::new("")));
        for (material, m) in included.materials {
            match d.materials.get(&material) {
                Some(own) if *own != m => {
                    return Err(located(
                        at,
                        format!(
                            "material `{material}` is defined differently here and in {}",
                            path.display()
                        ),
                    ));
                }
                Some(_) => {}
                None => {
                    d.materials.insert(material, m);
                }
            }
        }
        d.objects.extend(included.objects);
    }
    let scene = resolve(&d, base, options).map_err(|e| {
        let LineColumn { line, column } = locate(source, &e.path);
        SceneError::Invalid {
            file: file.to_owned(),
            line,
            column,
            field: e.path.to_string(),
            message: e.message,
        }
    })?;
    Ok((scene, d))
}

/// Makes the asset paths of an included file's objects (height maps and meshes, relative to that file's
/// folder `folder`) absolute, so they resolve from the including file too.
fn rebase_assets(d: &mut description::Scene, folder: &Path) {
    fn shape(s: &mut description::Shape, folder: &Path) {
        use description::Shape;
        match s {
            Shape::Terrain(t) => t.path = folder.join(&t.path).display().to_string(),
            Shape::Mesh(m) => m.path = folder.join(&m.path).display().to_string(),
            Shape::Union(v) | Shape::Intersection(v) => v.iter_mut().for_each(|s| shape(s, folder)),
            Shape::Difference(a, b) => {
                shape(a, folder);
                shape(b, folder);
            }
            Shape::Transformed { shape: s, .. } => shape(s, folder),
            Shape::FreeForm(_) | Shape::Quadric(_) => {}
        }
    }
    for o in &mut d.objects {
        shape(&mut o.shape, folder);
    }
}

/// Parses scene text into its [`description::Scene`] without validating values (types, field
/// names and syntax are checked); `file` is the name errors report.
pub fn parse_description(source: &str, file: &str) -> Result<description::Scene, SceneError> {
    let options = ron::Options::default().with_default_extension(Extensions::IMPLICIT_SOME);
    let mut de = ron::Deserializer::from_str_with_options(source, &options)
        .map_err(|e| ron_error(file, e, &FieldPath::root()))?;
    match serde_path_to_error::deserialize::<_, description::Scene>(&mut de) {
        Ok(scene) => match de.end() {
            Ok(()) => Ok(scene),
            Err(code) => Err(ron_error(file, de.span_error(code), &FieldPath::root())),
        },
        Err(e) => {
            let path = FieldPath::from_serde(e.path());
            let code = e.into_inner();
            Err(ron_error(file, de.span_error(code), &path))
        }
    }
}

/// A `ron` error at `path` as a [`SceneError`]: `Invalid` (with the field) for errors about
/// what a value is, `Syntax` for malformed text.
fn ron_error(file: &str, e: SpannedError, path: &FieldPath) -> SceneError {
    let position = e.span.end;
    let (line, column) = (position.line, position.col);
    let file = file.to_owned();
    let list = |names: &[&str]| -> String {
        let names: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
        if names.is_empty() {
            "none".to_owned()
        } else {
            names.join(", ")
        }
    };
    let (field, message) = match &e.code {
        RonError::NoSuchStructField {
            expected, found, ..
        } => {
            // The tracked path usually ends with the unknown key already.
            let field = match path.segments.last() {
                Some(Segment::Field(last)) if last == found => path.clone(),
                _ => path.field(found),
            };
            (
                field,
                format!(
                    "unknown field `{found}`, expected one of {}",
                    list(expected)
                ),
            )
        }
        RonError::NoSuchEnumVariant {
            expected, found, ..
        } => (
            path.clone(),
            format!(
                "unknown variant `{found}`, expected one of {}",
                list(expected)
            ),
        ),
        RonError::MissingStructField { field, .. } => {
            (path.field(field), "missing required field".to_owned())
        }
        RonError::DuplicateStructField { field, .. } => {
            (path.field(field), "field given twice".to_owned())
        }
        RonError::Message(_)
        | RonError::ExpectedArray
        | RonError::ExpectedBoolean
        | RonError::ExpectedChar
        | RonError::ExpectedByteLiteral
        | RonError::ExpectedFloat
        | RonError::ExpectedInteger
        | RonError::ExpectedOption
        | RonError::ExpectedMap
        | RonError::ExpectedDifferentStructName { .. }
        | RonError::ExpectedStructLike
        | RonError::ExpectedNamedStructLike(_)
        | RonError::ExpectedUnit
        | RonError::ExpectedString
        | RonError::ExpectedByteString
        | RonError::IntegerOutOfBounds
        | RonError::InvalidValueForType { .. }
        | RonError::ExpectedDifferentLength { .. }
        | RonError::ExpectedRawValue
        | RonError::ExpectedStructName(_) => (path.clone(), wrong_type_message(&e.code)),
        code => {
            return SceneError::Syntax {
                file,
                line,
                column,
                message: code.to_string(),
            };
        }
    };
    SceneError::Invalid {
        file,
        line,
        column,
        field: field.to_string(),
        message,
    }
}

fn wrong_type_message(code: &RonError) -> String {
    match code {
        RonError::ExpectedFloat => "expected a number".to_owned(),
        RonError::ExpectedInteger => "expected a whole number".to_owned(),
        RonError::IntegerOutOfBounds => "the number is out of range for this field".to_owned(),
        RonError::ExpectedBoolean => "expected `true` or `false`".to_owned(),
        RonError::ExpectedString => "expected a string in double quotes".to_owned(),
        RonError::InvalidValueForType { expected, found } => {
            format!("expected {expected}, found {found}")
        }
        other => {
            let text = other.to_string();
            let mut chars = text.chars();
            match chars.next() {
                Some(c) => c.to_lowercase().chain(chars).collect(),
                None => text,
            }
        }
    }
}
