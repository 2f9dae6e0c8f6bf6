//! The regression report: one [`Row`] per scene × backend (or backend pair), printed as a
//! console line and written as `index.html` with the images side by side.

use crate::compare::{BAD_PIXEL_DIFFERENCE, Metrics};
use crate::thresholds::Thresholds;
use fray_core::RenderStats;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Duration;

/// The outcome of one comparison (or of a failure before one could be made).
#[derive(Clone, Debug)]
pub struct Row {
    pub scene: String,
    /// The backend, or `"gpu vs cpu"` for a comparison between backends.
    pub backend: String,
    /// Image file names relative to the report's directory.
    pub reference: Option<String>,
    pub actual: Option<String>,
    pub diff: Option<String>,
    pub metrics: Option<Metrics>,
    pub thresholds: Thresholds,
    pub pass: bool,
    /// Why the row failed before or instead of a comparison (load error, missing reference…).
    pub message: Option<String>,
    /// Wall time of the render call and the backend's statistics.
    pub render: Option<(Duration, RenderStats)>,
}

impl Row {
    /// A failed row with only a message.
    pub fn failure(scene: &str, backend: &str, message: String) -> Self {
        Self {
            scene: scene.to_owned(),
            backend: backend.to_owned(),
            reference: None,
            actual: None,
            diff: None,
            metrics: None,
            thresholds: Thresholds::default(),
            pass: false,
            message: Some(message),
            render: None,
        }
    }

    fn status(&self) -> &'static str {
        if self.pass { "PASS" } else { "FAIL" }
    }
}

/// The one-line console summary of a row.
pub fn console_line(row: &Row) -> String {
    let mut line = format!("{} {:<24} {:<12}", row.status(), row.scene, row.backend);
    if let Some(m) = &row.metrics {
        let t = &row.thresholds;
        let _ = write!(
            line,
            " rmse {:.3} (≤ {:.3})  bad {:.4} (≤ {:.4})  max {:>3}{}",
            m.rmse,
            t.rmse,
            m.bad_fraction,
            t.bad_fraction,
            m.max_abs,
            t.max_abs.map(|x| format!(" (≤ {x})")).unwrap_or_default()
        );
    }
    if let Some((wall, _)) = &row.render {
        let _ = write!(line, "  {:.1} ms", wall.as_secs_f64() * 1e3);
    }
    if let Some(msg) = &row.message {
        let _ = write!(line, "  {msg}");
    }
    line
}

/// Escapes text for HTML element content and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

