//! Loading scene files: read → parse (RON, `implicit_some` on) → validate → resolve.

use crate::description;
use crate::locate::{LineColumn, locate};
use crate::path::{FieldPath, Segment};
use crate::resolve::resolve;
use crate::{Scene, SceneError};
use fray_core::MemoryBudget;
use fray_core::input::{InputError, read_file, utf8};
use ron::error::{Error as RonError, SpannedError};
use ron::extensions::Extensions;
use std::collections::HashMap;
use std::path::Path;
use std::path::PathBuf;

/// Reads, parses, validates and resolves the scene file at `path`. Errors name the file.
/// What it builds (height maps and pyramids, cloud grids, sky tables) is checked against the
/// default [`MemoryBudget`].
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    load_with(path, &BuildOptions::default())
}

/// [`load`] building as `options` say: within their memory budget, reporting long builds.
pub fn load_with(path: &Path, options: &BuildOptions) -> Result<Scene, SceneError> {
    let source = read_scene_file(path, &options.budget)?;
    parse_with(&source, &path.display().to_string(), options)
}

/// The text of the scene file at `path`: a regular file within what is left of the budget (so a
/// device or a FIFO is refused at once), UTF-8 (a bad byte is a syntax error at its line and
/// column).
fn read_scene_file(path: &Path, budget: &MemoryBudget) -> Result<String, SceneError> {
    let bytes = read_file(path, budget).map_err(|e| SceneError::Io {
        path: path.to_owned(),
        source: match e {
            InputError::Io(source) => source,
            other => std::io::Error::other(other.to_string()),
        },
    })?;
    utf8(bytes).map_err(|e| SceneError::Syntax {
        file: path.display().to_string(),
        line: e.line,
        column: e.column,
        message: format!(
            "invalid UTF-8 at byte {} (a scene file is UTF-8 text)",
            e.byte
        ),
    })
}

/// Parses, validates and resolves scene text; `file` is the name errors report, and asset paths
/// are relative to its folder.
pub fn parse(source: &str, file: &str) -> Result<Scene, SceneError> {
    parse_with(source, file, &BuildOptions::default())
}

