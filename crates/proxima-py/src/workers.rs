//! `workers=`: where a batch runs. One worker runs on the calling thread; more
//! run on a rayon pool of that size, built once per size and kept (a pool costs
//! a thread spawn per worker, far more than a small batch).

use pyo3::exceptions::PyValueError;
use pyo3::PyResult;
use rayon::ThreadPool;
use std::sync::{Arc, Mutex};

/// Where a batch runs, from a `workers=` argument.
#[derive(Clone)]
pub enum Workers {
    /// On the calling thread, sequentially.
    Caller,
    /// On this pool (`workers=n`, n >= 2) or on rayon's global pool, one thread
    /// per core (`workers=-1`, scipy's convention).
    Pool(Option<Arc<ThreadPool>>),
}

/// The pools built so far, by size.
static POOLS: Mutex<Vec<(usize, Arc<ThreadPool>)>> = Mutex::new(Vec::new());

impl Workers {
    /// `1` (the default): the calling thread; `n >= 2`: a pool of `n` threads;
    /// `-1`: one thread per core. Anything else is a `ValueError`.
    pub fn new(workers: i64) -> PyResult<Workers> {
        match workers {
            1 => Ok(Workers::Caller),
            -1 => Ok(Workers::Pool(None)),
            n if n >= 2 => {
                let n = usize::try_from(n).unwrap_or(usize::MAX).min(1024);
                let mut pools = POOLS.lock().unwrap_or_else(|p| p.into_inner());
                if let Some((_, p)) = pools.iter().find(|(size, _)| *size == n) {
                    return Ok(Workers::Pool(Some(p.clone())));
                }
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .thread_name(|i| format!("proxima-{i}"))
                    .build()
                    .map_err(|e| PyValueError::new_err(format!("workers={n}: {e}")))?;
                let pool = Arc::new(pool);
                pools.push((n, pool.clone()));
                Ok(Workers::Pool(Some(pool)))
            }
            n => Err(PyValueError::new_err(format!(
                "workers must be 1, a larger count, or -1 for one per core; got {n}"
            ))),
        }
    }

    /// Whether the batch runs in parallel.
    pub fn parallel(&self) -> bool {
        matches!(self, Workers::Pool(_))
    }

    /// Runs `f` where the batch belongs: on the calling thread, or inside the
    /// pool (so rayon's parallel iterators in `f` use its threads).
    pub fn run<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        match self {
            Workers::Caller | Workers::Pool(None) => f(),
            Workers::Pool(Some(pool)) => pool.install(f),
        }
    }
}