fn image_cell(file: &Option<String>) -> String {
    match file {
        Some(f) => {
            let f = escape(f);
            format!(r#"<td><a href="{f}"><img src="{f}" alt="{f}"></a></td>"#)
        }
        None => "<td class=none>—</td>".to_owned(),
    }
}

fn stats_cell(render: &Option<(Duration, RenderStats)>) -> String {
    let Some((wall, s)) = render else {
        return "<td class=none>—</td>".to_owned();
    };
    format!(
        "<td class=stats>{:.1} ms wall ({:.1} ms backend)<br>backend {}, {} threads<br>\
         {} primary + {} shadow rays, {} hits<br>{:.2} Mrays/s, {:.1} steps/ray<br>\
         {} bound / {} point evaluations<br>ε = {:.3e}<br>passes: {}</td>",
        wall.as_secs_f64() * 1e3,
        s.elapsed.as_secs_f64() * 1e3,
        escape(&s.backend),
        s.threads,
        s.primary_rays,
        s.shadow_rays,
        s.hits,
        s.rays_per_second() / 1e6,
        s.steps_per_ray(),
        s.bound_evaluations,
        s.point_evaluations,
        s.epsilon,
        escape(&s.passes.join(", ")),
    )
}

/// The whole report as an HTML page.
pub fn html(rows: &[Row], title: &str) -> String {
    let failed = rows.iter().filter(|r| !r.pass).count();
    let mut page = String::new();
    let _ = write!(
        page,
        r#"<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>
body {{ font-family: sans-serif; margin: 1em; }}
table {{ border-collapse: collapse; }}
th, td {{ border: 1px solid #ccc; padding: 4px 6px; vertical-align: top; text-align: left; }}
img {{ width: 320px; image-rendering: pixelated; display: block; background: #888; }}
.PASS {{ background: #cfc; font-weight: bold; }}
.FAIL {{ background: #fcc; font-weight: bold; }}
.none {{ color: #999; text-align: center; }}
.stats, .metrics {{ font-size: 85%; white-space: nowrap; }}
.msg {{ color: #a00; white-space: pre-wrap; }}
</style></head><body>
<h1>{title}</h1>
<p>{passed} passed, {failed} failed. A pixel is <em>bad</em> when a channel differs by more
than {BAD_PIXEL_DIFFERENCE} (of 255); the diff shows |reference − actual| × 8.</p>
<table>
<tr><th>scene</th><th>backend</th><th>reference</th><th>actual</th><th>diff</th>
<th>metrics</th><th>thresholds</th><th>result</th><th>render</th></tr>
"#,
        title = escape(title),
        passed = rows.len() - failed,
    );
    for row in rows {
        let metrics = match &row.metrics {
            Some(m) => format!(
                "rmse {:.3}<br>max {}<br>bad {:.4}",
                m.rmse, m.max_abs, m.bad_fraction
            ),
            None => "—".to_owned(),
        };
        let message = row
            .message
            .as_deref()
            .map(|m| format!("<div class=msg>{}</div>", escape(m)))
            .unwrap_or_default();
        let _ = writeln!(
            page,
            "<tr><td>{}</td><td>{}</td>{}{}{}<td class=metrics>{metrics}</td>\
             <td class=metrics>rmse ≤ {:.3}<br>bad ≤ {:.4}{}</td><td class={status}>{status}{message}</td>{}</tr>",
            escape(&row.scene),
            escape(&row.backend),
            image_cell(&row.reference),
            image_cell(&row.actual),
            image_cell(&row.diff),
            row.thresholds.rmse,
            row.thresholds.bad_fraction,
            row.thresholds
                .max_abs
                .map(|x| format!("<br>max ≤ {x}"))
                .unwrap_or_default(),
            stats_cell(&row.render),
            status = row.status(),
        );
    }
    page.push_str("</table>\n</body></html>\n");
    page
}

/// Writes the report as `<dir>/index.html`.
pub fn write(dir: &Path, rows: &[Row], title: &str) -> Result<(), String> {
    let path = dir.join("index.html");
    std::fs::write(&path, html(rows, title))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_shows_rows() {
        assert_eq!(
            escape(r#"<a href="x">&'"#),
            "&lt;a href=&quot;x&quot;&gt;&amp;&#39;"
        );
        let mut ok = Row::failure("sphere", "cpu", String::new());
        ok.message = None;
        ok.pass = true;
        ok.actual = Some("sphere.cpu.png".into());
        ok.metrics = Some(Metrics {
            rmse: 0.5,
            max_abs: 3,
            bad_fraction: 0.0,
        });
        ok.render = Some((Duration::from_millis(12), RenderStats::default()));
        let bad = Row::failure(
            "<fog>",
            "cpu",
            "no reference: run `cargo xtask bless fog`".into(),
        );
        let page = html(&[ok.clone(), bad.clone()], "fray regress");
        assert!(page.contains("1 passed, 1 failed"));
        assert!(page.contains(r#"<img src="sphere.cpu.png""#));
        assert!(page.contains("&lt;fog&gt;"));
        assert!(!page.contains("<fog>"));
        assert!(page.contains("cargo xtask bless fog"));

        let line = console_line(&ok);
        assert!(
            line.starts_with("PASS sphere")
                && line.contains("rmse 0.500")
                && line.contains("12.0 ms"),
            "{line}"
        );
        assert!(console_line(&bad).starts_with("FAIL <fog>"));
    }
}
