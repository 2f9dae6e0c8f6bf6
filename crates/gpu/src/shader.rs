//! WGSL modules: the files of `shaders/` (one per concept), the include step that composes an
//! entry module from them, the Rust-generated prelude (structs, constants, array sizes) and the
//! pipeline specialisation (`override` constants).
//!
//! The include step reads directives in comments, so every file is valid WGSL on its own terms:
//! - `// #include "file.wgsl"` — the file's text, once per module (WGSL declarations may come
//!   in any order, so included text is simply appended);
//! - `// #include "file.wgsl" if terrain` / `… unless terrain` — only with / without a terrain
//!   (likewise `if mesh` / `unless mesh`: with / without triangle meshes; `if fog` /
//!   `unless fog`: with / without a fog layer; `if sky` / `unless sky`: with / without a
//!   physically based sky; `if clouds` / `unless clouds`: with / without a cloud volume;
//!   `if textures` / `unless textures`: with / without image textures or colour ramps);
//! - `// #if fog` … `// #else` … `// #endif` — the lines (directives included) with / without
//!   the feature (any of the conditions above): a feature's hooks and, in the `#else`, their
//!   identities for a scene without it, in one file; a file whose outermost block is left out is
//!   marked `// ---- file.wgsl (without fog) ----` in the composed text;
//! - `// #instantiate "file.wgsl" { KEY: value; … }` — the file as a template, each `{{KEY}}`
//!   replaced (the CSG evaluator, once per algebra);
//! - `// #bindings frame, work, terrains if terrain` — the generated declarations of those bind
//!   groups (`bindings::GROUPS`), under the same conditions; `shading` stands for the scene's
//!   lights-and-media group (`bindings::shading`: with the fog's, the sky's and the clouds'
//!   bindings only where the scene has them), `surfaces` for the terrains', the meshes' and
//!   the textures' group (`bindings::surfaces`: any of them together, or no group at all).

use crate::features::{Feature, Features};
use crate::{bindings, counters, kind_dispatch, params};
use fray_core::gpu_struct::GpuStruct;
use fray_geometry::gpu_layout;
use fray_scene::{PrimitiveKind, Scene};

// `SHADER_FILES`: every file of `shaders/`, embedded (the crate's `shaders` is a link to the
// repository's, so a packaged crate holds them too).
include!(concat!(env!("OUT_DIR"), "/shader_files.rs"));

/// The entry modules, one per pass (`passes`, `kinds`) and one per batch kernel (`testing`): the
/// files that declare their bind groups (`// #bindings …`) — what only an entry module does.
pub fn entry_modules() -> impl Iterator<Item = &'static str> {
    SHADER_FILES
        .iter()
        .filter(|(_, text)| text.lines().any(|l| l.trim().starts_with("// #bindings ")))
        .map(|(name, _)| *name)
}

/// The entry modules composed only for Whitted scenes (`ModuleOptions::whitted`).
pub const WHITTED_ENTRY_MODULES: [&str; 5] = [
    "queue_forward.wgsl",
    "queue_level.wgsl",
    "queue_gather.wgsl",
    "intersect_secondary.wgsl",
    "whitted_gather.wgsl",
];

/// The text of shader file `name`.
pub fn file(name: &str) -> Option<&'static str> {
    SHADER_FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
}

/// Sizes fixed per scene when a module is built: the per-invocation arrays and the uniform
/// tables.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ArraySizes {
    pub max_leaves: u32,
    pub max_perturbations: u32,
    pub max_stack: u32,
    pub max_lights: u32,
    pub max_materials: u32,
    pub max_terrains: u32,
}

impl Default for ArraySizes {
    fn default() -> Self {
        Self {
            max_leaves: 8,
            max_perturbations: 16,
            max_stack: 4,
            max_lights: 4,
            max_materials: 8,
            max_terrains: 1,
        }
    }
}

/// Bytes of per-invocation private memory the free-form code needs for `sizes` (its leaf and
/// perturbation arrays and its stacks): `GpuScene` refuses a scene that needs more than
/// [`MAX_PRIVATE_BYTES`].
pub fn private_bytes(sizes: &ArraySizes) -> u64 {
    // LeafRay: 2 f32, 2 bool, vec3, 2 u32 (48 with padding); a perturbation's vec4; the CSG
    // stacks (bound: vec4; surface: vec4 + u32 → 32) and the segment stack (32 × vec2).
    48 * u64::from(sizes.max_leaves)
        + 16 * u64::from(sizes.max_perturbations)
        + 32 * u64::from(sizes.max_stack)
        + 8 * 32
}

/// The most per-invocation private memory a scene may need on the GPU (16 KiB): beyond it,
/// drivers spill to slow scratch memory or refuse the pipeline, so the backend refuses the scene
/// (`auto` renders it on the CPU).
pub const MAX_PRIVATE_BYTES: u64 = 16 << 10;

/// What a module is composed with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ModuleOptions {
    pub sizes: ArraySizes,
    /// The scene's features (`if <feature>` / `unless <feature>`: [`Features::condition`]).
    pub features: Features,
}

impl ModuleOptions {
    /// What a batch test pass is composed with: no scene's arrays (every size 1) and no
    /// feature; a pass turns on the one it tests (`BATCH.with(Feature::Fog)`).
    pub const BATCH: Self = Self {
        sizes: ArraySizes {
            max_leaves: 1,
            max_perturbations: 1,
            max_stack: 1,
            max_lights: 1,
            max_materials: 1,
            max_terrains: 1,
        },
        features: Features::NONE,
    };

