//! The memory limit a bench shares among the runs it holds at once.

use std::sync::{Condvar, Mutex};

/// The memory limit of a bench, shared by the runs it holds at once: a run starts when its
/// estimate fits beside those of the runs in progress (or when none is in progress, so every
/// run the limit admits alone gets its turn). Checked per run only, `--max-memory 341` with
/// `--jobs 4` peaked at 861 MB.
pub(crate) struct MemoryBudget {
    limit: f64,
    used: Mutex<f64>,
    freed: Condvar,
}

/// A run's share of the [`MemoryBudget`], given back when dropped.
pub(crate) struct Grant<'a> {
    budget: &'a MemoryBudget,
    bytes: f64,
}

impl MemoryBudget {
    pub(crate) fn new(limit_mb: u64) -> Self {
        Self {
            limit: limit_mb as f64 * 1024.0 * 1024.0,
            used: Mutex::new(0.0),
            freed: Condvar::new(),
        }
    }

    /// Waits until `bytes` fit beside the runs in progress (or none is in progress).
    pub(crate) fn take(&self, bytes: f64) -> Grant<'_> {
        let mut used = self
            .used
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        while *used > 0.0 && *used + bytes > self.limit {
            used = self
                .freed
                .wait(used)
                .unwrap_or_else(std::sync::PoisonError::into_inner);
        }
        *used += bytes;
        Grant {
            budget: self,
            bytes,
        }
    }
}

impl Drop for Grant<'_> {
    fn drop(&mut self) {
        let mut used = self
            .budget
            .used
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        *used = (*used - self.bytes).max(0.0);
        self.budget.freed.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs that do not fit beside each other under the limit take turns; one that fits alone
    /// always gets its turn (no deadlock), and runs that fit together run together.
    #[test]
    fn runs_take_turns_under_the_memory_limit() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let mb = 1024.0 * 1024.0;
        let budget = MemoryBudget::new(100);
        let first = budget.take(60.0 * mb);
        let second_started = AtomicBool::new(false);
        std::thread::scope(|scope| {
            let h = scope.spawn(|| {
                let _g = budget.take(60.0 * mb);
                second_started.store(true, Ordering::SeqCst);
            });
            std::thread::sleep(std::time::Duration::from_millis(100));
            assert!(
                !second_started.load(Ordering::SeqCst),
                "a run started beside one it does not fit beside"
            );
            drop(first);
            h.join().unwrap();
        });
        assert!(second_started.load(Ordering::SeqCst));
        // Two that fit together are held together; one larger than the limit runs alone.
        let a = budget.take(40.0 * mb);
        let b = budget.take(40.0 * mb);
        drop((a, b));
        let huge = budget.take(500.0 * mb);
        drop(huge);
        assert_eq!(*budget.used.lock().unwrap(), 0.0);
    }
}
