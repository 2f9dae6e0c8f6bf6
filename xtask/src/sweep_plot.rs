//! Time against error for one sweep of a method's knob: the settings as labelled points on log
//! axes with the Pareto front drawn and the default setting marked (SVG and PNG, the font in
//! `xtask/fonts`), the same rows as CSV, and the Markdown summary row `docs/accuracy.md` tables.
//! Besides, [`LinePlot`]: a cost against a size (time against map size, screen size, distance)
//! as lines on the same log axes, for the sweeps whose knob changes no error.

use crate::plot_font::{FONT, register_font};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The relative error `docs/accuracy.md`'s tables ask the fastest setting to stay within.
pub const WITHIN: f64 = 1e-4;

/// One setting of the knob: its time and its error against the method's reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub label: String,
    /// Median wall time (ms) of what the sweep times (a frame, a ray set).
    pub time_ms: f64,
    /// Relative error against the reference (0: none measured).
    pub error: f64,
    /// Rays that hit in one and miss in the other (not in `error`; a setting with any is never
    /// "within" a bound).
    pub flips: usize,
}

impl Setting {
    pub fn new(label: impl Into<String>, time_ms: f64, error: f64) -> Self {
        Self {
            label: label.into(),
            time_ms,
            error,
            flips: 0,
        }
    }
}

/// One method's sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// File stem of its CSV and plots (`target/bench/<name>.{csv,svg,png}`).
    pub name: String,
    /// The method, for captions and tables.
    pub method: String,
    /// What `error` is (the y axis).
    pub error_desc: String,
    /// What `time_ms` times (the x axis).
    pub time_desc: String,
    pub settings: Vec<Setting>,
    /// Index of the method's default setting, when the sweep contains it.
    pub default: Option<usize>,
}

/// Whether `a` dominates `b`: no slower, no less accurate, and better in one of the two.
fn dominates(a: &Setting, b: &Setting) -> bool {
    a.time_ms <= b.time_ms && a.error <= b.error && (a.time_ms < b.time_ms || a.error < b.error)
}

/// The Pareto front: the settings no other setting dominates (both no slower and no less
/// accurate, better in one), by index, fastest first.
pub fn pareto_front(settings: &[Setting]) -> Vec<usize> {
    let mut front: Vec<usize> = (0..settings.len())
        .filter(|&i| !settings.iter().any(|o| dominates(o, &settings[i])))
        .collect();
    front.sort_by(|&a, &b| settings[a].time_ms.total_cmp(&settings[b].time_ms));
    front
}

/// The fastest setting whose error is at most `bound` and that flips no ray.
pub fn fastest_within(settings: &[Setting], bound: f64) -> Option<usize> {
    (0..settings.len())
        .filter(|&i| settings[i].error <= bound && settings[i].flips == 0)
        .min_by(|&a, &b| settings[a].time_ms.total_cmp(&settings[b].time_ms))
}

impl Sweep {
    /// The CSV: one row per setting, with whether it is on the front and the default.
    pub fn csv(&self) -> String {
        let front = pareto_front(&self.settings);
        let mut s = String::from("setting,time_ms,error,flips,pareto,default\n");
        for (i, r) in self.settings.iter().enumerate() {
            let _ = writeln!(
                s,
                "\"{}\",{:.4},{:e},{},{},{}",
                r.label.replace('"', "'"),
                r.time_ms,
                r.error,
                r.flips,
                front.contains(&i),
                self.default == Some(i)
            );
        }
        s
    }

    /// The Markdown table of `docs/accuracy.md`: the default's time and error, and the fastest
    /// setting within [`WITHIN`].
    pub fn summary(&self) -> String {
        let cell = |i: Option<usize>| match i {
            Some(i) => {
                let r = &self.settings[i];
                format!("{} | {:.3} | {:.1e}", r.label, r.time_ms, r.error)
            }
            None => "none | | ".into(),
        };
        format!(
            "| {} | {} | {} |\n",
            self.method,
            cell(self.default),
            cell(fastest_within(&self.settings, WITHIN))
        )
    }

    /// Writes `<name>.csv`, `<name>.svg` and `<name>.png` under `dir`; returns the paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, String> {
        write_files(self, &self.name, &self.csv(), dir)
    }
}

/// The header of [`Sweep::summary`]'s rows.
pub fn summary_header() -> String {
    format!(
        "| method | default | time ms | error | fastest within {WITHIN:.0e} | time ms | error |\n\
         |---|---|---:|---:|---|---:|---:|\n"
    )
}