    /// These options with `feature` on.
    pub const fn with(self, feature: Feature) -> Self {
        Self {
            features: self.features.with(feature),
            ..self
        }
    }

    /// These options with `feature` on where `on`, off otherwise.
    pub const fn with_if(self, feature: Feature, on: bool) -> Self {
        Self {
            features: self.features.with_if(feature, on),
            ..self
        }
    }

    /// Whether `feature` is on.
    pub const fn has(&self, feature: Feature) -> bool {
        self.features.has(feature)
    }
}

impl Default for ModuleOptions {
    /// Every feature but Whitted's secondary rays.
    fn default() -> Self {
        Self {
            sizes: ArraySizes::default(),
            features: Features::every().with_if(Feature::Whitted, false),
        }
    }
}

/// Why a module could not be composed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ComposeError {
    #[error("{file}: includes {missing}, which is not a shader file")]
    Missing { file: String, missing: String },
    #[error("{file}: unknown bind group {group}")]
    UnknownGroup { file: String, group: String },
    #[error("{file}: a malformed directive: {line}")]
    Malformed { file: String, line: String },
    #[error("{file}: template {template} leaves {{{{{key}}}}} unreplaced")]
    Unreplaced {
        file: String,
        template: String,
        key: String,
    },
}

/// The bind groups entry module `entry` binds, in the order of their indices (group `k` is the
/// `k`-th): what its pass must lay out and bind in that order.
pub fn module_groups(
    entry: &str,
    options: &ModuleOptions,
) -> Result<Vec<bindings::Group>, ComposeError> {
    Ok(Compose::of(entry, options)?.groups)
}

/// The complete source of entry module `entry`: the prelude, the bind groups it asks for, and
/// every file it includes (recursively, each once), then its own text.
pub fn compose(entry: &str, options: &ModuleOptions) -> Result<String, ComposeError> {
    let state = Compose::of(entry, options)?;
    let mut out = prelude(&options.sizes);
    for (index, g) in state.groups.iter().enumerate() {
        out.push_str(&g.declarations(index as u32));
    }
    out.push_str(&state.body);
    Ok(out)
}

struct Compose {
    options: ModuleOptions,
    included: Vec<String>,
    groups: Vec<bindings::Group>,
    body: String,
}

impl Compose {
    /// Entry module `entry` read with everything it includes.
    fn of(entry: &str, options: &ModuleOptions) -> Result<Self, ComposeError> {
        let mut state = Self {
            options: *options,
            included: Vec::new(),
            groups: Vec::new(),
            body: String::new(),
        };
        state.include(entry, entry)?;
        Ok(state)
    }

    /// Whether a directive's condition holds; an unknown feature is a malformed directive.
    fn condition(&self, rest: &str, file: &str, line: &str) -> Result<bool, ComposeError> {
        self.options
            .features
            .condition(rest)
            .ok_or_else(|| ComposeError::Malformed {
                file: file.to_owned(),
                line: line.to_owned(),
            })
    }

    fn include(&mut self, name: &str, from: &str) -> Result<(), ComposeError> {
        if self.included.iter().any(|n| n == name) {
            return Ok(());
        }
        // The dispatch to the scene's kinds' hooks is generated for its features.
        let generated;
        let text = if name == kind_dispatch::FILE {
            generated = kind_dispatch::kinds_wgsl(self.options.features);
            generated.as_str()
        } else {
            file(name).ok_or_else(|| ComposeError::Missing {
                file: from.to_owned(),
                missing: name.to_owned(),
            })?
        };
        self.included.push(name.to_owned());
        // `// #if <feature>` … `// #else` … `// #endif` blocks: what a file holds with and
        // without a feature (its hooks' real bodies and their identities), side by side.
        let mut blocks: Vec<bool> = Vec::new();
        // The feature a file's outermost `#if` found absent: its marker says so.
        let mut without: Option<&str> = None;
        let mut kept = String::with_capacity(text.len());
        for line in text.lines() {
            let malformed = || ComposeError::Malformed {
                file: name.to_owned(),
                line: line.to_owned(),
            };
            let on = blocks.iter().all(|&b| b);
            let directive = line.trim().strip_prefix("// #");
            match directive {
                Some(d) if d.starts_with("if ") => {
                    let present = self.condition(d, name, line)?;
                    if blocks.is_empty() && !present {
                        without = Some(d["if ".len()..].trim());
                    }
                    blocks.push(present);
                    continue;
                }
                Some("else") => {
                    let top = blocks.last_mut().ok_or_else(malformed)?;
                    *top = !*top;
                    continue;
                }
                Some("endif") => {
                    blocks.pop().ok_or_else(malformed)?;
                    continue;
                }
                _ => {}
            }
            if !on {
                continue;
            }
            kept.push_str(line);
            kept.push('\n');
            let Some(directive) = directive else {
                continue;
            };
            if let Some(rest) = directive.strip_prefix("include ") {
                let (target, condition) = quoted(rest).ok_or_else(malformed)?;
                if self.condition(condition, name, line)? {
                    self.include(target, name)?;
                }
            } else if let Some(rest) = directive.strip_prefix("instantiate ") {
                let (template, args) = quoted(rest).ok_or_else(malformed)?;
                let text = instantiate(name, template, args)?;
                self.body.push_str(&text);
            } else if let Some(rest) = directive.strip_prefix("bindings ") {
                for item in rest.split(',') {
                    let item = item.trim();
                    let (group, condition) = item.split_once(' ').unwrap_or((item, ""));
                    if !self.condition(condition, name, line)? {
                        continue;
                    }
                    let g = if group == "shading" {
                        // The scene's lights with its media (see `bindings::shading`).
                        bindings::shading(self.options.features)
                    } else if group == "surfaces" {
                        // The scene's terrains, meshes and textures (see
                        // `bindings::surfaces`), if any.
                        match bindings::surfaces(self.options.features) {
                            Some(g) => g,
                            None => continue,
                        }
                    } else {
                        *bindings::GROUPS
                            .iter()
                            .find(|g| g.name == group)
                            .ok_or_else(|| ComposeError::UnknownGroup {
                                file: name.to_owned(),
                                group: group.to_owned(),
                            })?
                    };
                    if !self.groups.contains(&g) {
                        self.groups.push(g);
                    }
                }
            } else {
                return Err(malformed());
            }
        }
        if !blocks.is_empty() {
            return Err(ComposeError::Malformed {
                file: name.to_owned(),
                line: "an `// #if` without its `// #endif`".to_owned(),
            });
        }
        match without {
            Some(feature) => self
                .body
                .push_str(&format!("\n// ---- {name} (without {feature}) ----\n")),
            None => self.body.push_str(&format!("\n// ---- {name} ----\n")),
        }
        self.body.push_str(&kept);
        Ok(())
    }
}

