//! The certified closed form (the CPU's default for rays that meet only plain quadrics) and the
//! halving search render the same images: on every data scene, depth within ε on every pixel
//! both hit, and hit/miss disagreement only on silhouette pixels (a neighbour differs in what it
//! hits), at most 0.2 % of the image.

mod common;

use fray_trace::{CastMethod, TraceSettings, render};

#[test]
fn closed_form_and_search_agree_on_every_data_scene() {
    for path in common::data_scenes() {
        let what = path.display().to_string();
        let s = common::load_at_height(&path, 120);
        let mut settings = TraceSettings::for_scene(&s);
        settings.shading = false;
        settings.method = CastMethod::Halving;
        let searched = render(&s, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"));
        settings.method = CastMethod::ClosedForm;
        let closed = render(&s, &settings, None).unwrap_or_else(|e| panic!("{what}: {e}"));
        let eps = settings.epsilon;
        let hit = |f: &fray_core::Frame, x: u32, y: u32| f.depth.get(x, y).is_finite();
        let (mut worst, mut disagreements) = (0.0f64, 0u32);
        for y in 0..s.height {
            for x in 0..s.width {
                let (a, b) = (*searched.depth.get(x, y), *closed.depth.get(x, y));
                match (a.is_finite(), b.is_finite()) {
                    (true, true) => {
                        // Both are within ε past the same first root.
                        let d = (a - b).abs();
                        assert!(d <= eps, "{what}: |Δt| = {d:e} > ε = {eps:e} at ({x}, {y})");
                        worst = worst.max(d);
                    }
                    (false, false) => {}
                    _ => {
                        disagreements += 1;
                        let silhouette = [(-1i32, 0i32), (1, 0), (0, -1), (0, 1)]
                            .iter()
                            .filter_map(|&(dx, dy)| {
                                let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                                (nx >= 0 && ny >= 0 && nx < s.width as i32 && ny < s.height as i32)
                                    .then(|| hit(&searched, nx as u32, ny as u32))
                            })
                            .any(|h| h != a.is_finite());
                        assert!(
                            silhouette,
                            "{what}: hit/miss differ off a silhouette at ({x}, {y})"
                        );
                    }
                }
            }
        }
        let share = f64::from(disagreements) / f64::from(s.width * s.height);
        assert!(
            share <= 0.002,
            "{what}: {share:.4} of the pixels differ in hit/miss"
        );
        // Terrain-only scenes have no free forms to answer.
        assert!(
            s.objects.is_empty() || closed.stats.closed_form_casts > 0,
            "{what}: nothing in closed form"
        );
        assert_eq!(searched.stats.closed_form_casts, 0, "{what}");
        eprintln!(
            "{what}: max |Δt| {worst:.2e} (ε {eps:.2e}), {disagreements} silhouette pixels differ; \
             bound evaluations {} → {}, point evaluations {} → {}, {} casts in closed form",
            searched.stats.bound_evaluations,
            closed.stats.bound_evaluations,
            searched.stats.point_evaluations,
            closed.stats.point_evaluations,
            closed.stats.closed_form_casts
        );
    }
}