/// One line of a [`LinePlot`]: its legend and its points `(x, y)`, x increasing, each with a
/// label beside it (none where `point_labels` is shorter).
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub point_labels: Vec<String>,
}

/// A cost against a size: lines through each series' points on log axes.
#[derive(Clone, Debug, PartialEq)]
pub struct LinePlot {
    /// File stem of its CSV and plots (`<name>.{csv,svg,png}`).
    pub name: String,
    pub title: String,
    pub x_desc: String,
    pub y_desc: String,
    pub series: Vec<Series>,
}

impl LinePlot {
    /// The CSV: one row per point, `series,x,y`.
    pub fn csv(&self) -> String {
        let mut s = String::from("series,x,y\n");
        for line in &self.series {
            for (x, y) in &line.points {
                let _ = writeln!(s, "\"{}\",{x},{y:.4}", line.label.replace('"', "'"));
            }
        }
        s
    }

    /// Writes `<name>.csv`, `<name>.svg` and `<name>.png` under `dir`; returns the paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>, String> {
        write_files(self, &self.name, &self.csv(), dir)
    }
}

const SIZE: (u32, u32) = (900, 600);

/// A chart drawn alike on the SVG and the bitmap backend.
trait Chart {
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>>;
}

impl Chart for Sweep {
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        draw(self, root)
    }
}

impl Chart for LinePlot {
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        draw_lines(self, root)
    }
}

/// Writes `csv` as `<name>.csv` and `chart` as `<name>.svg` and `<name>.png` under `dir`;
/// returns the paths.
fn write_files(
    chart: &impl Chart,
    name: &str,
    csv: &str,
    dir: &Path,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let [csv_path, svg, png] = ["csv", "svg", "png"].map(|e| dir.join(format!("{name}.{e}")));
    std::fs::write(&csv_path, csv)
        .map_err(|e| format!("cannot write {}: {e}", csv_path.display()))?;
    write_plot(chart, &svg, &png)?;
    Ok(vec![csv_path, svg, png])
}

fn write_plot(chart: &impl Chart, svg: &Path, png: &Path) -> Result<(), String> {
    register_font()?;
    chart
        .draw(SVGBackend::new(svg, SIZE).into_drawing_area())
        .map_err(|e| format!("cannot draw {}: {e}", svg.display()))?;
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    chart
        .draw(BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area())
        .map_err(|e| format!("cannot draw {}: {e}", png.display()))?;
    image::save_buffer(png, &rgb, SIZE.0, SIZE.1, image::ExtendedColorType::Rgb8)
        .map_err(|e| format!("cannot write {}: {e}", png.display()))
}

/// The range of the positive finite values widened by the factors `margin` (a log axis).
fn span(values: impl Iterator<Item = f64>, margin: (f64, f64)) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if lo > hi {
        return (1.0, 10.0);
    }
    (lo / margin.0, hi * margin.1)
}

