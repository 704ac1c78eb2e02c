//! Progress display on stderr (hidden when stderr is not a terminal).

use indicatif::{ProgressBar, ProgressStyle};
use std::time::Duration;

/// A spinner with a message, ticking in the background until dropped or finished.
pub fn spinner(msg: impl Into<String>) -> ProgressBar {
    let pb = ProgressBar::new_spinner();
    pb.set_style(
        ProgressStyle::with_template("{spinner} {msg} [{elapsed}]").expect("valid template"),
    );
    pb.set_message(msg.into());
    pb.enable_steady_tick(Duration::from_millis(120));
    pb
}

/// Loads a grid with a spinner.
pub fn load(path: &std::path::Path) -> abgs::Result<abgs::Grid> {
    let pb = spinner(format!("loading {}", path.display()));
    let g = abgs::Grid::load(path);
    pb.finish_and_clear();
    g
}
