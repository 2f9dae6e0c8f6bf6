//! `cargo xtask datasize`: the data-size claim at equal error — a scene's free-form solid
//! polygonised at several cell sizes, each mesh's two-sided Hausdorff distance to the surface
//! (`hausdorff`), the bytes of both descriptions in binary (the functional model's GPU arrays,
//! an indexed f32 mesh), and the size ratio at the error of a mesh that looks the same at 1080p.
//!
//! Written to `<out>/datasize.csv`, `datasize.md`, `datasize.svg` and `datasize.png`.

use crate::datasize_plot::{self, Plot, PlotMesh};
use crate::hausdorff::{self, Hausdorff, Sampling};
use fray_core::{Aabb, MemoryBudget, Projector};
use fray_geometry::Solid;
use fray_geometry::gpu_layout::{GpuLeaf, GpuPerturbation, GpuSolid};
use fray_scene::Scene;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// What to measure and where to write it.
#[derive(Clone, Debug)]
pub struct DatasizeOptions {
    pub scene: PathBuf,
    /// Cubic cells along the longest side of the solid's box, one mesh each.
    pub cells: Vec<u32>,
    pub out: PathBuf,
    /// Where to copy the plot as `datasize.svg` and `datasize.png` too (the docs' copies).
    pub docs: Option<PathBuf>,
    pub sampling: Sampling,
}

/// The image rows whose pixel defines "looks the same".
pub const ROWS: u32 = 1080;

/// The functional model in bytes: the arrays the GPU backend uploads for the scene's free forms
/// (`fray_gpu`'s resident scene: [`GpuSolids`] with its complements), and the same numbers as
/// f64 without padding (a quadric's origin and ten coefficients, a form factor, a box's six
/// corners as f64; indices, flags and program words as u32).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelBytes {
    pub solids: usize,
    pub leaves: usize,
    pub perturbations: usize,
    pub program_words: usize,
    /// `GpuSolid` + `GpuLeaf` + `GpuPerturbation` arrays and the program, as uploaded.
    pub gpu: usize,
    /// The same numbers unpadded, floats in f64.
    pub f64: usize,
}

/// Bytes of a quadric in f64: origin (3) and coefficients (10).
const F64_QUADRIC: usize = 13 * 8;
/// A perturbation: its quadric and form factor.
const F64_PERTURBATION: usize = F64_QUADRIC + 8;
/// A leaf: base quadric, box (6 f64), clips, first and end perturbation, material (4 u32).
const F64_LEAF: usize = F64_QUADRIC + 6 * 8 + 4 * 4;
/// A solid: box, first leaf, leaf count, first word, word count, complement word (5 u32).
const F64_SOLID: usize = 6 * 8 + 5 * 4;

/// The scene's free forms as the GPU holds them (`fray_gpu::resident::scene_solids`, which
/// `ResidentScene::upload` uploads).
pub fn model_bytes(scene: &Scene) -> ModelBytes {
    let flat = fray_gpu::resident::scene_solids(scene, glam::DVec3::ZERO);
    let (s, l, p, w) = (
        flat.solids.len(),
        flat.leaves.len(),
        flat.perturbations.len(),
        flat.program.len(),
    );
    ModelBytes {
        solids: s,
        leaves: l,
        perturbations: p,
        program_words: w,
        gpu: s * size_of::<GpuSolid>()
            + l * size_of::<GpuLeaf>()
            + p * size_of::<GpuPerturbation>()
            + w * size_of::<u32>(),
        f64: s * F64_SOLID + l * F64_LEAF + p * F64_PERTURBATION + w * 4,
    }
}

/// One polygonisation and its measure.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshRow {
    pub cells: u32,
    /// The cell's side (world units).
    pub cell_size: f64,
    pub vertices: usize,
    pub triangles: usize,
    pub hausdorff: Hausdorff,
    pub polygonise: Duration,
}

