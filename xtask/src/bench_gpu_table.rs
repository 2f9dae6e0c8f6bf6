//! `cargo xtask bench gpu`'s results and their tables: per scene and image size the median wall,
//! encode and kernel time of the timed frames and each pass's median, written as CSV (one row per
//! scene × size × pass, the adapter in columns) and Markdown (one table per size, scenes as rows,
//! passes as columns, ms); scenes the GPU refused are listed with the reason.

use std::fmt::Write as _;
use std::time::Duration;

/// The passes in the order a frame runs them (`fray_gpu`'s labels): the tables' column order.
/// A label not listed here follows them in the order first seen.
pub const PASS_ORDER: [&str; 9] = [
    "rebase",
    "raygen",
    "free forms",
    "terrains",
    "meshes",
    "shade",
    "whitted",
    "media",
    "resolve",
];

/// The adapter the frames ran on and how their passes were timed.
#[derive(Clone, Debug, PartialEq)]
pub struct Adapter {
    /// e.g. `"llvmpipe (LLVM 15.0.6, 256 bits)"`.
    pub name: String,
    /// e.g. `"Vulkan"`.
    pub backend: String,
    /// A software adapter (the host's CPU), whose figures are not GPU figures.
    pub software: bool,
    /// How passes were timed: `"timestamps"`, `"host clock"` or `"none"`.
    pub clock: String,
}

/// One timed frame's figures (`RenderStats`).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameTimes {
    /// Wall time of the `render` call (work list, encoding, the passes, readback).
    pub wall: Duration,
    /// The host's time to encode and submit the frame (`RenderStats::encode_time`).
    pub encode: Duration,
    /// The passes' total (`RenderStats::kernel_time`), where they were timed.
    pub kernel: Option<Duration>,
    /// Each pass's time (`RenderStats::pass_times`).
    pub passes: Vec<(String, Duration)>,
}

/// What became of one scene at one size.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// The timed frames (warm-up frames excluded), at least one.
    Timed(Vec<FrameTimes>),
    /// Not rendered: why (a device limit, an unsupported feature, a scene that would not load).
    Refused(String),
}

/// One scene at one size.
#[derive(Clone, Debug, PartialEq)]
pub struct Run {
    /// The scene's file stem.
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub outcome: Outcome,
}

/// A whole bench run.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuBench {
    pub adapter: Adapter,
    /// Frames rendered and discarded per scene and size before timing.
    pub warmup: usize,
    /// Frames timed per scene and size.
    pub frames: usize,
    pub runs: Vec<Run>,
}

/// The medians of a run's timed frames, in milliseconds.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub wall_ms: f64,
    pub encode_ms: f64,
    /// `None` where the passes were not timed.
    pub kernel_ms: Option<f64>,
    /// Each pass that ran in any timed frame, in [`PASS_ORDER`]: its median over the frames,
    /// counting 0 in a frame it did not run in.
    pub passes: Vec<(String, f64)>,
}

/// The median (the mean of the middle two for an even count); `None` for no values.
pub fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    values.sort_by(f64::total_cmp);
    let n = values.len();
    Some(if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    })
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Where `label` sorts among the pass columns.
fn pass_rank(label: &str) -> usize {
    PASS_ORDER
        .iter()
        .position(|p| *p == label)
        .unwrap_or(PASS_ORDER.len())
}

/// `labels` with new ones from `more` added, sorted by [`PASS_ORDER`] (unknown labels after,
/// in the order first seen).
fn merge_labels(labels: &mut Vec<String>, more: impl IntoIterator<Item = String>) {
    for label in more {
        if !labels.contains(&label) {
            labels.push(label);
        }
    }
    // A stable sort keeps the unknown labels in the order first seen.
    labels.sort_by_key(|l| pass_rank(l));
}

