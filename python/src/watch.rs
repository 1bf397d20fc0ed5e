//! Long work (a build, a render) run on a thread of its own while the calling thread,
//! GIL released, wakes every [`POLL`] to take the GIL for a moment: to run Python's signal
//! handlers (Ctrl-C raises `KeyboardInterrupt` there, and cancels the work) and to call
//! the host's progress callback. So the callback always runs on the caller's thread, the
//! GIL is held only for those moments, and nothing of Python reaches the worker threads.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

use hairtrace::Progress;
use hairtrace::scene::{Stage, StageProgress};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyBool;

/// How often the caller looks at signals and progress: Ctrl-C cancels within it, plus
/// the samples in flight, which stop at the next one.
const POLL: Duration = Duration::from_millis(50);

/// What the work reports and the caller reads: pixels done of a total, and whether to stop.
#[derive(Default)]
pub struct Watch {
    done: AtomicU64,
    total: AtomicU64,
    cancel: AtomicBool,
}

impl Progress for Watch {
    fn update(&self, done: u64, total: u64) -> bool {
        self.total.store(total, Ordering::Relaxed);
        self.done.store(done, Ordering::Relaxed);
        !self.cancel.load(Ordering::Relaxed)
    }
}

impl StageProgress for Watch {
    fn update(&self, _stage: Stage, _fraction: f64) -> bool {
        !self.cancel.load(Ordering::Relaxed)
    }
}

/// How the caller's wait ended besides the work's own result.
pub enum Stop {
    /// Ctrl-C, or the callback raised: the work was cancelled, the error is to raise.
    Raised(PyErr),
    /// The callback returned False: the work was cancelled, its result stands.
    Asked,
}

/// Runs `work` on a thread of its own, the GIL released, until it returns; meanwhile
/// answers signals and calls `progress(done, total)` when `done` moved.
pub fn run<T: Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    work: impl FnOnce(&Watch) -> T + Send,
) -> PyResult<(T, Option<Stop>)> {
    let watch = Watch::default();
    let caller = std::thread::current();
    std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let out = work(&watch);
            caller.unpark();
            out
        });
        let mut stop = None;
        let mut told = None;
        loop {
            let finished = worker.is_finished();
            if stop.is_none() {
                stop = look(py, &watch, progress, &mut told, finished);
                if stop.is_some() {
                    watch.cancel.store(true, Ordering::Relaxed);
                }
            }
            if finished {
                break;
            }
            py.detach(|| std::thread::park_timeout(POLL));
        }
        let out = worker
            .join()
            .map_err(|_| PyRuntimeError::new_err("hairtrace: the work failed unexpectedly"))?;
        Ok((out, stop))
    })
}

/// One look: signals, then the callback (once more at the end, so it sees the last count).
fn look(
    py: Python<'_>,
    watch: &Watch,
    progress: Option<&Bound<'_, PyAny>>,
    told: &mut Option<u64>,
    finished: bool,
) -> Option<Stop> {
    if let Err(e) = py.check_signals() {
        return Some(Stop::Raised(e));
    }
    let cb = progress?;
    let (done, total) = (
        watch.done.load(Ordering::Relaxed),
        watch.total.load(Ordering::Relaxed),
    );
    if total == 0 || *told == Some(done) {
        return None;
    }
    *told = Some(done);
    match cb.call1((done, total)) {
        Err(e) => Some(Stop::Raised(e)),
        Ok(r) if r.is_instance_of::<PyBool>() && !r.is_truthy().unwrap_or(true) && !finished => {
            Some(Stop::Asked)
        }
        Ok(_) => None,
    }
}