impl MeshRow {
    /// An indexed f32 mesh: 12 bytes a vertex (position), 12 a triangle (three u32 indices),
    /// and with `normals` 12 more a vertex.
    pub fn bytes(&self, normals: bool) -> usize {
        let per_vertex = if normals { 24 } else { 12 };
        self.vertices * per_vertex + self.triangles * 12
    }
}

/// A pixel's footprint at the model: the distance from the eye to the nearest point of the
/// model's box, and the side of a pixel there, `distance · 2 tan(fov_y / 2) / rows`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    pub distance: f64,
    pub pixel: f64,
}

/// The footprint of one of `rows` pixel rows of a pinhole `camera` at `bounds`' nearest point
/// (a pinhole keeps its vertical field of view at any image size).
pub fn pixel_footprint(camera: &Projector, bounds: &Aabb, rows: u32) -> Result<Footprint, String> {
    let Projector::Pinhole(pinhole) = camera else {
        return Err("the pixel footprint needs a pinhole camera".into());
    };
    let eye = pinhole.eye;
    let distance = (eye.clamp(bounds.min, bounds.max) - eye).length();
    if distance <= 0.0 {
        return Err("the eye is inside the model's box".into());
    }
    Ok(Footprint {
        distance,
        pixel: distance * 2.0 * pinhole.tan_half_fov_y / f64::from(rows),
    })
}

/// How the mesh's size at an error was read off the measured meshes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reading {
    /// Log-log between the meshes of these cell counts, which bracket the error.
    Interpolated(u32, u32),
    /// Log-log beyond the finest meshes (no measured mesh is that accurate): the least-squares
    /// line through the meshes from `first` to `last` cells, `bytes ∝ error^exponent`.
    Extrapolated {
        first: u32,
        last: u32,
        exponent: f64,
    },
    /// The coarsest mesh already meets the error: its size, an upper bound.
    Coarsest(u32),
}

/// How many of the finest meshes the extrapolation's line is fitted to.
pub const EXTRAPOLATION_MESHES: usize = 3;

/// The least-squares line `ln bytes = a + k ln error` through `(cells, error, bytes)`:
/// `(a, k)`, or `None` for fewer than two distinct positive errors.
fn log_log_line(points: &[(u32, f64, f64)]) -> Option<(f64, f64)> {
    let logs: Vec<(f64, f64)> = points.iter().map(|p| (p.1.ln(), p.2.ln())).collect();
    if points.len() < 2 || logs.iter().any(|(x, y)| !x.is_finite() || !y.is_finite()) {
        return None;
    }
    let n = logs.len() as f64;
    let (mx, my) = logs
        .iter()
        .fold((0.0, 0.0), |(sx, sy), (x, y)| (sx + x / n, sy + y / n));
    let sxx: f64 = logs.iter().map(|(x, _)| (x - mx) * (x - mx)).sum();
    let sxy: f64 = logs.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let k = sxy / sxx;
    Some((my - k * mx, k))
}

/// The size of a mesh with error `target`, from `(cells, error, bytes)` ordered by cells: between
/// the last mesh above the error and the first at or below it (log-log); where none meets it,
/// on the least-squares log-log line through the [`EXTRAPOLATION_MESHES`] finest. `None` with
/// fewer than two meshes and none meeting it, or errors that are not positive.
pub fn bytes_at(points: &[(u32, f64, f64)], target: f64) -> Option<(f64, Reading)> {
    let at = |(a, k): (f64, f64)| (a + k * target.ln()).exp();
    match points.iter().position(|p| p.1 <= target) {
        Some(0) => Some((points[0].2, Reading::Coarsest(points[0].0))),
        Some(i) => log_log_line(&points[i - 1..=i]).map(|line| {
            (
                at(line),
                Reading::Interpolated(points[i - 1].0, points[i].0),
            )
        }),
        None => {
            let finest = &points[points.len().saturating_sub(EXTRAPOLATION_MESHES)..];
            let line = log_log_line(finest)?;
            let reading = Reading::Extrapolated {
                first: finest[0].0,
                last: finest[finest.len() - 1].0,
                exponent: line.1,
            };
            Some((at(line), reading))
        }
    }
}