/// Ticks on a log axis over `lo..hi`: 1, 2, 5 per decade, or every digit where that leaves
/// fewer than three (a range under a decade gets no decade tick of its own).
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let decades = lo.log10().floor() as i32..=hi.log10().ceil() as i32;
    let pick = |mantissas: &[f64]| -> Vec<f64> {
        decades
            .clone()
            .flat_map(|d| mantissas.iter().map(move |m| m * 10f64.powi(d)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let ticks = pick(&[1.0, 2.0, 5.0]);
    if ticks.len() >= 3 {
        ticks
    } else {
        pick(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0])
    }
}

/// A tick label: three significant digits, plain where that is short.
fn tick(v: &f64) -> String {
    if (1e-2..1e4).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

fn draw<DB: DrawingBackend>(
    sweep: &Sweep,
    root: DrawingArea<DB, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let s = &sweep.settings;
    let (x0, x1) = span(s.iter().map(|r| r.time_ms), (1.3, 2.5));
    let (mut y0, y1) = span(s.iter().map(|r| r.error).chain([WITHIN]), (3.0, 3.0));
    // Settings with no error measured (0) sit on a floor a decade below the rest.
    if s.iter().any(|r| r.error <= 0.0) {
        y0 /= 10.0;
    }
    let at = |r: &Setting| (r.time_ms, if r.error > 0.0 { r.error } else { y0 });
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{}: time against error", sweep.method), (FONT, 20))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(log_ticks(x0, x1)),
            (y0..y1).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc(&sweep.time_desc)
        .y_desc(&sweep.error_desc)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .x_label_formatter(&tick)
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()?;
    let grey = RGBColor(120, 120, 120);
    let front_colour = RGBColor(31, 119, 180);
    let default_colour = RGBColor(214, 39, 40);
    chart
        .draw_series(DashedLineSeries::new(
            [(x0, WITHIN), (x1, WITHIN)],
            6,
            4,
            grey.stroke_width(1),
        ))?
        .label(format!("relative error {WITHIN:.0e}"))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.stroke_width(1)));
    let front = pareto_front(s);
    chart
        .draw_series(LineSeries::new(
            front.iter().map(|&i| at(&s[i])),
            front_colour.stroke_width(2),
        ))?
        .label("Pareto front")
        .legend(move |(x, y)| {
            PathElement::new(vec![(x, y), (x + 20, y)], front_colour.stroke_width(2))
        });
    chart.draw_series(s.iter().enumerate().map(|(i, r)| {
        let style = if front.contains(&i) {
            front_colour.filled()
        } else {
            grey.filled()
        };
        let label = if r.error > 0.0 {
            r.label.clone()
        } else {
            format!("{} (error 0)", r.label)
        };
        // Neighbouring settings often sit close: their labels alternate above and below.
        let dy = if i % 2 == 0 { -16 } else { 4 };
        EmptyElement::at(at(r))
            + Circle::new((0, 0), 4, style)
            + Text::new(label, (7, dy), (FONT, 13).into_font())
    }))?;
    if let Some(d) = sweep.default {
        chart
            .draw_series([Circle::new(at(&s[d]), 9, default_colour.stroke_width(2))])?
            .label(format!("default: {}", s[d].label))
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, default_colour.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()
}

/// Colours of a [`LinePlot`]'s series, in order (then again).
const PALETTE: [RGBColor; 5] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
];

