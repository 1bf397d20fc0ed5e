//! Parallel work on threads of the library's own, joined before the work returns: no
//! thread outlives a call into the library (a C host may call `ht_shutdown` and unload it),
//! and rayon's global pool, whose threads live until the process exits, is never started.

use crate::error::{Result, invalid_arg};
use crate::quiet_panic;

/// Runs `op` on a pool of `threads` threads (0: one per hardware thread), joined before
/// this returns. Its workers keep the panics of a quiet call (the C ABI's) quiet, as the
/// calling thread does. Called from a worker of a pool of that size, `op` runs on that
/// pool: a render's passes share one pool instead of starting one each.
pub(crate) fn scoped<T: Send>(threads: usize, op: impl FnOnce() -> T + Send) -> Result<T> {
    let threads = match threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    if rayon::current_thread_index().is_some() && rayon::current_num_threads() == threads {
        return Ok(op());
    }
    let quiet = quiet_panic::is_quiet();
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build_scoped(
            |thread| quiet_panic::inherit(quiet, || thread.run()),
            |pool| pool.install(op),
        )
        .map_err(|e| invalid_arg!("cannot start {threads} threads: {e}"))
}
