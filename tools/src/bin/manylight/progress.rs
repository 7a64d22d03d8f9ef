//! The bench's progress: a bar on a terminal, and one plain line per step where stderr is a
//! file or a pipe (a bar is invisible there, so a long run would print nothing until it ends).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// Steps done out of a known total.
pub struct Progress {
    bar: ProgressBar,
    plain: bool,
    message: String,
}

impl Progress {
    /// A progress of `steps` steps on stderr.
    pub fn new(steps: u64) -> Progress {
        let plain = !std::io::stderr().is_terminal();
        let bar = if plain {
            ProgressBar::hidden()
        } else {
            ProgressBar::new(steps).with_style(
                ProgressStyle::with_template("{bar:40} {pos}/{len} {elapsed_precise} {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            )
        };
        bar.set_length(steps);
        Progress {
            bar,
            plain,
            message: String::new(),
        }
    }

    /// What the next step is.
    pub fn set_message(&mut self, message: String) {
        self.bar.set_message(message.clone());
        self.message = message;
    }

    /// One step done.
    pub fn inc(&mut self) {
        self.bar.inc(1);
        if self.plain {
            let len = self.bar.length().unwrap_or(0);
            let secs = self.bar.elapsed().as_secs();
            eprintln!("[{}/{len} {secs} s] {}", self.bar.position(), self.message);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
