//! The data-size plot: bytes against Hausdorff error, both on log axes — the meshes as points on
//! a line (with and without normals), the functional model as a horizontal line at its size, the
//! 1080p pixel as a vertical line — drawn once per backend as SVG and PNG with the repository's
//! font (`xtask/fonts`).

use crate::plot_font::{FONT, register_font};
use plotters::prelude::*;
use std::path::Path;

/// What the plot shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Plot {
    /// The scene's name, for the caption.
    pub scene: String,
    pub meshes: Vec<PlotMesh>,
    pub model_gpu: usize,
    pub model_f64: usize,
    /// One pixel's footprint at 1080p (m).
    pub pixel: f64,
    /// The mesh's bytes read off at that error, and whether they were extrapolated (drawn as a
    /// dotted line from the finest mesh).
    pub at_pixel: Option<(f64, bool)>,
}

/// One mesh's point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlotMesh {
    /// Two-sided Hausdorff error (m).
    pub error: f64,
    /// The larger side's 99th percentile (m).
    pub p99: f64,
    pub bytes: usize,
    pub bytes_with_normals: usize,
}

const SIZE: (u32, u32) = (960, 640);
/// Writes the plot to `svg` and `png`.
pub fn write(plot: &Plot, svg: &Path, png: &Path) -> Result<(), String> {
    register_font()?;
    draw(plot, SVGBackend::new(svg, SIZE).into_drawing_area())
        .map_err(|e| format!("cannot draw {}: {e}", svg.display()))?;
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    draw(
        plot,
        BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area(),
    )
    .map_err(|e| format!("cannot draw {}: {e}", png.display()))?;
    image::save_buffer(png, &rgb, SIZE.0, SIZE.1, image::ExtendedColorType::Rgb8)
        .map_err(|e| format!("cannot write {}: {e}", png.display()))
}

/// The axes' ranges: every point and line with a margin, whole decades.
fn ranges(plot: &Plot) -> ((f64, f64), (f64, f64)) {
    let errors = plot
        .meshes
        .iter()
        .flat_map(|m| [m.error, m.p99])
        .chain([plot.pixel]);
    let bytes = plot
        .meshes
        .iter()
        .flat_map(|m| [m.bytes as f64, m.bytes_with_normals as f64])
        .chain([plot.model_gpu as f64, plot.model_f64 as f64])
        .chain(plot.at_pixel.map(|a| a.0));
    let span = |values: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = values
            .filter(|v| v.is_finite() && *v > 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        if lo > hi {
            return (1.0, 10.0);
        }
        (
            10f64.powf(lo.log10().floor()),
            10f64.powf(hi.log10().ceil()),
        )
    };
    (span(&mut { errors }), span(&mut { bytes }))
}

fn draw<DB: DrawingBackend>(
    plot: &Plot,
    root: DrawingArea<DB, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let ((x0, x1), (y0, y1)) = ranges(plot);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{}: bytes against two-sided Hausdorff error", plot.scene),
            (FONT, 22),
        )
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(90)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("Hausdorff error (m)")
        .y_desc("bytes")
        .label_style((FONT, 15))
        .axis_desc_style((FONT, 17))
        .x_label_formatter(&|x| format!("{x:.0e}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()?;
    let mesh = RGBColor(31, 119, 180);
    let normals = RGBColor(255, 127, 14);
    let model = RGBColor(44, 160, 44);
    let series = |pick: fn(&PlotMesh) -> (f64, usize)| -> Vec<(f64, f64)> {
        plot.meshes
            .iter()
            .map(|m| {
                let (e, b) = pick(m);
                (e, b as f64)
            })
            .collect()
    };
    let faint = mesh.mix(0.35);
    chart
        .draw_series(DashedLineSeries::new(
            series(|m| (m.p99, m.bytes)),
            6,
            4,
            faint.stroke_width(1),
        ))?
        .label("the mesh against its 99th-percentile error")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], faint.stroke_width(1)));
    chart.draw_series(PointSeries::of_element(
        series(|m| (m.p99, m.bytes)),
        3,
        faint.filled(),
        &|c, s, st| Circle::new(c, s, st),
    ))?;
    for (points, colour, label) in [
        (
            series(|m| (m.error, m.bytes)),
            mesh,
            "indexed f32 mesh (positions + u32 indices)",
        ),
        (
            series(|m| (m.error, m.bytes_with_normals)),
            normals,
            "the same with f32 normals",
        ),
    ] {
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(PointSeries::of_element(
            points,
            5,
            colour.filled(),
            &|c, s, st| Circle::new(c, s, st),
        ))?;
    }
    for (bytes, style, label) in [
        (
            plot.model_gpu as f64,
            model.stroke_width(3),
            format!("functional model, GPU arrays ({} B)", plot.model_gpu),
        ),
        (
            plot.model_f64 as f64,
            model.mix(0.5).stroke_width(2),
            format!("functional model, f64 ({} B)", plot.model_f64),
        ),
    ] {
        chart
            .draw_series(LineSeries::new([(x0, bytes), (x1, bytes)], style))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
    }
    chart.draw_series(PointSeries::of_element(
        [(plot.pixel, plot.model_gpu as f64)],
        8,
        model.filled(),
        &|c, s, st| TriangleMarker::new(c, s, st),
    ))?;
    let grey = RGBColor(120, 120, 120);
    chart
        .draw_series(LineSeries::new(
            [(plot.pixel, y0), (plot.pixel, y1)],
            grey.stroke_width(1),
        ))?
        .label(format!("one pixel at 1080p ({:.1} mm)", plot.pixel * 1e3))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(1)));
    if let Some((bytes, extrapolated)) = plot.at_pixel {
        if let (true, Some(finest)) = (extrapolated, plot.meshes.last()) {
            chart.draw_series(DashedLineSeries::new(
                [(finest.error, finest.bytes as f64), (plot.pixel, bytes)],
                2,
                5,
                mesh.stroke_width(2),
            ))?;
        }
        let how = if extrapolated { " (extrapolated)" } else { "" };
        chart
            .draw_series(PointSeries::of_element(
                [(plot.pixel, bytes)],
                7,
                mesh.stroke_width(2),
                &|c, s, st| Cross::new(c, s, st),
            ))?
            .label(format!(
                "mesh at one pixel{how}: {} the model",
                crate::datasize::times(bytes / plot.model_gpu as f64)
            ))
            .legend(move |(x, y)| Cross::new((x + 10, y), 5, mesh.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 14))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both files are written, the SVG names the series and the PNG decodes to the plot's size
    /// with more than the background in it (the font rasterised text and lines drawn).
    #[test]
    fn the_plot_writes_svg_and_png() {
        let dir = std::env::temp_dir().join(format!("fray-datasize-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let plot = Plot {
            scene: "test".into(),
            meshes: vec![
                PlotMesh {
                    error: 0.1,
                    p99: 0.02,
                    bytes: 20_000,
                    bytes_with_normals: 30_000,
                },
                PlotMesh {
                    error: 0.03,
                    p99: 0.004,
                    bytes: 200_000,
                    bytes_with_normals: 300_000,
                },
            ],
            model_gpu: 6_000,
            model_f64: 10_000,
            pixel: 0.005,
            at_pixel: Some((2.0e6, true)),
        };
        let (svg, png) = (dir.join("p.svg"), dir.join("p.png"));
        write(&plot, &svg, &png).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(
            text.contains("functional model, GPU arrays (6000 B)"),
            "{text}"
        );
        let image = image::open(&png).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), SIZE);
        let dark = image
            .pixels()
            .filter(|p| p.0.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 1000, "{dark}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