/// The medians of `frames`; `None` for no frames.
pub fn summarise(frames: &[FrameTimes]) -> Option<Summary> {
    let wall_ms = median(frames.iter().map(|f| ms(f.wall)).collect())?;
    let encode_ms = median(frames.iter().map(|f| ms(f.encode)).collect())?;
    let kernels: Vec<f64> = frames.iter().filter_map(|f| f.kernel.map(ms)).collect();
    let kernel_ms = if kernels.len() == frames.len() {
        median(kernels)
    } else {
        None
    };
    let mut labels = Vec::new();
    for f in frames {
        merge_labels(&mut labels, f.passes.iter().map(|(l, _)| l.clone()));
    }
    let passes = labels
        .into_iter()
        .map(|label| {
            let times = frames
                .iter()
                .map(|f| {
                    // From +0 (`sum` of no floats is −0, printed "-0.000").
                    f.passes
                        .iter()
                        .filter(|(l, _)| *l == label)
                        .fold(0.0, |t, (_, d)| t + ms(*d))
                })
                .collect();
            // `frames` is not empty here (the wall median exists).
            let m = median(times).unwrap_or(0.0);
            (label, m)
        })
        .collect();
    Some(Summary {
        wall_ms,
        encode_ms,
        kernel_ms,
        passes,
    })
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// The CSV header.
pub const CSV_HEADER: &str = "adapter,backend,software,clock,scene,width,height,status,warmup,frames,wall_ms,encode_ms,kernel_ms,pass,pass_ms,reason";

/// One row per scene × size × pass (the run's medians repeated on each of its rows); a refused
/// run, or one whose passes were not timed, is one row with the pass empty.
pub fn to_csv(bench: &GpuBench) -> String {
    let a = &bench.adapter;
    let mut s = format!("{CSV_HEADER}\n");
    let lead = format!(
        "{},{},{},{}",
        csv_field(&a.name),
        csv_field(&a.backend),
        a.software,
        csv_field(&a.clock)
    );
    for run in &bench.runs {
        let head = format!(
            "{lead},{},{},{}",
            csv_field(&run.scene),
            run.width,
            run.height
        );
        match &run.outcome {
            Outcome::Refused(reason) => {
                let _ = writeln!(
                    s,
                    "{head},refused,{},0,,,,,,{}",
                    bench.warmup,
                    csv_field(reason)
                );
            }
            Outcome::Timed(frames) => {
                let Some(sum) = summarise(frames) else {
                    continue;
                };
                let kernel = sum.kernel_ms.map(|k| format!("{k:.4}")).unwrap_or_default();
                let timed = format!(
                    "{head},timed,{},{},{:.4},{:.4},{kernel}",
                    bench.warmup,
                    frames.len(),
                    sum.wall_ms,
                    sum.encode_ms
                );
                if sum.passes.is_empty() {
                    let _ = writeln!(s, "{timed},,,");
                }
                for (label, m) in &sum.passes {
                    let _ = writeln!(s, "{timed},{},{m:.4},", csv_field(label));
                }
            }
        }
    }
    s
}

/// A Markdown table cell: `|` escaped, line breaks as spaces.
fn md_cell(s: &str) -> String {
    s.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// Milliseconds to three significant figures or so (at least 0.001 ms); the decimals chosen by
/// the rounded value (99.96 is "100", not "100.0").
fn fmt_ms(v: f64) -> String {
    if v >= 99.95 {
        format!("{v:.0}")
    } else if v >= 9.995 {
        format!("{v:.1}")
    } else if v >= 0.9995 {
        format!("{v:.2}")
    } else {
        format!("{v:.3}")
    }
}

/// `n` `thing`s, in words.
fn count(n: usize, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}

/// The sizes of the runs in the order first seen.
fn sizes(bench: &GpuBench) -> Vec<(u32, u32)> {
    let mut sizes = Vec::new();
    for run in &bench.runs {
        if !sizes.contains(&(run.width, run.height)) {
            sizes.push((run.width, run.height));
        }
    }
    sizes
}

/// How the passes were timed, in words.
fn clock_words(a: &Adapter) -> &'static str {
    match a.clock.as_str() {
        "host clock" => {
            "passes timed by the host's clock around each pass submitted alone and waited for"
        }
        "timestamps" => "passes timed by the device's timestamp queries",
        _ => "passes not timed (no timestamp queries on this device)",
    }
}

/// One table per size: a row per timed scene (frame, encode and kernel medians, then each pass
/// that ran at that size), then the refused scenes with their reasons.
pub fn to_markdown(bench: &GpuBench) -> String {
    let a = &bench.adapter;
    let mut s = format!(
        "# GPU frames pass by pass (`cargo xtask bench gpu`)\n\n\
         Adapter **{}** ({}{}); {}. Each scene uploaded once (resident); per size {} \
         discarded, then the median of {}, in ms. *frame*: the `render` \
         call's wall time; *encode*: the host's time to build the work list, write, encode and \
         submit (waits excluded); *kernels*: the passes' total.\n",
        md_cell(&a.name),
        md_cell(&a.backend),
        if a.software {
            ", software: the host's CPU — not GPU figures"
        } else {
            ""
        },
        clock_words(a),
        count(bench.warmup, "warm-up frame"),
        count(bench.frames, "timed frame"),
    );
    for (width, height) in sizes(bench) {
        let runs: Vec<&Run> = bench
            .runs
            .iter()
            .filter(|r| (r.width, r.height) == (width, height))
            .collect();
        let timed: Vec<(&Run, Summary)> = runs
            .iter()
            .filter_map(|r| match &r.outcome {
                Outcome::Timed(frames) => summarise(frames).map(|sum| (*r, sum)),
                Outcome::Refused(_) => None,
            })
            .collect();
        let mut labels = Vec::new();
        for (_, sum) in &timed {
            merge_labels(&mut labels, sum.passes.iter().map(|(l, _)| l.clone()));
        }
        let _ = write!(s, "\n## {width} × {height}\n\n");
        if timed.is_empty() {
            s.push_str("No scene was timed at this size.\n");
        } else {
            s.push_str("| scene | frame | encode | kernels |");
            for l in &labels {
                let _ = write!(s, " {} |", md_cell(l));
            }
            s.push_str("\n|---|---:|---:|---:|");
            s.push_str(&"---:|".repeat(labels.len()));
            s.push('\n');
            for (run, sum) in &timed {
                let kernel = sum.kernel_ms.map_or_else(|| "–".to_owned(), fmt_ms);
                let _ = write!(
                    s,
                    "| {} | {} | {} | {kernel} |",
                    md_cell(&run.scene),
                    fmt_ms(sum.wall_ms),
                    fmt_ms(sum.encode_ms)
                );
                for l in &labels {
                    let cell = sum
                        .passes
                        .iter()
                        .find(|(p, _)| p == l)
                        .map_or_else(|| "–".to_owned(), |(_, m)| fmt_ms(*m));
                    let _ = write!(s, " {cell} |");
                }
                s.push('\n');
            }
        }
        let refused: Vec<(&Run, &String)> = runs
            .iter()
            .filter_map(|r| match &r.outcome {
                Outcome::Refused(reason) => Some((*r, reason)),
                Outcome::Timed(_) => None,
            })
            .collect();
        if !refused.is_empty() {
            s.push_str("\nRefused:\n\n");
            for (run, reason) in refused {
                let _ = writeln!(s, "- `{}`: {}", run.scene, md_cell(reason));
            }
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Duration {
        Duration::from_millis(v)
    }

    fn frame(wall: u64, encode: u64, passes: &[(&str, u64)]) -> FrameTimes {
        FrameTimes {
            wall: ms(wall),
            encode: ms(encode),
            kernel: Some(passes.iter().map(|(_, d)| ms(*d)).sum()),
            passes: passes
                .iter()
                .map(|(l, d)| (l.to_string(), ms(*d)))
                .collect(),
        }
    }

    /// Two sizes; at the first a free-form scene (three frames, one of them rebasing) and a
    /// terrain scene with media (two frames: even medians), at the second the free-form scene
    /// and a refusal whose reason has a comma, a quote and a bar.
    fn bench() -> GpuBench {
        let ff = |w, h| Run {
            scene: "csg".into(),
            width: w,
            height: h,
            outcome: Outcome::Timed(vec![
                frame(30, 3, &[("raygen", 2), ("free forms", 10), ("shade", 6)]),
                frame(
                    50,
                    5,
                    &[
                        ("rebase", 4),
                        ("raygen", 1),
                        ("free forms", 30),
                        ("shade", 2),
                    ],
                ),
                frame(40, 4, &[("raygen", 3), ("free forms", 20), ("shade", 4)]),
            ]),
        };
        GpuBench {
            adapter: Adapter {
                name: "llvmpipe (LLVM 15.0.6, 256 bits)".into(),
                backend: "Vulkan".into(),
                software: true,
                clock: "host clock".into(),
            },
            warmup: 2,
            frames: 3,
            runs: vec![
                ff(1280, 720),
                Run {
                    scene: "terrain_low".into(),
                    width: 1280,
                    height: 720,
                    outcome: Outcome::Timed(vec![
                        frame(10, 1, &[("raygen", 1), ("terrains", 4), ("media", 2)]),
                        frame(20, 2, &[("raygen", 2), ("terrains", 6), ("media", 3)]),
                    ]),
                },
                ff(1920, 1080),
                Run {
                    scene: "big".into(),
                    width: 1920,
                    height: 1080,
                    outcome: Outcome::Refused(
                        "the image's longer side, in pixels: needs 1920, the device allows 1024 \"|\"".into(),
                    ),
                },
            ],
        }
    }

    #[test]
    fn medians_of_odd_and_even_counts() {
        assert_eq!(median(vec![]), None);
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), Some(2.5));
    }

    #[test]
    fn a_summary_takes_each_pass_median_counting_absent_passes_as_zero() {
        let Outcome::Timed(frames) = &bench().runs[0].outcome else {
            panic!("timed");
        };
        let sum = summarise(frames).unwrap();
        assert_eq!((sum.wall_ms, sum.encode_ms), (40.0, 4.0));
        // Kernels: 18, 37, 27.
        assert_eq!(sum.kernel_ms, Some(27.0));
        assert_eq!(
            sum.passes,
            [
                ("rebase".to_owned(), 0.0),
                ("raygen".to_owned(), 2.0),
                ("free forms".to_owned(), 20.0),
                ("shade".to_owned(), 4.0),
            ]
        );
        assert_eq!(summarise(&[]), None);
        // A frame without timed passes: no kernel median.
        let mut untimed = frames.clone();
        untimed[1].kernel = None;
        assert_eq!(summarise(&untimed).unwrap().kernel_ms, None);
    }

    #[test]
    fn milliseconds_keep_about_three_figures() {
        let cases = [
            (13220.2, "13220"),
            (99.96, "100"),
            (99.94, "99.9"),
            (9.996, "10.0"),
            (4.0, "4.00"),
            (0.9996, "1.00"),
            (0.5249, "0.525"),
            (0.0, "0.000"),
        ];
        for (v, text) in cases {
            assert_eq!(fmt_ms(v), text, "{v}");
        }
    }

    #[test]
    fn unknown_passes_follow_the_known_ones_in_the_order_first_seen() {
        let mut labels = vec!["shade".to_owned()];
        merge_labels(
            &mut labels,
            ["zeta", "raygen", "alpha", "rebase"].map(String::from),
        );
        assert_eq!(labels, ["rebase", "raygen", "shade", "zeta", "alpha"]);
    }

    #[test]
    fn the_csv_has_a_row_per_scene_size_and_pass_and_quotes_what_needs_it() {
        let csv = to_csv(&bench());
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], CSV_HEADER);
        let columns = CSV_HEADER.split(',').count();
        // csg 4 passes × 2 sizes, terrain_low 3 passes, one refusal.
        assert_eq!(lines.len(), 1 + 4 + 3 + 4 + 1);
        let adapter = "\"llvmpipe (LLVM 15.0.6, 256 bits)\",Vulkan,true,host clock";
        assert_eq!(
            lines[1],
            format!("{adapter},csg,1280,720,timed,2,3,40.0000,4.0000,27.0000,rebase,0.0000,")
        );
        assert_eq!(
            lines[3],
            format!("{adapter},csg,1280,720,timed,2,3,40.0000,4.0000,27.0000,free forms,20.0000,")
        );
        assert_eq!(
            lines[5],
            format!(
                "{adapter},terrain_low,1280,720,timed,2,2,15.0000,1.5000,9.0000,raygen,1.5000,"
            )
        );
        assert_eq!(
            lines[7],
            format!("{adapter},terrain_low,1280,720,timed,2,2,15.0000,1.5000,9.0000,media,2.5000,")
        );
        assert_eq!(
            lines[12],
            format!(
                "{adapter},big,1920,1080,refused,2,0,,,,,,\"the image's longer side, in pixels: needs 1920, the device allows 1024 \"\"|\"\"\""
            )
        );
        // Every row has the header's columns once quoted fields are read as one.
        for line in &lines[1..] {
            let mut fields = 1;
            let mut quoted = false;
            for c in line.chars() {
                match c {
                    '"' => quoted = !quoted,
                    ',' if !quoted => fields += 1,
                    _ => {}
                }
            }
            assert_eq!(fields, columns, "{line}");
        }
    }

    #[test]
    fn the_markdown_has_a_table_per_size_with_the_passes_that_ran_and_the_refusals() {
        let md = to_markdown(&bench());
        assert!(md.contains("**llvmpipe (LLVM 15.0.6, 256 bits)** (Vulkan, software"));
        assert!(md.contains("not GPU figures"));
        assert!(md.contains("per size 2 warm-up frames discarded"), "{md}");
        assert!(md.contains("median of 3 timed frames"), "{md}");
        let first = md.find("## 1280 × 720").expect("first size");
        let second = md.find("## 1920 × 1080").expect("second size");
        assert!(first < second);
        let (one, two) = (&md[first..second], &md[second..]);
        // The first size's columns: every pass any of its scenes ran, in frame order.
        assert!(one.contains(
            "| scene | frame | encode | kernels | rebase | raygen | free forms | terrains | shade | media |\n\
             |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
        ), "{one}");
        assert!(
            one.contains("| csg | 40.0 | 4.00 | 27.0 | 0.000 | 2.00 | 20.0 | – | 4.00 | – |\n"),
            "{one}"
        );
        assert!(
            one.contains("| terrain_low | 15.0 | 1.50 | 9.00 | – | 1.50 | – | 5.00 | – | 2.50 |\n"),
            "{one}"
        );
        assert!(!one.contains("Refused"), "{one}");
        assert!(
            two.contains(
                "| scene | frame | encode | kernels | rebase | raygen | free forms | shade |\n"
            ),
            "{two}"
        );
        assert!(!two.contains("| big |"), "{two}");
        assert!(two.contains("Refused:\n\n- `big`: the image's longer side, in pixels: needs 1920, the device allows 1024 \"\\|\"\n"), "{two}");
    }

    #[test]
    fn a_size_where_every_scene_was_refused_says_so() {
        let mut b = bench();
        b.runs.retain(|r| r.scene == "big");
        (b.warmup, b.frames) = (1, 1);
        let md = to_markdown(&b);
        assert!(
            md.contains("per size 1 warm-up frame discarded, then the median of 1 timed frame,"),
            "{md}"
        );
        assert!(
            md.contains("## 1920 × 1080\n\nNo scene was timed at this size.\n"),
            "{md}"
        );
        assert!(md.contains("- `big`:"), "{md}");
        assert_eq!(to_csv(&b).lines().count(), 2);
    }
}
