//! Saying what a step that may take a while is doing: loading a large file,
//! building the trees of a large scene, denoising. A step that ends within
//! [`QUIET_FOR`] says nothing; one that lasts longer says what it is doing
//! on stderr: on a terminal a spinner with its words and the time so far,
//! cleared when it ends; elsewhere (a log) one line when it has taken
//! [`QUIET_FOR`], and one with its time when it ends.
//! `SAHARA_STATUS_AFTER` (seconds) sets another delay; 0 says every step.

use std::io::IsTerminal;
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// How long a step runs before it says what it is doing.
pub const QUIET_FOR: Duration = Duration::from_secs(1);

/// A step under way; it ends when [`Step::end`] is called or it is dropped.
pub struct Step {
    done: Arc<(Mutex<bool>, Condvar)>,
    watcher: Option<JoinHandle<()>>,
}

impl Step {
    /// Starts the step `what` (`loading scene.glb`): said after
    /// [`QUIET_FOR`] if it is still under way.
    pub fn start(what: impl Into<String>) -> Self {
        let what = what.into();
        let done = Arc::new((Mutex::new(false), Condvar::new()));
        let watched = Arc::clone(&done);
        let watcher = std::thread::Builder::new()
            .name("sahara-status".into())
            .spawn(move || watch(&what, &watched))
            .ok();
        Self { done, watcher }
    }

    /// Ends the step (waiting for what it printed to be finished).
    pub fn end(&mut self) {
        let (lock, wake) = &*self.done;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        wake.notify_all();
        if let Some(w) = self.watcher.take() {
            let _ = w.join();
        }
    }
}

impl Drop for Step {
    fn drop(&mut self) {
        self.end();
    }
}

/// How long a step runs before it says what it is doing:
/// `SAHARA_STATUS_AFTER` if it is a number of seconds >= 0, else
/// [`QUIET_FOR`].
fn quiet_for() -> Duration {
    std::env::var("SAHARA_STATUS_AFTER")
        .ok()
        .and_then(|v| v.trim().parse::<f64>().ok())
        .filter(|s| *s >= 0.0 && s.is_finite())
        .map_or(QUIET_FOR, Duration::from_secs_f64)
}

/// Waits for the step to end; if it lasts beyond [`quiet_for`], says
/// `what` until it does.
fn watch(what: &str, done: &(Mutex<bool>, Condvar)) {
    let start = Instant::now();
    let (lock, wake) = done;
    let delay = quiet_for();
    let guard = lock.lock().unwrap_or_else(|e| e.into_inner());
    let (guard, _) = wake
        .wait_timeout_while(guard, delay, |ended| !*ended)
        .unwrap_or_else(|e| e.into_inner());
    // A delay of 0 says every step, however short.
    if *guard && !delay.is_zero() {
        return;
    }
    let spinner = std::io::stderr().is_terminal().then(|| {
        let s = ProgressBar::new_spinner().with_elapsed(start.elapsed());
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} {elapsed}") {
            s.set_style(style);
        }
        s.set_message(format!("{what}..."));
        s.enable_steady_tick(Duration::from_millis(200));
        s
    });
    if spinner.is_none() {
        eprintln!("{what}...");
    }
    let _ended = wake
        .wait_while(guard, |ended| !*ended)
        .unwrap_or_else(|e| e.into_inner());
    match spinner {
        Some(s) => s.finish_and_clear(),
        None => eprintln!("{what}: done in {:.1} s", start.elapsed().as_secs_f64()),
    }
}
