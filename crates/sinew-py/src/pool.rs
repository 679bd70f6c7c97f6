//! `threads=` of the batch calls: the Rust part runs on a rayon pool of exactly that many
//! threads, never on rayon's global pool (which a Dask worker per core would oversubscribe);
//! without `threads` it runs on the global pool (every core, or `RAYON_NUM_THREADS`).
//!
//! Pools are lent, not shared: a call takes an idle pool of its size (or builds one) and gives
//! it back when it returns, so two Python threads that each ask for `threads=1` run on two
//! threads at once instead of queueing on one. At most [`IDLE_POOLS`] idle pools are kept.

use std::sync::Mutex;

use pyo3::PyResult;
use pyo3::exceptions::PyRuntimeError;
use rayon::ThreadPool;

use crate::errors::input;

/// The most threads a call may ask for.
pub const MAX_THREADS: usize = 1024;

/// The most idle pools kept for later calls.
const IDLE_POOLS: usize = 8;

/// Idle pools by size.
static IDLE: Mutex<Vec<(usize, ThreadPool)>> = Mutex::new(Vec::new());

/// The `threads` argument checked: `None` (the global pool) or `1..=MAX_THREADS`.
pub fn threads_arg(threads: Option<i64>) -> PyResult<Option<usize>> {
    match threads {
        None => Ok(None),
        Some(n) if n < 1 => Err(input(format!(
            "threads: expected a number of threads ≥ 1 (or None: every core), got {n}"
        ))),
        Some(n) => match usize::try_from(n) {
            Ok(n) if n <= MAX_THREADS => Ok(Some(n)),
            _ => Err(input(format!("threads: {n} is more than the {MAX_THREADS} a call may use"))),
        },
    }
}

/// Run `f` on a pool of `threads` threads (`None`: rayon's global pool). Call it with the GIL
/// released: `f` runs until every task it spawns has finished.
pub fn run<R: Send>(threads: Option<usize>, f: impl FnOnce() -> R + Send) -> PyResult<R> {
    let Some(n) = threads else { return Ok(f()) };
    let pool = take(n)?;
    let result = pool.install(f);
    give_back(n, pool);
    Ok(result)
}

/// The number of threads the calling rayon pool has (the global pool's outside any).
pub fn current_threads() -> usize {
    rayon::current_num_threads()
}

fn take(n: usize) -> PyResult<ThreadPool> {
    let idle = IDLE.lock().ok().and_then(|mut idle| {
        let k = idle.iter().position(|(size, _)| *size == n)?;
        Some(idle.swap_remove(k).1)
    });
    match idle {
        Some(pool) => Ok(pool),
        None => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .thread_name(|i| format!("sinew-{i}"))
            .build()
            .map_err(|e| {
                PyRuntimeError::new_err(format!("threads: cannot start {n} threads: {e}"))
            }),
    }
}

fn give_back(n: usize, pool: ThreadPool) {
    if let Ok(mut idle) = IDLE.lock()
        && idle.len() < IDLE_POOLS
    {
        idle.push((n, pool));
    }
}