/// `"name" rest` → `(name, rest)`.
fn quoted(s: &str) -> Option<(&str, &str)> {
    let s = s.trim().strip_prefix('"')?;
    let (name, rest) = s.split_once('"')?;
    Some((name, rest))
}

/// Template `template` with `{ KEY: value; … }` substituted for each `{{KEY}}`.
fn instantiate(from: &str, template: &str, args: &str) -> Result<String, ComposeError> {
    let malformed = || ComposeError::Malformed {
        file: from.to_owned(),
        line: args.to_owned(),
    };
    let mut text = file(template)
        .ok_or_else(|| ComposeError::Missing {
            file: from.to_owned(),
            missing: template.to_owned(),
        })?
        .to_owned();
    let inner = args
        .trim()
        .strip_prefix('{')
        .and_then(|a| a.strip_suffix('}'))
        .ok_or_else(malformed)?;
    for pair in inner.split(';') {
        let pair = pair.trim();
        if pair.is_empty() {
            continue;
        }
        let (key, value) = pair.split_once(':').ok_or_else(malformed)?;
        text = text.replace(&format!("{{{{{}}}}}", key.trim()), value.trim());
    }
    // Directive-free code only: a template's own comments may mention `{{…}}`, its code not.
    let code: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("//"))
        .collect::<Vec<_>>()
        .join("\n");
    if let Some(start) = code.find("{{") {
        let key = code[start + 2..]
            .split("}}")
            .next()
            .unwrap_or_default()
            .to_owned();
        return Err(ComposeError::Unreplaced {
            file: from.to_owned(),
            template: template.to_owned(),
            key,
        });
    }
    Ok(format!(
        "\n// ---- {template} (instantiated in {from}) ----\n{code}\n"
    ))
}

/// The generated prelude: the geometry structs and op codes (fray-geometry), the terrain's
/// parameter struct (fray-terrain), the fog layer's and the sky's (fray-atmosphere), the
/// clouds' (fray-clouds), the meshes' structs and constants (fray-mesh), the
/// work-list structs (fray-quadtree), this crate's frame, path, light, material and rebase structs, the shared
/// constants, the counters' layout and the array sizes.
pub fn prelude(sizes: &ArraySizes) -> String {
    let mut s = gpu_layout::wgsl_declarations();
    s.push_str(&fray_terrain::gpu_layout::wgsl_declaration());
    s.push_str(&fray_atmosphere::gpu_layout::wgsl_declaration());
    s.push_str(&fray_clouds::gpu_layout::wgsl_declaration());
    s.push_str(&fray_mesh::gpu_layout::wgsl_declarations());
    s.push_str(&crate::texture_layout::wgsl_declarations());
    s.push_str("// Generated by fray_gpu::shader — do not edit.\n");
    for decl in [
        fray_quadtree::WorkItem::declaration(),
        fray_quadtree::Candidate::declaration(),
        params::FrameParams::declaration(),
        params::GpuPath::declaration(),
        params::GpuLight::declaration(),
        params::GpuMaterial::declaration(),
        params::GpuSecondary::declaration(),
        crate::params::RebaseParams::declaration(),
    ] {
        s.push_str(&decl);
    }
    let mut constants: Vec<(String, u32)> = params::wgsl_constants()
        .into_iter()
        .map(|(n, v)| (n.to_owned(), v))
        .collect();
    constants.extend(counters::wgsl_constants());
    constants.extend(
        fray_atmosphere::gpu_layout::wgsl_constants()
            .into_iter()
            .map(|(n, v)| (n.to_owned(), v)),
    );
    constants.extend(
        fray_mesh::gpu_layout::wgsl_constants()
            .into_iter()
            .map(|(n, v)| (n.to_owned(), v)),
    );
    constants.extend(
        crate::texture_layout::wgsl_constants()
            .into_iter()
            .map(|(n, v)| (n.to_owned(), v)),
    );
    constants.extend(
        PrimitiveKind::ALL
            .into_iter()
            .map(|k| (kind_dispatch::kind_constant(k), k.code())),
    );
    constants.extend([
        ("TILE_THREADS".to_owned(), crate::work::TILE),
        (
            "MAX_SHADOW_CROSSINGS".to_owned(),
            crate::params::MAX_SHADOW_CROSSINGS,
        ),
        (
            "MESH_TEXTURE_WIDTH".to_owned(),
            crate::params::DATA_TEXTURE_WIDTH,
        ),
    ]);
    for (name, value) in [
        ("MAX_LEAVES", sizes.max_leaves),
        ("MAX_PERTURBATIONS", sizes.max_perturbations),
        ("MAX_STACK", sizes.max_stack),
        ("MAX_LIGHTS", sizes.max_lights),
        ("MAX_MATERIALS", sizes.max_materials),
        ("MAX_TERRAINS", sizes.max_terrains),
    ] {
        constants.push((name.to_owned(), value.max(1)));
    }
    for (name, value) in constants {
        s.push_str(&format!("const {name}: u32 = {value}u;\n"));
    }
    s.push_str(&counters::wgsl_tables());
    s
}

