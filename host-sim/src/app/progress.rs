//! Progress shown on the terminal for work that takes more than a moment.

use indicatif::{ProgressBar, ProgressStyle};

/// A progress bar over `len` items named `unit` on stderr, or a hidden one.
pub fn progress_bar(len: usize, unit: &str, show: bool) -> ProgressBar {
    let bar = if show {
        ProgressBar::new(len as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(&format!(
            "{{bar:40}} {{pos}}/{{len}} {unit}, {{elapsed}} elapsed, ETA {{eta}}"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
