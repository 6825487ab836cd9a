//! Independent computations side by side.
//!
//! The automatic term selection measures a level with two or three independent eigen-solves,
//! and the final modes solve two independent pencils. Each computation is sequential inside
//! and gets the same inputs whatever thread runs it, so the results do not depend on the
//! number of threads.
//!
//! They run on a pool of this module's own, not rayon's global one, and the pool belongs to
//! the process that made it: a process forked after a run (Python's `multiprocessing` forks
//! by default on Linux) has no thread but the calling one, and a pool made before the fork
//! would queue the child's work for workers that do not exist there, for ever. A child makes
//! a pool of its own (the parent's, unusable there, is left alone). Persistent workers keep
//! their allocator heaps between calls; threads started per call cost a large model's pages
//! afresh every time (measured: 49 ms against 43 ms for the composite spacecraft to 1e-5).
//!
//! The number of threads: rayon's default (`RAYON_NUM_THREADS` when set, else the machine's
//! available parallelism).

use rayon::prelude::*;
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::sync::{Arc, Mutex};

/// This process's pool (None when no thread could be started, or when the caller already
/// runs on a rayon worker — a Monte Carlo run on its `--jobs` pool: waiting there for
/// another pool would let the worker steal further runs onto the same stack, nesting without
/// bound, and would add threads beyond `--jobs`; such a caller computes on its own thread).
fn pool() -> Option<Arc<ThreadPool>> {
    static POOL: Mutex<Option<(u32, Arc<ThreadPool>)>> = Mutex::new(None);
    if rayon::current_thread_index().is_some() {
        return None;
    }
    let pid = std::process::id();
    let lock = || POOL.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((owner, pool)) = lock().as_ref() {
        if *owner == pid {
            return Some(pool.clone());
        }
    }
    // Built with the lock released: a fork while the threads start (another thread of a
    // Python program) must not leave the child a locked mutex.
    let fresh = Arc::new(ThreadPoolBuilder::new().build().ok()?);
    let mut slot = lock();
    match slot.as_ref() {
        Some((owner, pool)) if *owner == pid => Some(pool.clone()),
        _ => {
            // Made before a fork: its workers live in the parent only. Dropping it would
            // signal them; forgetting it leaves the child's memory as the fork gave it.
            if let Some(stale) = slot.replace((pid, fresh.clone())) {
                std::mem::forget(stale);
            }
            Some(fresh)
        }
    }
}

/// `f` of every item, in the items' order, side by side.
pub fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync + Send) -> Vec<R> {
    match pool().filter(|p| items.len() > 1 && p.current_num_threads() > 1) {
        Some(p) => p.install(|| items.par_iter().map(&f).collect()),
        None => items.iter().map(&f).collect(),
    }
}

/// `(a(), b())`, side by side when `worth` it (a large job).
pub fn join<A: Send, B: Send>(
    worth: bool,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    match pool().filter(|p| worth && p.current_num_threads() > 1) {
        Some(p) => p.join(a, b),
        None => (a(), b()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_keeps_the_order_and_join_both_results() {
        let items: Vec<usize> = (0..17).collect();
        assert_eq!(
            map(&items, |i| i * i),
            items.iter().map(|i| i * i).collect::<Vec<_>>()
        );
        assert_eq!(map(&[] as &[usize], |i| *i), Vec::<usize>::new());
        assert_eq!(join(true, || 1, || "b"), (1, "b"));
        assert_eq!(join(false, || 2, || 3), (2, 3));
    }

    /// On a worker of another pool (a Monte Carlo run) nothing is handed to this module's
    /// pool: the work stays on the caller's thread, and the results are the same.
    #[test]
    fn a_rayon_worker_computes_on_its_own_thread() {
        let outer = ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("pool");
        let items: Vec<usize> = (0..9).collect();
        let (no_pool, squares) = outer.install(|| (pool().is_none(), map(&items, |i| i * i)));
        assert!(no_pool);
        assert_eq!(squares, items.iter().map(|i| i * i).collect::<Vec<_>>());
    }
}