/// The array sizes `scene` needs.
pub fn array_sizes(scene: &Scene, solids: &gpu_layout::GpuSolids) -> ArraySizes {
    ArraySizes {
        max_leaves: solids.max_leaves,
        max_perturbations: solids.max_perturbations,
        max_stack: solids.max_stack,
        max_lights: scene.lights.len() as u32,
        max_materials: scene.materials.len() as u32 + 1,
        max_terrains: scene.terrains.len() as u32,
    }
}

/// What the pipelines are specialised for: features absent here compile to nothing. The
/// default has no feature (what modules without overrides are built with).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Specialisation {
    /// The kinds, media, Whitted's rays and textures the scene has (as its modules are
    /// composed): each kind's intersection pass runs where it has one, the media pass where it
    /// has a medium, Whitted's queue passes where its materials reflect or transmit.
    pub features: Features,
    pub perturbations: bool,
    pub csg: bool,
    pub shadows: bool,
    pub sun: bool,
    pub point_lights: bool,
    pub projector: u32,
    /// Materials that transmit: shadow rays pass through them, dimmed by `kt`.
    pub transmission: bool,
}

impl Specialisation {
    /// The specialisation `scene` needs; `shadows` is the effective shadow switch.
    pub fn for_scene(scene: &Scene, shadows: bool) -> Self {
        let f = &scene.features;
        Self {
            features: Features::of_scene(scene),
            perturbations: f.perturbations,
            csg: f.csg,
            shadows: shadows && f.shadows && !scene.lights.is_empty(),
            sun: f.sun,
            point_lights: f.point_lights,
            projector: params::projector_kind(&scene.camera),
            transmission: f.transmission,
        }
    }

    /// Whether the scene has `feature`.
    pub const fn has(&self, feature: Feature) -> bool {
        self.features.has(feature)
    }

    /// Whether the scene has media (fog, a sky or clouds): the media pass runs.
    pub fn media(&self) -> bool {
        self.features.media()
    }

    /// The `override` constants of entry module `entry` (each module declares only its own).
    pub fn constants(&self, entry: &str) -> Vec<(&'static str, f64)> {
        let b = |v: bool| if v { 1.0 } else { 0.0 };
        let free_form = [
            ("HAS_PERTURBATIONS", b(self.perturbations)),
            // A transmissive solid's complement is a program (its own, negated).
            ("HAS_CSG", b(self.csg || self.transmission)),
        ];
        match entry {
            "raygen.wgsl" => vec![("PROJECTOR", f64::from(self.projector))],
            "resolve.wgsl" => vec![("HAS_MEDIA", b(self.media()))],
            "intersect_freeform.wgsl" => free_form.to_vec(),
            "shade.wgsl" => {
                let mut c = free_form.to_vec();
                c.extend([
                    (
                        "HAS_FREE_FORMS",
                        b(self.has(Feature::Kind(PrimitiveKind::FreeForm))),
                    ),
                    ("SHADOWS", b(self.shadows)),
                    ("HAS_SUN", b(self.sun)),
                    ("HAS_POINT", b(self.point_lights)),
                ]);
                if self.has(Feature::Whitted) {
                    c.push(("TRANSMISSION", b(self.transmission)));
                }
                c
            }
            "intersect_secondary.wgsl" => free_form.to_vec(),
            _ => Vec::new(),
        }
    }

    /// A short description for the frame's stats, e.g. `"pinhole, csg, shadows, sun"`.
    pub fn describe(&self) -> String {
        let projector = match self.projector {
            params::PROJECTOR_PINHOLE => "pinhole",
            params::PROJECTOR_PARALLEL => "parallel",
            _ => "sphere",
        };
        let mut parts = vec![projector];
        let has_free_forms = self.has(Feature::Kind(PrimitiveKind::FreeForm));
        for (on, name) in [
            (has_free_forms, "free-form"),
            (self.perturbations, "perturbations"),
            (self.csg, "csg"),
            (self.shadows, "shadows"),
            (self.sun, "sun"),
            (self.point_lights, "point-lights"),
        ] {
            if on {
                parts.push(name);
            }
        }
        for feature in self.features.iter() {
            if feature != Feature::Kind(PrimitiveKind::FreeForm) {
                parts.push(feature.name());
            }
            if feature == Feature::Whitted && self.transmission {
                parts.push("transmission");
            }
        }
        parts.join(", ")
    }
}