/// [`parse`] building as `options` say.
pub fn parse_with(source: &str, file: &str, options: &BuildOptions) -> Result<Scene, SceneError> {
    parse_at_depth(source, file, 0, options, &mut Includes::default()).map(|(scene, _)| scene)
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

/// The most objects a scene may hold once its includes are merged. Every object is a candidate
/// that the quadtree tests against every cell it reaches, so the cost of a frame grows with the
/// count; a few includes that include each other several times reach millions from a few
/// hundred bytes of text, and this stops them before they are copied.
pub const MAX_OBJECTS: usize = 100_000;

/// What one object of a scene costs before its shape's own lists: its description and its
/// resolved form, charged to the budget for every object after includes.
const OBJECT_BYTES: u64 =
    (std::mem::size_of::<description::Object>() + std::mem::size_of::<crate::Object>()) as u64;

/// The files one load includes, each parsed and validated once, by their canonical path: the
/// description with its own includes merged and its asset paths made absolute.
#[derive(Default)]
struct Includes {
    merged: HashMap<PathBuf, description::Scene>,
    /// What the load's files read and built, once (an included file is resolved alone, then as
    /// part of the scene).
    assets: crate::assets::LoadedAssets,
    /// Files being read now (an include whose own includes are still being read).
    reading: usize,
}

/// How many distinct files one scene may read through `include`s, all levels together: far more
/// than a scene made of parts needs (the data scenes include one), few enough that includes
/// fanning out — each file including several others, `k^depth` files from a few lines — are
/// refused at once instead of read and resolved one by one.
pub const MAX_INCLUDED_FILES: usize = 64;

/// [`parse`] of a file `depth` includes deep; also returns its description with its includes
/// merged, for the file that includes it.
fn parse_at_depth(
    source: &str,
    file: &str,
    depth: usize,
    options: &BuildOptions,
    includes: &mut Includes,
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
    let names = std::mem::take(&mut d.include);
    for (i, name) in names.iter().enumerate() {
        let at = FieldPath::root().field("include").index(i);
        if depth >= MAX_INCLUDE_DEPTH {
            return Err(located(
                at,
                format!("includes nest deeper than {MAX_INCLUDE_DEPTH} files (a cycle?)"),
            ));
        }
        let path = base.join(name);
        let key = std::fs::canonicalize(&path).unwrap_or_else(|_| path.clone());
        let included = match includes.merged.get(&key) {
            Some(included) => included,
            None => {
                if includes.merged.len() + includes.reading >= MAX_INCLUDED_FILES {
                    return Err(located(
                        at,
                        format!(
                            "{} would be file {} read through includes, past the limit of \
                             {MAX_INCLUDED_FILES}",
                            path.display(),
                            MAX_INCLUDED_FILES + 1
                        ),
                    ));
                }
                let text = read_scene_file(&path, &options.budget).map_err(|e| match e {
                    SceneError::Io { source, .. } => located(
                        at.clone(),
                        format!("cannot read {}: {source}", path.display()),
                    ),
                    other => other,
                })?;
                // The included file is validated on its own (so its errors name it), on an
                // account of its own; what it reads and builds is kept for this scene
                // (`Includes::assets`), which is charged for it again.
                let alone = BuildOptions {
                    budget: MemoryBudget::new(options.budget.remaining()),
                    progress: options.progress,
                };
                includes.reading += 1;
                let parsed = parse_at_depth(
                    &text,
                    &path.display().to_string(),
                    depth + 1,
                    &alone,
                    includes,
                );
                includes.reading -= 1;
                let (_, mut included) = parsed?;
                rebase_assets(&mut included, path.parent().unwrap_or(Path::new("")));
                includes.merged.entry(key).or_insert(included)
            }
        };
        let objects = d.objects.len().saturating_add(included.objects.len());
        if objects > MAX_OBJECTS {
            return Err(located(
                at,
                format!(
                    "with {} the scene would hold {objects} objects, more than the \
                     {MAX_OBJECTS} a scene may hold",
                    path.display()
                ),
            ));
        }
        let included = included.clone();
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
    options
        .budget
        .charge_elements(
            "the scene's objects after includes",
            d.objects.len() as u64,
            OBJECT_BYTES,
        )
        .map_err(|e| located(FieldPath::root().field("objects"), e.to_string()))?;
    let scene = resolve(&d, base, options, &mut includes.assets).map_err(|e| {
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
        let paths = s.asset_paths_mut();
        if !paths.is_empty() {
            for path in paths {
                *path = folder.join(&*path).display().to_string();
            }
            return;
        }
        match s {
            Shape::Union(v) | Shape::Intersection(v) => v.iter_mut().for_each(|s| shape(s, folder)),
            Shape::Difference(a, b) => {
                shape(a, folder);
                shape(b, folder);
            }
            Shape::Transformed { shape: s, .. } => shape(s, folder),
            _ => {}
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A mesh named by an included file and by the scene is read and built once in the load —
    /// not once to validate the included file and again for the scene —, both objects are
    /// instances of it, and the scene's account is charged for it.
    #[test]
    fn an_included_files_assets_are_built_once_and_charged_to_the_scene() {
        let dir = std::env::temp_dir().join(format!("fray-assets-once-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let mesh = "(objects: [(shape: Mesh(path: \"tri.obj\"))])";
        std::fs::write(dir.join("part.ron"), mesh).unwrap();
        let main = dir.join("main.ron");
        let text = "(include: [\"part.ron\"], objects: [(shape: Mesh(path: \"tri.obj\"))])";
        std::fs::write(&main, text).unwrap();
        let options = BuildOptions::default();
        let mut includes = Includes::default();
        let (scene, _) = parse_at_depth(
            text,
            &main.display().to_string(),
            0,
            &options,
            &mut includes,
        )
        .unwrap();
        assert_eq!(includes.assets.meshes.builds, 1);
        assert_eq!(scene.meshes.len(), 2);
        let packets = |k: usize| scene.meshes[k].instance.packets().map(std::ptr::from_ref);
        assert!(packets(0).is_some() && packets(0) == packets(1));
        let ledger = options.budget.ledger();
        assert!(
            ledger.iter().any(|(what, _)| what.contains("tri.obj")),
            "{ledger:?}"
        );
        std::fs::remove_dir_all(&dir).ok();
    }
}