/// The mesh's size at one error, without and with normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AtError {
    pub error: f64,
    pub mesh_bytes: f64,
    pub mesh_bytes_with_normals: f64,
    pub reading: Reading,
}

impl AtError {
    /// Read off `rows` at `error`, each mesh's error given by `of`.
    fn read(rows: &[MeshRow], error: f64, of: impl Fn(&Hausdorff) -> f64) -> Option<Self> {
        let series = |normals: bool| -> Vec<(u32, f64, f64)> {
            rows.iter()
                .map(|r| (r.cells, of(&r.hausdorff), r.bytes(normals) as f64))
                .collect()
        };
        let (mesh_bytes, reading) = bytes_at(&series(false), error)?;
        let (mesh_bytes_with_normals, _) = bytes_at(&series(true), error)?;
        Some(Self {
            error,
            mesh_bytes,
            mesh_bytes_with_normals,
            reading,
        })
    }
}

/// The larger side's 99th percentile: the error that 99 % of each side's samples are within.
pub fn p99(h: &Hausdorff) -> f64 {
    h.mesh_to_surface.p99.max(h.surface_to_mesh.p99)
}

/// The one solid `scene` describes by functions.
fn the_solid(scene: &Scene, path: &std::path::Path) -> Result<Solid, String> {
    match scene.objects.as_slice() {
        [object] => Ok(object.solid.clone()),
        objects => Err(format!(
            "{}: datasize measures one free-form object; the scene has {}",
            path.display(),
            objects.len()
        )),
    }
}

/// Measures every cell count, writes the CSV, the table and the plot; returns the table.
pub fn run(options: &DatasizeOptions) -> Result<String, String> {
    let scene = fray_scene::load(&options.scene).map_err(|e| e.to_string())?;
    let solid = the_solid(&scene, &options.scene)?;
    let bounds = solid.bounds();
    if !bounds.is_finite() || bounds.is_empty() {
        return Err(format!(
            "{}: the free form has no finite box",
            options.scene.display()
        ));
    }
    let model = model_bytes(&scene);
    let footprint = pixel_footprint(&scene.camera, &bounds, ROWS)?;
    let budget = MemoryBudget::from_env().map_err(|e| e.to_string())?;
    let surface = hausdorff::Surface::new(&solid, options.sampling.eps_share);
    let start = Instant::now();
    let points = surface.samples(&options.sampling);
    let sampled = start.elapsed();
    eprintln!(
        "{} surface samples in {:.1} s",
        points.len(),
        sampled.as_secs_f64()
    );
    let mut rows = Vec::new();
    let mut cells = options.cells.clone();
    cells.sort_unstable();
    cells.dedup();
    for &n in &cells {
        let start = Instant::now();
        let mesh =
            fray_geometry::polygonise(&[&solid], bounds, n, &budget).map_err(|e| e.to_string())?;
        let polygonise = start.elapsed();
        let h = hausdorff::measure(&surface, &points, &mesh, &options.sampling);
        let row = MeshRow {
            cells: n,
            cell_size: (bounds.max - bounds.min).max_element() / f64::from(n),
            vertices: mesh.positions.len(),
            triangles: mesh.triangles.len(),
            hausdorff: h,
            polygonise,
        };
        eprintln!(
            "{n} cells: {} triangles, Hausdorff {:.3e} (a {:.3e} at {:.3}, b {:.3e} at {:.3}), \
             {:.1} + {:.1} + {:.1} s",
            row.triangles,
            h.two_sided(),
            h.mesh_to_surface.max,
            h.mesh_to_surface.worst,
            h.surface_to_mesh.max,
            h.surface_to_mesh.worst,
            row.polygonise.as_secs_f64(),
            h.mesh_to_surface.time.as_secs_f64(),
            h.surface_to_mesh.time.as_secs_f64(),
        );
        rows.push(row);
    }
    let by_max = AtError::read(&rows, footprint.pixel, Hausdorff::two_sided);
    let by_p99 = AtError::read(&rows, footprint.pixel, p99);
    let diagonal = bounds.diagonal();
    let context = Context {
        scene: options
            .scene
            .file_name()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        model,
        diagonal,
        footprint,
        by_max,
        by_p99,
        sampling: options.sampling,
        surface_samples: (points.len(), sampled),
    };
    std::fs::create_dir_all(&options.out)
        .map_err(|e| format!("cannot create {}: {e}", options.out.display()))?;
    let write = |name: &str, text: &str| {
        let path = options.out.join(name);
        std::fs::write(&path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
    };
    write("datasize.csv", &csv(&rows, &context))?;
    let md = markdown(&rows, &context);
    write("datasize.md", &md)?;
    let plot = Plot {
        scene: options
            .scene
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned()),
        meshes: rows
            .iter()
            .map(|r| PlotMesh {
                error: r.hausdorff.two_sided(),
                p99: p99(&r.hausdorff),
                bytes: r.bytes(false),
                bytes_with_normals: r.bytes(true),
            })
            .collect(),
        model_gpu: model.gpu,
        model_f64: model.f64,
        pixel: footprint.pixel,
        at_pixel: by_max.map(|h| {
            let extrapolated = matches!(h.reading, Reading::Extrapolated { .. });
            (h.mesh_bytes, extrapolated)
        }),
    };
    let mut dirs = vec![options.out.clone()];
    dirs.extend(options.docs.clone());
    for dir in dirs {
        datasize_plot::write(&plot, &dir.join("datasize.svg"), &dir.join("datasize.png"))?;
    }
    Ok(md)
}