/// Test support: `source` parses and validates with naga and declares `T` as Rust lays it out —
/// every field by name, in order, at Rust's offset, and the same size. The batch modules' tests
/// (terrain, fog, sky) share it.
#[cfg(test)]
pub(crate) fn assert_validates_with_struct<T: GpuStruct>(source: &str) {
    let name = T::wgsl();
    let module = naga::front::wgsl::parse_str(source)
        .unwrap_or_else(|e| panic!("the module declaring {name} does not parse: {e}"));
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module);
    assert!(info.is_ok(), "{info:?}");
    let (_, ty) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(name.as_str()))
        .unwrap_or_else(|| panic!("{name} declared"));
    let naga::TypeInner::Struct { members, span } = &ty.inner else {
        panic!("{name} is not a struct");
    };
    assert_eq!(*span as usize, std::mem::size_of::<T>(), "{name} size");
    let fields = T::fields();
    let names: Vec<&str> = members.iter().filter_map(|m| m.name.as_deref()).collect();
    let rust: Vec<&str> = fields.iter().map(|f| f.name).collect();
    assert_eq!(names, rust, "{name} fields");
    for (m, f) in members.iter().zip(&fields) {
        assert_eq!(m.offset as usize, f.rust_offset, "{name}.{}", f.name);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    pub(crate) fn validate(name: &str, source: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(source)));
        module
    }

    #[test]
    fn every_shader_file_is_embedded_and_every_entry_module_validates_with_naga() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".wgsl"))
            .collect();
        on_disk.sort();
        let mut embedded: Vec<String> = SHADER_FILES
            .iter()
            .filter(|(_, text)| !text.is_empty())
            .map(|(n, _)| n.to_string())
            .collect();
        embedded.sort();
        assert_eq!(on_disk, embedded, "every file in shaders/ must be embedded");
        let mut reached: Vec<String> = Vec::new();
        let all: Vec<Feature> = Feature::all().collect();
        for k in 0..1u32 << all.len() {
            let features = all.iter().enumerate().fold(Features::NONE, |set, (i, f)| {
                set.with_if(*f, k & (1 << i) != 0)
            });
            let whitted = features.has(Feature::Whitted);
            for sizes in [
                ArraySizes::default(),
                ArraySizes {
                    max_leaves: 1,
                    max_perturbations: 0,
                    max_stack: 1,
                    max_lights: 0,
                    max_materials: 1,
                    max_terrains: 0,
                },
            ] {
                let options = ModuleOptions { sizes, features };
                for entry in entry_modules() {
                    if !whitted && WHITTED_ENTRY_MODULES.contains(&entry) {
                        continue;
                    }
                    let source = compose(entry, &options).unwrap();
                    validate(&format!("{entry} ({features:?})"), &source);
                    for (name, text) in SHADER_FILES {
                        if !text.is_empty() && source.contains(&format!("// ---- {name}")) {
                            reached.push(name.to_owned());
                        }
                    }
                }
            }
        }
        for (name, text) in SHADER_FILES {
            assert!(
                text.is_empty() || reached.iter().any(|r| r == name),
                "{name} is in no module"
            );
        }
    }

    #[test]
    fn the_include_step_resolves_once_instantiates_and_reports_errors() {
        // Every feature but the textures (whose switch is checked on its own below).
        let options = ModuleOptions::default().with_if(Feature::Textures, false);
        let shade = compose("shade.wgsl", &options).unwrap();
        // freeform.wgsl is included by shade.wgsl and reached again through nothing else: once.
        assert_eq!(shade.matches("// ---- freeform.wgsl ----").count(), 1);
        assert_eq!(shade.matches("// ---- ray.wgsl ----").count(), 1);
        // The CSG template, once per algebra.
        for name in ["csg_bound(", "csg_value(", "csg_surface("] {
            assert_eq!(shade.matches(&format!("fn {name}")).count(), 1, "{name}");
        }
        assert!(!shade.contains("{{"), "every placeholder replaced");
        // Conditional includes and bindings follow the terrain switch.
        assert!(shade.contains("// ---- terrain.wgsl ----"));
        assert!(shade.contains("// ---- terrain_hooks.wgsl"));
        let flat = compose(
            "shade.wgsl",
            &options.with_if(Feature::Kind(PrimitiveKind::Terrain), false),
        )
        .unwrap();
        assert!(
            !flat.contains("// ---- terrain.wgsl ----")
                && !flat.contains("var<storage, read> pyramid")
        );
        assert!(!flat.contains("terrain_hooks.wgsl") && !flat.contains("fn terrain_"));
        // And the meshes': a scene without them compiles no mesh code and binds no mesh data;
        // with them, shade reads the mesh texture through the terrains-and-meshes group.
        assert!(
            shade.contains("// ---- mesh.wgsl ----")
                && shade.contains("// ---- mesh_hooks.wgsl")
                && shade.contains("var mesh_data: texture_2d<u32>")
        );
        assert_eq!(
            module_groups("shade.wgsl", &options).unwrap()[3],
            bindings::group_of(&[bindings::Part::Terrains, bindings::Part::Meshes])
        );
        for (terrain, group) in [(true, Some(bindings::TERRAINS)), (false, None)] {
            let plain = options
                .with_if(Feature::Kind(PrimitiveKind::Terrain), terrain)
                .with_if(Feature::Kind(PrimitiveKind::Mesh), false);
            let frame_modules =
                entry_modules().filter(|e| !e.starts_with("mesh") && !e.ends_with("_mesh.wgsl"));
            for entry in frame_modules {
                let source = compose(entry, &plain).unwrap();
                assert!(
                    !source.contains("// ---- mesh.wgsl")
                        && !source.contains("mesh_data")
                        && !source.contains("mesh_info")
                        && !source.contains("fn load_mesh")
                        && !source.contains("fn mesh_instance_"),
                    "{entry}"
                );
            }
            assert_eq!(
                module_groups("shade.wgsl", &plain).unwrap().get(3).copied(),
                group
            );
        }
        let meshes_only = options.with_if(Feature::Kind(PrimitiveKind::Terrain), false);
        assert_eq!(
            module_groups("shade.wgsl", &meshes_only).unwrap()[3],
            bindings::MESHES
        );
        assert_eq!(
            module_groups("intersect_mesh.wgsl", &meshes_only).unwrap(),
            vec![bindings::FRAME, bindings::WORK, bindings::MESHES]
        );
        // And the fog switch: a scene without fog compiles no fog code and binds no fog layer.
        assert!(
            shade.contains("// ---- fog.wgsl ----") && shade.contains("var<uniform> fog: GpuFog")
        );
        assert!(!shade.contains("// ---- fog_shading.wgsl (without fog) ----"));
        for entry in ["shade.wgsl", "resolve.wgsl", "media.wgsl"] {
            let clear = compose(entry, &options.with_if(Feature::Fog, false)).unwrap();
            assert!(
                !clear.contains("// ---- fog.wgsl ----")
                    && !clear.contains("// ---- fog_shading.wgsl ----")
                    && !clear.contains("// ---- fog_media.wgsl ----")
                    && !clear.contains("var<uniform> fog"),
                "{entry}"
            );
        }
        // And the sky's: with a sky, shade reads its transmittance table and media both tables;
        // without, neither module has sky code, the sky's block or a table.
        assert!(
            shade.contains("// ---- sky.wgsl ----")
                && shade.contains("// ---- sky_shading.wgsl ----")
                && shade.contains("var<uniform> sky: GpuSky")
                && shade.contains("var sky_transmittance_table: texture_2d<f32>")
                && !shade.contains("// ---- sky_shading.wgsl (without sky) ----")
        );
        let media = compose("media.wgsl", &options).unwrap();
        assert!(
            media.contains("// ---- sky_media.wgsl ----")
                && media.contains("// ---- fog_media.wgsl ----")
        );
        for entry in ["shade.wgsl", "resolve.wgsl", "media.wgsl"] {
            let clear = compose(entry, &options.with_if(Feature::Sky, false)).unwrap();
            assert!(
                !clear.contains("// ---- sky.wgsl ----")
                    && !clear.contains("// ---- sky_shading.wgsl ----")
                    && !clear.contains("// ---- sky_media.wgsl ----")
                    && !clear.contains("var<uniform> sky")
                    && !clear.contains("sky_transmittance_table")
                    && !clear.contains("sky_view_table"),
                "{entry}"
            );
        }
        // And the clouds': with them shade and media march the volume and bind its block and
        // grids; without, no module has cloud code, the block or a texture.
        for entry in ["shade.wgsl", "media.wgsl"] {
            let cloudy = compose(entry, &options).unwrap();
            assert!(
                cloudy.contains("// ---- clouds.wgsl ----")
                    && cloudy.contains("var<uniform> clouds: GpuClouds")
                    && cloudy.contains("var cloud_density: texture_3d<f32>")
                    && cloudy.contains("var cloud_max: texture_3d<f32>")
                    && !cloudy.contains("(without clouds)"),
                "{entry}"
            );
        }
        for entry in ["shade.wgsl", "resolve.wgsl", "media.wgsl"] {
            let clear = compose(entry, &options.with_if(Feature::Clouds, false)).unwrap();
            assert!(
                !clear.contains("// ---- clouds.wgsl ----")
                    && !clear.contains("// ---- clouds_shading.wgsl ----")
                    && !clear.contains("// ---- clouds_media.wgsl ----")
                    && !clear.contains("var<uniform> clouds")
                    && !clear.contains("cloud_density")
                    && !clear.contains("cloud_max")
                    && !clear.contains("fn cloud_march"),
                "{entry}"
            );
        }
        // A scene with no medium: the plain lights-and-materials group.
        let plain = options
            .with_if(Feature::Fog, false)
            .with_if(Feature::Sky, false)
            .with_if(Feature::Clouds, false);
        assert_eq!(
            module_groups("shade.wgsl", &plain).unwrap()[2],
            bindings::group_of(&[bindings::Part::Lighting])
        );
        assert_eq!(
            module_groups("media.wgsl", &options).unwrap()[1],
            bindings::group_of(&[
                bindings::Part::Lighting,
                bindings::Part::Fog,
                bindings::Part::Sky,
                bindings::Part::Clouds
            ])
        );
        assert_eq!(
            module_groups("media.wgsl", &options.with_if(Feature::Clouds, false)).unwrap()[1],
            bindings::group_of(&[
                bindings::Part::Lighting,
                bindings::Part::Fog,
                bindings::Part::Sky
            ])
        );
        // And the textures': with them shade reads the texture data through the surfaces
        // group (alone for free forms only, after the terrains' and the meshes' bindings), with
        // the mesh and terrain hooks only where the scene has those kinds; without, no module
        // has texture code, the uniform or the data texture.
        let textured = options.with_if(Feature::Textures, true);
        let shade_textured = compose("shade.wgsl", &textured).unwrap();
        assert!(
            shade_textured.contains("// ---- texture.wgsl ----")
                && shade_textured.contains("fn mesh_texturing(")
                && shade_textured.contains("fn terrain_texturing(")
                && shade_textured.contains("var texture_data: texture_2d<u32>")
                && shade_textured.contains("var<uniform> texture_info: GpuTextureInfo")
                && !shade_textured.contains("// ---- texture.wgsl (without textures) ----")
        );
        assert_eq!(
            module_groups("shade.wgsl", &textured).unwrap()[3],
            bindings::group_of(&[
                bindings::Part::Terrains,
                bindings::Part::Meshes,
                bindings::Part::Textures
            ])
        );
        let free_forms_textured = textured
            .with_if(Feature::Kind(PrimitiveKind::Terrain), false)
            .with_if(Feature::Kind(PrimitiveKind::Mesh), false);
        let ff = compose("shade.wgsl", &free_forms_textured).unwrap();
        assert!(
            ff.contains("// ---- texture.wgsl ----")
                && !ff.contains("fn mesh_texturing(")
                && !ff.contains("fn terrain_texturing(")
        );
        assert_eq!(
            module_groups("shade.wgsl", &free_forms_textured).unwrap()[3],
            bindings::group_of(&[bindings::Part::Textures])
        );
        for entry in entry_modules() {
            let source = compose(entry, &options).unwrap();
            assert!(
                !source.contains("// ---- texture.wgsl ----")
                    && !source.contains("fn mesh_texturing(")
                    && !source.contains("fn terrain_texturing(")
                    && !source.contains("var texture_data")
                    && !source.contains("var<uniform> texture_info")
                    && !source.contains("texture_info.")
                    && !source.contains("fn texture_"),
                "{entry}"
            );
        }
        assert!(shade.contains("// ---- texture.wgsl (without textures) ----"));
        assert!(matches!(
            compose("nonexistent.wgsl", &options),
            Err(ComposeError::Missing { .. })
        ));
        assert!(matches!(
            instantiate("x", "csg.wgsl", "{ NAME: v }"),
            Err(ComposeError::Unreplaced { .. })
        ));
    }

    #[test]
    fn generated_layouts_and_constants_are_the_rust_ones() {
        let module = validate(
            "shade.wgsl",
            &compose("shade.wgsl", &ModuleOptions::default()).unwrap(),
        );
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let mut found: HashMap<String, (u32, Vec<u32>)> = HashMap::new();
        for (handle, ty) in module.types.iter() {
            if let (Some(name), naga::TypeInner::Struct { members, .. }) = (&ty.name, &ty.inner) {
                found.insert(
                    name.clone(),
                    (
                        layouter[handle].size,
                        members.iter().map(|m| m.offset).collect(),
                    ),
                );
            }
        }
        fn expect<T: GpuStruct>(found: &HashMap<String, (u32, Vec<u32>)>) {
            let name = T::wgsl();
            let (size, offsets) = found.get(&name).unwrap_or_else(|| panic!("{name} missing"));
            assert_eq!(*size as usize, std::mem::size_of::<T>(), "{name} size");
            let rust: Vec<u32> = T::fields().iter().map(|f| f.rust_offset as u32).collect();
            assert_eq!(offsets, &rust, "{name} offsets");
        }
        expect::<gpu_layout::GpuQuadric>(&found);
        expect::<gpu_layout::GpuPerturbation>(&found);
        expect::<gpu_layout::GpuLeaf>(&found);
        expect::<gpu_layout::GpuSolid>(&found);
        expect::<params::FrameParams>(&found);
        expect::<params::GpuPath>(&found);
        expect::<params::GpuLight>(&found);
        expect::<params::GpuMaterial>(&found);
        expect::<fray_quadtree::WorkItem>(&found);
        expect::<fray_quadtree::Candidate>(&found);
        expect::<fray_atmosphere::gpu_layout::GpuFog>(&found);
        expect::<fray_atmosphere::gpu_layout::GpuSky>(&found);
        expect::<fray_clouds::gpu_layout::GpuClouds>(&found);
        expect::<fray_mesh::gpu_layout::GpuMeshNode>(&found);
        expect::<fray_mesh::gpu_layout::GpuMeshTriangle>(&found);
        expect::<fray_mesh::gpu_layout::GpuMeshVertex>(&found);
        expect::<fray_mesh::gpu_layout::GpuMeshInstance>(&found);
        expect::<fray_mesh::texture::gpu_layout::GpuMapping>(&found);
        expect::<crate::texture_layout::GpuTextureMaterial>(&found);
        expect::<crate::texture_layout::GpuTextureLevel>(&found);
        expect::<crate::texture_layout::GpuTextureInfo>(&found);
        let constants: HashMap<String, naga::Handle<naga::Expression>> = module
            .constants
            .iter()
            .filter_map(|(_, c)| c.name.clone().map(|n| (n, c.init)))
            .collect();
        for (name, value) in [
            ("OP_LEAF", gpu_layout::OP_LEAF),
            ("OP_NEG", gpu_layout::OP_NEG),
            ("OP_BITS", gpu_layout::OP_BITS),
            ("PROJECTOR_SPHERE", params::PROJECTOR_SPHERE),
            ("LIGHT_POINT", params::LIGHT_POINT),
            ("KIND_TERRAIN", PrimitiveKind::Terrain.code()),
            ("KIND_MESH", PrimitiveKind::Mesh.code()),
            ("MESH_TEXTURE_WIDTH", crate::params::DATA_TEXTURE_WIDTH),
            ("MESH_FLAG_SMOOTH", fray_mesh::gpu_layout::MESH_FLAG_SMOOTH),
            ("TILE_THREADS", crate::work::TILE),
            ("FOG_METHOD", fray_atmosphere::gpu_layout::FOG_METHOD),
            ("PHASE_PRINTED", fray_atmosphere::gpu_layout::PHASE_PRINTED),
            ("NO_LIGHT", fray_atmosphere::gpu_layout::NO_LIGHT),
            ("MESH_STACK", fray_mesh::gpu_layout::MESH_STACK),
            ("MESH_NO_HIT", fray_mesh::gpu_layout::MESH_NO_HIT),
            (
                "MAPPING_TRIPLANAR",
                fray_mesh::texture::gpu_layout::MAPPING_TRIPLANAR,
            ),
            (
                "TEXTURE_WRAP_MIRROR",
                crate::texture_layout::TEXTURE_WRAP_MIRROR,
            ),
            (
                "TEXTURE_FILTER_TRILINEAR",
                crate::texture_layout::TEXTURE_FILTER_TRILINEAR,
            ),
            (
                "TEXTURE_DATA_WIDTH",
                crate::texture_layout::TEXTURE_DATA_WIDTH,
            ),
            (
                "SKY_AERIAL_PERSPECTIVE",
                fray_atmosphere::gpu_layout::SKY_AERIAL_PERSPECTIVE,
            ),
        ] {
            assert_eq!(
                module.global_expressions[constants[name]],
                naga::Expression::Literal(naga::Literal::U32(value)),
                "{name}"
            );
        }
    }

    #[test]
    fn specialisation_follows_the_scene() {
        let scene = fray_scene::parse(
            "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
            "inline.ron",
        )
        .unwrap();
        let s = Specialisation::for_scene(&scene, true);
        assert!(
            !s.perturbations
                && !s.csg
                && s.has(Feature::Kind(PrimitiveKind::FreeForm))
                && !s.has(Feature::Kind(PrimitiveKind::Terrain))
        );
        assert_eq!(s.projector, params::PROJECTOR_PINHOLE);
        assert!(s.describe().starts_with("pinhole"));
        assert_eq!(s.constants("shade.wgsl").len(), 6);
        assert_eq!(s.constants("raygen.wgsl"), vec![("PROJECTOR", 0.0)]);
        // Without fog resolve takes misses as the background; with fog the media pass's.
        assert!(!s.has(Feature::Fog) && !s.describe().contains("fog"));
        assert_eq!(s.constants("resolve.wgsl"), vec![("HAS_MEDIA", 0.0)]);
        let foggy = fray_scene::parse(
            "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), atmosphere: (fog: (top: 2)), objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
            "inline.ron",
        )
        .unwrap();
        let f = Specialisation::for_scene(&foggy, true);
        assert!(f.has(Feature::Fog) && f.describe().ends_with("fog"));
        assert_eq!(f.constants("resolve.wgsl"), vec![("HAS_MEDIA", 1.0)]);
        // A sky alone is media too.
        let sky = fray_scene::parse(
            "Scene(camera: Pinhole(eye: (0, 2, -4), look_at: (0, 0, 0)), atmosphere: (sky: ()), objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
            "inline.ron",
        )
        .unwrap();
        let k = Specialisation::for_scene(&sky, true);
        assert!(
            k.has(Feature::Sky)
                && !k.has(Feature::Fog)
                && k.media()
                && k.describe().ends_with("sky")
        );
        assert_eq!(k.constants("resolve.wgsl"), vec![("HAS_MEDIA", 1.0)]);
        assert!(!s.has(Feature::Clouds) && !f.has(Feature::Clouds) && !k.has(Feature::Clouds));
        // And clouds alone.
        let cloudy = fray_scene::parse(
            "Scene(camera: Pinhole(eye: (0, 0, -4), look_at: (0, 0, 0)), clouds: (region: (min: (-1, -1, -1), max: (1, 1, 1)), density: Layer((resolution: (4, 4, 4)))), objects: [(shape: Sphere(center: (0, 0, 0), radius: 1))])",
            "inline.ron",
        )
        .unwrap();
        let c = Specialisation::for_scene(&cloudy, true);
        assert!(
            c.has(Feature::Clouds)
                && !c.has(Feature::Sky)
                && !c.has(Feature::Fog)
                && c.media()
                && c.describe().ends_with("clouds")
        );
        assert_eq!(c.constants("resolve.wgsl"), vec![("HAS_MEDIA", 1.0)]);
    }
}
