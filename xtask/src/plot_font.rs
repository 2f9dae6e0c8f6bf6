//! The plots' font: DejaVu Sans Mono (its licence in `xtask/fonts/`), bundled so a plot looks
//! the same on every machine, registered once per process under [`FONT`].

use plotters::style::FontStyle;

/// The family name the plots ask for.
pub const FONT: &str = "sans-serif";

/// Registers the bundled font under [`FONT`], once for the process.
pub fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font(
            FONT,
            FontStyle::Normal,
            include_bytes!("../fonts/DejaVuSansMono.ttf"),
        )
        .is_ok()
    });
    ok.then_some(())
        .ok_or_else(|| "the plot's font does not load".to_string())
}
