//! Progress of the long runs over models on stderr (`analyze`, `check`):
//! one tick per model, the clock, and the models in progress by name.
//! indicatif draws nothing when stderr is not a terminal.

use indicatif::{ProgressBar, ProgressStyle};
use std::collections::BTreeSet;
use std::sync::Mutex;

/// The number of worker threads for `--jobs N` (0: one per core).
pub fn threads(jobs: usize) -> usize {
    match jobs {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
}

/// A bar over `len` models that names the models in progress; shared by
/// the workers.
pub struct ModelProgress {
    pub bar: ProgressBar,
    running: Mutex<BTreeSet<String>>,
}

impl ModelProgress {
    /// A bar `prefix [====>   ] pos/len models, elapsed names`.
    pub fn new(prefix: &'static str, len: u64) -> ModelProgress {
        ModelProgress::with_unit(prefix, len, "models")
    }

    /// The same bar counting `unit` (e.g. "cases").
    pub fn with_unit(prefix: &'static str, len: u64, unit: &str) -> ModelProgress {
        let bar = ProgressBar::new(len);
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{prefix}} [{{bar:30}}] {{pos}}/{{len}} {unit}, {{elapsed}} {{msg}}"
            ))
            .expect("valid template")
            .progress_chars("=> "),
        );
        bar.set_prefix(prefix);
        // The clock runs while a slow model is in progress.
        bar.enable_steady_tick(std::time::Duration::from_secs(1));
        ModelProgress {
            bar,
            running: Mutex::new(BTreeSet::new()),
        }
    }

    /// `names` are in progress from now on.
    pub fn start(&self, names: &[String]) {
        self.update(|r| r.extend(names.iter().cloned()));
    }

    /// `names` are no longer in progress.
    pub fn end(&self, names: &[String]) {
        self.update(|r| names.iter().for_each(|n| _ = r.remove(n)));
    }

    fn update(&self, f: impl FnOnce(&mut BTreeSet<String>)) {
        // A poisoned lock only means another worker panicked, and that
        // panic ends the run anyway; the set itself is still usable.
        let mut r = self.running.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut r);
        self.bar
            .set_message(r.iter().cloned().collect::<Vec<_>>().join(", "));
    }
}