/// What the tables say besides the rows.
#[derive(Clone, Debug)]
struct Context {
    scene: String,
    model: ModelBytes,
    diagonal: f64,
    footprint: Footprint,
    /// The mesh's size at one pixel of two-sided Hausdorff error (the headline) and at one
    /// pixel of the sides' 99th percentile.
    by_max: Option<AtError>,
    by_p99: Option<AtError>,
    sampling: Sampling,
    /// The surface samples of (b) and what casting them took.
    surface_samples: (usize, Duration),
}

/// One row per mesh; the model's sizes and the footprint in every row, so each stands alone.
fn csv(rows: &[MeshRow], c: &Context) -> String {
    let mut s = String::from(
        "scene,cells,cell_size_m,vertices,triangles,mesh_bytes,mesh_bytes_with_normals,\
         a_samples,a_max_m,a_p99_m,b_samples,b_max_m,b_p99_m,hausdorff_m,hausdorff_rel_diagonal,\
         model_gpu_bytes,model_f64_bytes,pixel_1080p_m,polygonise_s,a_s,b_s\n",
    );
    for r in rows {
        let h = &r.hausdorff;
        let _ = writeln!(
            s,
            "{},{},{:.6},{},{},{},{},{},{:.6e},{:.6e},{},{:.6e},{:.6e},{:.6e},{:.6e},{},{},{:.6e},{:.3},{:.3},{:.3}",
            c.scene,
            r.cells,
            r.cell_size,
            r.vertices,
            r.triangles,
            r.bytes(false),
            r.bytes(true),
            h.mesh_to_surface.samples,
            h.mesh_to_surface.max,
            h.mesh_to_surface.p99,
            h.surface_to_mesh.samples,
            h.surface_to_mesh.max,
            h.surface_to_mesh.p99,
            h.two_sided(),
            h.two_sided() / c.diagonal,
            c.model.gpu,
            c.model.f64,
            c.footprint.pixel,
            r.polygonise.as_secs_f64(),
            h.mesh_to_surface.time.as_secs_f64(),
            h.surface_to_mesh.time.as_secs_f64(),
        );
    }
    s
}

