//! Panics that the C ABI catches print nothing. Rust's default hook writes every panic, caught
//! or not, and its backtrace to stderr, which in a C host is the host's; a library prints
//! nothing a host did not ask for. The message still reaches the host, through the error
//! the boundary returns.
//!
//! One hook is installed the first time a quiet call runs: silent on a thread inside such a
//! call, and the hook it replaced (a Rust host's own, or the default) everywhere else, so a
//! Rust host keeps its own hook for its own panics.

use std::cell::Cell;
use std::sync::Once;

thread_local! {
    /// How many quiet calls this thread is inside.
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

/// Keeps this thread's panics quiet while it lives (also when unwinding); quiet calls may
/// nest. A count rather than a saved flag: entering and leaving are an increment and a
/// decrement, with nothing kept across the call. A guard rather than a closure, so that
/// the code it covers is compiled as if it were not there.
#[must_use]
pub(crate) struct Quiet(());

impl Quiet {
    pub(crate) fn enter() -> Quiet {
        install();
        DEPTH.set(DEPTH.get() + 1);
        Quiet(())
    }
}

impl Drop for Quiet {
    fn drop(&mut self) {
        DEPTH.set(DEPTH.get() - 1);
    }
}

/// Whether this thread runs a quiet call: the threads that call starts inherit it with
/// [`inherit`].
pub(crate) fn is_quiet() -> bool {
    DEPTH.get() > 0
}

/// Runs `f` quietly when `quiet` (a worker of a quiet call), else as it is.
pub(crate) fn inherit<R>(quiet: bool, f: impl FnOnce() -> R) -> R {
    let _quiet = quiet.then(Quiet::enter);
    f()
}

fn install() {
    static HOOK: Once = Once::new();
    // `set_hook` may not be called while this thread panics (a call from a destructor
    // during unwinding): that call stays loud, and a later one installs the hook.
    if HOOK.is_completed() || std::thread::panicking() {
        return;
    }
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !DEPTH.try_with(|d| d.get() > 0).unwrap_or(false) {
                previous(info);
            }
        }));
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quiet_calls_nest_and_restore() {
        assert!(!is_quiet());
        {
            let _outer = Quiet::enter();
            assert!(is_quiet());
            drop(Quiet::enter());
            assert!(is_quiet());
            let caught = std::panic::catch_unwind(|| {
                let _inner = Quiet::enter();
                panic!("quiet")
            });
            assert!(caught.is_err() && is_quiet());
        }
        assert!(!is_quiet());
        inherit(true, || assert!(is_quiet()));
        inherit(false, || assert!(!is_quiet()));
    }
}