fn draw_lines<DB: DrawingBackend>(
    plot: &LinePlot,
    root: DrawingArea<DB, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let points = || plot.series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = span(points().map(|p| p.0), (1.2, 1.2));
    let (y0, y1) = span(points().map(|p| p.1), (1.5, 1.5));
    // A few sizes swept (256² … 4096²): ticks at the sizes themselves.
    let mut xs: Vec<f64> = points().map(|p| p.0).filter(|x| *x > 0.0).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let x_ticks = if xs.len() <= 8 { xs } else { log_ticks(x0, x1) };
    let mut chart = ChartBuilder::on(&root)
        .caption(&plot.title, (FONT, 20))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(x_ticks),
            (y0..y1).log_scale().with_key_points(log_ticks(y0, y1)),
        )?;
    chart
        .configure_mesh()
        .x_desc(&plot.x_desc)
        .y_desc(&plot.y_desc)
        .label_style((FONT, 14))
        .axis_desc_style((FONT, 15))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .draw()?;
    for (i, line) in plot.series.iter().enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        chart
            .draw_series(LineSeries::new(
                line.points.iter().copied(),
                colour.stroke_width(2),
            ))?
            .label(&line.label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(line.points.iter().enumerate().map(|(k, &p)| {
            let label = line.point_labels.get(k).cloned().unwrap_or_default();
            EmptyElement::at(p)
                + Circle::new((0, 0), 4, colour.filled())
                + Text::new(label, (7, -14), (FONT, 12).into_font())
        }))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font((FONT, 13))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(points: &[(f64, f64)]) -> Vec<Setting> {
        points
            .iter()
            .enumerate()
            .map(|(i, &(t, e))| Setting::new(format!("s{i}"), t, e))
            .collect()
    }

    /// A hand-made set whose front is known: 0 (fastest), 2 and 4 (each slower and more
    /// accurate), 5 (the most accurate); 1 is dominated by 0 (slower, worse), 3 by 2 (same
    /// time, worse error), 6 by 4 (same error, slower); 7 equals 2 in both and is kept (nothing
    /// is better than it in either). A front taken by time order alone, by error alone, or
    /// with ties dropped or kept wrongly fails.
    #[test]
    fn the_front_is_the_undominated_settings_fastest_first() {
        let s = set(&[
            (1.0, 1e-2), // 0
            (2.0, 5e-2), // 1: dominated by 0
            (3.0, 1e-4), // 2
            (3.0, 1e-3), // 3: dominated by 2 (same time)
            (5.0, 1e-6), // 4
            (9.0, 1e-9), // 5
            (7.0, 1e-6), // 6: dominated by 4 (same error)
            (3.0, 1e-4), // 7: equal to 2
        ]);
        let front = pareto_front(&s);
        assert_eq!(front.len(), 5, "{front:?}");
        assert_eq!(front[0], 0);
        assert!(
            front[1..3].contains(&2) && front[1..3].contains(&7),
            "{front:?}"
        );
        assert_eq!(&front[3..], &[4, 5]);
        // Brute force against the definition: every dominated point is out, every other in.
        for i in 0..s.len() {
            let dominated = (0..s.len()).any(|j| {
                s[j].time_ms <= s[i].time_ms
                    && s[j].error <= s[i].error
                    && (s[j].time_ms, s[j].error) != (s[i].time_ms, s[i].error)
            });
            assert_eq!(front.contains(&i), !dominated, "setting {i}");
        }
        // The fastest within 1e-4 is 2 (3 ms), not 4 or 5; a flip disqualifies it.
        assert_eq!(fastest_within(&s, 1e-4), Some(2));
        let mut flipped = s.clone();
        flipped[2].flips = 1;
        flipped[7].flips = 1;
        assert_eq!(fastest_within(&flipped, 1e-4), Some(4));
        assert_eq!(fastest_within(&s, 1e-12), None);
    }

    /// Under a decade every digit is a tick; over several, 1–2–5.
    #[test]
    fn log_ticks_cover_short_and_long_ranges() {
        assert_eq!(
            log_ticks(150.0, 780.0),
            [200.0, 300.0, 400.0, 500.0, 600.0, 700.0]
        );
        assert_eq!(log_ticks(0.7, 30.0), [1.0, 2.0, 5.0, 10.0, 20.0]);
    }

    /// The files are written; the SVG labels every setting and the default; the PNG is the
    /// plot's size with text and lines in it; the CSV marks the front.
    #[test]
    fn the_sweep_writes_csv_svg_and_png() {
        let dir = std::env::temp_dir().join(format!("fray-sweep-plot-{}", std::process::id()));
        let mut settings = set(&[(1.0, 1e-2), (2.0, 5e-2), (4.0, 1e-5), (8.0, 0.0)]);
        settings[1].flips = 3;
        let sweep = Sweep {
            name: "t".into(),
            method: "test method".into(),
            error_desc: "relative error".into(),
            time_desc: "ms".into(),
            settings,
            default: Some(2),
        };
        sweep.write(&dir).unwrap();
        let svg = std::fs::read_to_string(dir.join("t.svg")).unwrap();
        for label in ["s0", "s1", "s2", "s3 (error 0)", "default: s2"] {
            assert!(svg.contains(label), "{label}");
        }
        let csv = std::fs::read_to_string(dir.join("t.csv")).unwrap();
        let pareto: Vec<&str> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(4).unwrap())
            .collect();
        assert_eq!(pareto, ["true", "false", "true", "true"]);
        let image = image::open(dir.join("t.png")).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), SIZE);
        let dark = image
            .pixels()
            .filter(|p| p.0.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 1000, "{dark}");
        assert!(
            sweep
                .summary()
                .contains("| s2 | 4.000 | 1.0e-5 | s2 | 4.000 | 1.0e-5 |")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The line plot writes its points as CSV rows and draws every series' legend; its PNG has
    /// the lines' colours in it.
    #[test]
    fn the_line_plot_writes_csv_svg_and_png() {
        let dir = std::env::temp_dir().join(format!("fray-line-plot-{}", std::process::id()));
        let plot = LinePlot {
            name: "l".into(),
            title: "cost against size".into(),
            x_desc: "size".into(),
            y_desc: "ms".into(),
            series: vec![
                Series {
                    label: "flat".into(),
                    points: vec![(256.0, 10.0), (1024.0, 11.0), (4096.0, 12.0)],
                    point_labels: vec!["first".into()],
                },
                Series {
                    label: "linear".into(),
                    points: vec![(256.0, 10.0), (1024.0, 40.0), (4096.0, 160.0)],
                    point_labels: Vec::new(),
                },
            ],
        };
        plot.write(&dir).unwrap();
        let csv = std::fs::read_to_string(dir.join("l.csv")).unwrap();
        assert_eq!(csv.lines().count(), 7);
        assert!(csv.contains("\"linear\",4096,160.0000"), "{csv}");
        let svg = std::fs::read_to_string(dir.join("l.svg")).unwrap();
        for label in ["flat", "linear", "cost against size", "first"] {
            assert!(svg.contains(label), "{label}");
        }
        let image = image::open(dir.join("l.png")).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), SIZE);
        for c in &PALETTE[..2] {
            let n = image.pixels().filter(|p| p.0 == [c.0, c.1, c.2]).count();
            assert!(n > 100, "{c:?}: {n} pixels");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
