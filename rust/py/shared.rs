//! Core objects shared between Python threads. A pyclass whose calls are cheap and made
//! once per step from a Python loop keeps its state in a `Mutex` and takes it with [`lock`]
//! (a Python-side lock would cost more than the step). The others are serialised by
//! `atomnav._stateful.Stateful` on the Python side.

use pyo3::prelude::*;
use std::sync::{Mutex, MutexGuard, TryLockError};

/// The guard of `m`: taken at once when free; otherwise waited for with the GIL released,
/// because the thread that holds it may be inside a call that released the GIL and needs
/// it back to finish (waiting with the GIL held would deadlock). A poisoned mutex is used
/// as it is: no panic is reachable in the core, and the state is what the last call left.
pub fn lock<'a, T: Send>(py: Python<'_>, m: &'a Mutex<T>) -> MutexGuard<'a, T> {
    match m.try_lock() {
        Ok(guard) => guard,
        Err(TryLockError::Poisoned(p)) => p.into_inner(),
        // wait, without the GIL, until the holder lets go; then try again with it (another
        // thread may take it first: then wait again)
        Err(TryLockError::WouldBlock) => {
            py.detach(|| drop(m.lock()));
            lock(py, m)
        }
    }
}