/// Bytes in kB, MB or GB (decimal), three decimals.
fn size(bytes: f64) -> String {
    if bytes >= 1e9 {
        format!("{:.3} GB", bytes / 1e9)
    } else if bytes >= 1e6 {
        format!("{:.3} MB", bytes / 1e6)
    } else {
        format!("{:.3} kB", bytes / 1e3)
    }
}

/// A ratio to three significant figures, with thin spaces between thousands: `410 000×`.
pub fn times(ratio: f64) -> String {
    if !ratio.is_finite() || ratio <= 0.0 {
        return format!("{ratio}×");
    }
    let digits = ratio.log10().floor() as i32;
    let step = 10f64.powi((digits - 2).max(0));
    let rounded = ((ratio / step).round() * step) as u64;
    let text = rounded.to_string();
    let mut out = String::new();
    for (i, ch) in text.chars().enumerate() {
        if i > 0 && (text.len() - i).is_multiple_of(3) {
            out.push('\u{2009}');
        }
        out.push(ch);
    }
    out + "×"
}

/// A length in mm, three figures.
fn mm(metres: f64) -> String {
    let v = metres * 1e3;
    if v >= 100.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

/// The table, the model's sizes, the footprint and the headline ratio.
fn markdown(rows: &[MeshRow], c: &Context) -> String {
    let mut s = String::new();
    let m = &c.model;
    let _ = writeln!(
        s,
        "Functional model ({}): {} solid(s), {} leaves, {} perturbations, {} program words — \
         **{} bytes** as the GPU holds it (f32 `GpuSolid`/`GpuLeaf`/`GpuPerturbation` arrays and \
         the program), {} bytes as unpadded f64.\n",
        c.scene, m.solids, m.leaves, m.perturbations, m.program_words, m.gpu, m.f64
    );
    let p = &c.sampling;
    let _ = writeln!(
        s,
        "Hausdorff distances in mm (box diagonal {:.3} m). (a) mesh → surface: each triangle's \
         vertices, edge midpoints, centroid and {} random points, each bounded from above by \
         the nearest hit along ±∇F and ± the triangle's normal (and its corners' bounds plus \
         their distance), those that decide the max and p99 refined along {} more directions; \
         (b) surface → mesh: every surface crossing of {} directions × {}² parallel rays ({} \
         points, cast once in {:.1} s), each one's exact distance to the mesh. Caster ε = \
         {:.0e} × diagonal.\n",
        c.diagonal,
        p.random_per_triangle,
        hausdorff::REFINE_DIRECTIONS,
        p.directions,
        p.rays_across,
        c.surface_samples.0,
        c.surface_samples.1.as_secs_f64(),
        p.eps_share
    );
    s.push_str(
        "| cells | cell (mm) | vertices | triangles | mesh | mesh + normals | (a) max | (a) p99 | \
         (b) max | (b) p99 | Hausdorff | / diagonal | time (s): polygonise, (a), (b) |\n",
    );
    s.push_str("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for r in rows {
        let h = &r.hausdorff;
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | **{}** | {:.2e} | {:.1}, {:.1}, {:.1} |",
            r.cells,
            mm(r.cell_size),
            r.vertices,
            r.triangles,
            size(r.bytes(false) as f64),
            size(r.bytes(true) as f64),
            mm(h.mesh_to_surface.max),
            mm(h.mesh_to_surface.p99),
            mm(h.surface_to_mesh.max),
            mm(h.surface_to_mesh.p99),
            mm(h.two_sided()),
            h.two_sided() / c.diagonal,
            r.polygonise.as_secs_f64(),
            h.mesh_to_surface.time.as_secs_f64(),
            h.surface_to_mesh.time.as_secs_f64(),
        );
    }
    let f = &c.footprint;
    let _ = writeln!(
        s,
        "\nOne pixel at 1920×1080 from the scene's camera: {} mm at {:.3} m (the nearest point \
         of the model's box to the eye).",
        mm(f.pixel),
        f.distance
    );
    let reading = |r: Reading| match r {
        Reading::Interpolated(a, b) => format!("interpolated log-log between {a} and {b} cells"),
        Reading::Extrapolated {
            first,
            last,
            exponent,
        } => format!(
            "**extrapolated** on the least-squares log-log line through the meshes of {first} \
             to {last} cells (bytes ∝ error^{exponent:.2}): no measured mesh is that accurate"
        ),
        Reading::Coarsest(n) => {
            format!("the coarsest mesh ({n} cells) already meets it: an upper bound")
        }
    };
    for (at, what) in [
        (&c.by_max, "Hausdorff error (the larger side's maximum)"),
        (&c.by_p99, "99th-percentile error (the larger side's)"),
    ] {
        match at {
            Some(h) => {
                let _ = writeln!(
                    s,
                    "\nA mesh with a {what} of one pixel: {} ({} with normals), {}. **Ratio \
                     {} ({} with normals)** against the functional model's {} bytes.",
                    size(h.mesh_bytes),
                    size(h.mesh_bytes_with_normals),
                    reading(h.reading),
                    times(h.mesh_bytes / m.gpu as f64),
                    times(h.mesh_bytes_with_normals / m.gpu as f64),
                    m.gpu
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "\nNo mesh size could be read off at one pixel of {what}."
                );
            }
        }
    }
    if let Some(finest) = rows.last() {
        let h = finest.hausdorff.two_sided();
        let _ = writeln!(
            s,
            "\nMeasured, without extrapolation: the finest mesh ({} cells) is {} ({} the \
             model) at {:.1} pixels of Hausdorff error.",
            finest.cells,
            size(finest.bytes(false) as f64),
            times(finest.bytes(false) as f64 / m.gpu as f64),
            h / f.pixel
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use fray_core::Projector;

    /// A solid of two leaves (one perturbed) in a clear and in a transmissive material: the
    /// arrays' sizes by hand, and the complement's words for the glass one.
    #[test]
    fn a_small_scene_counts_its_bytes() {
        let source = |material: &str| {
            format!(
                r#"Scene(
  materials: {{ "glass": (transmit: (0.9, 0.9, 0.9), ior: 1.5), "paint": (diffuse: (0.5, 0.5, 0.5)) }},
  objects: [
    (name: "pair", material: "{material}", shape: Union([
      FreeForm(base: Ellipsoid(center: (0, 0, 0), radii: (1, 1, 1)),
               perturbations: [(form_factor: 0.5, quadric: Ellipsoid(center: (1, 0, 0), radii: (0.5, 0.5, 0.5)))]),
      Sphere(center: (2, 0, 0), radius: 1),
    ])),
  ],
)"#
            )
        };
        let paint = fray_scene::parse(&source("paint"), "pair.ron").unwrap();
        let bytes = model_bytes(&paint);
        assert_eq!(
            (
                bytes.solids,
                bytes.leaves,
                bytes.perturbations,
                bytes.program_words
            ),
            (1, 2, 1, 3)
        );
        // GpuSolid 64, GpuLeaf 112, GpuPerturbation 80 bytes; three program words.
        assert_eq!(bytes.gpu, 64 + 2 * 112 + 80 + 3 * 4);
        assert_eq!(bytes.f64, 68 + 2 * 168 + 112 + 3 * 4);
        let glass = fray_scene::parse(&source("glass"), "pair.ron").unwrap();
        let with_complement = model_bytes(&glass);
        assert_eq!(with_complement.program_words, 3 + 4);
        assert_eq!(with_complement.gpu, bytes.gpu + 4 * 4);
    }

    /// The turboprop's camera: the nearest box point, and the pixel from the field of view.
    #[test]
    fn the_footprint_follows_the_camera() {
        let camera = Projector::Pinhole(
            fray_core::Pinhole::new(
                glam::DVec3::new(0.0, 0.0, 10.0),
                glam::DVec3::ZERO,
                glam::DVec3::Y,
                90f64.to_radians(),
                0.05,
            )
            .unwrap(),
        );
        let b = Aabb::new(glam::DVec3::splat(-1.0), glam::DVec3::splat(1.0));
        let f = pixel_footprint(&camera, &b, 1000).unwrap();
        assert!((f.distance - 9.0).abs() < 1e-12);
        assert!((f.pixel - 9.0 * 2.0 / 1000.0).abs() < 1e-12);
        let inside = Aabb::new(glam::DVec3::splat(-20.0), glam::DVec3::splat(20.0));
        assert!(pixel_footprint(&camera, &inside, 1000).is_err());
    }

    #[test]
    fn ratios_keep_three_figures() {
        assert_eq!(times(410_173.4), "410\u{2009}000×");
        assert_eq!(times(4563.2), "4\u{2009}560×");
        assert_eq!(times(98.76), "99×");
        assert_eq!(times(1.234), "1×");
    }

    /// On a power law `bytes = k · error⁻²` the log-log reading is exact, between brackets and
    /// beyond the finest mesh; a coarsest mesh that meets the error is the answer as it stands.
    #[test]
    fn sizes_are_read_off_log_log() {
        let law = |e: f64| 3.0e3 * e.powi(-2);
        let points: Vec<(u32, f64, f64)> = [(40, 0.1), (80, 0.05), (160, 0.02)]
            .map(|(n, e)| (n, e, law(e)))
            .to_vec();
        let (b, how) = bytes_at(&points, 0.07).unwrap();
        assert!((b / law(0.07) - 1.0).abs() < 1e-12);
        assert_eq!(how, Reading::Interpolated(40, 80));
        let (b, how) = bytes_at(&points, 0.005).unwrap();
        assert!((b / law(0.005) - 1.0).abs() < 1e-12);
        let Reading::Extrapolated {
            first: 40,
            last: 160,
            exponent,
        } = how
        else {
            panic!("{how:?}")
        };
        assert!((exponent + 2.0).abs() < 1e-12);
        assert_eq!(
            bytes_at(&points, 0.5),
            Some((law(0.1), Reading::Coarsest(40)))
        );
        assert_eq!(bytes_at(&points[..1], 0.01), None);
        // Not monotone: the first mesh at or below the error closes the bracket.
        let bumpy = vec![(40, 0.1, 1e3), (80, 0.12, 2e3), (160, 0.03, 8e3)];
        assert_eq!(
            bytes_at(&bumpy, 0.05).unwrap().1,
            Reading::Interpolated(80, 160)
        );
        // Past the finest, the least-squares line through the finest three only (the coarsest,
        // far off the line, is left out): points off `ln b = 2 − ln e` by +0.1, 0 and −0.1 tilt
        // it; the normal equations by hand give where it reaches e = 0.1.
        let noisy = [(10, 1.0, 0.1), (20, 0.5, 0.0), (40, 0.25, -0.1)]
            .map(|(n, e, d): (u32, f64, f64)| (n, e, (2.0 - e.ln() + d).exp()));
        let mut four = vec![(5, 9.0, 1.0)];
        four.extend(noisy);
        let (b, how) = bytes_at(&four, 0.1).unwrap();
        assert!(matches!(
            how,
            Reading::Extrapolated {
                first: 10,
                last: 40,
                ..
            }
        ));
        let xs = noisy.map(|p| p.1.ln());
        let ys = noisy.map(|p| p.2.ln());
        let (mx, my) = (xs.iter().sum::<f64>() / 3.0, ys.iter().sum::<f64>() / 3.0);
        let k = xs
            .iter()
            .zip(ys)
            .map(|(x, y)| (x - mx) * (y - my))
            .sum::<f64>()
            / xs.iter().map(|x| (x - mx) * (x - mx)).sum::<f64>();
        let expected = (my + k * (0.1f64.ln() - mx)).exp();
        assert!((b / expected - 1.0).abs() < 1e-12, "{b} vs {expected}");
        let fitted = (2.0 - 0.1f64.ln()).exp();
        assert!((b / fitted - 1.0).abs() > 1e-3, "the residuals move it");
    }
}
