//! A bench's hold on its output folder: [`ccpp_io::lock::FolderLock`] (shared with the Python
//! sweeps), registered with the interrupt cleanup so that Ctrl-C removes the lock file too.

use std::path::Path;

use anyhow::Result;

pub use ccpp_io::lock::LOCK_FILE;

/// The lock on an output folder, released (and its file removed) when dropped.
pub struct FolderLock {
    inner: ccpp_io::lock::FolderLock,
}

impl FolderLock {
    /// Takes the lock of the existing folder `folder` and registers its file with the
    /// interrupt cleanup.
    ///
    /// # Errors
    /// When another process holds it (`OUT is in use by another ccpp bench or sweep (pid N)`),
    /// or the lock file cannot be created or locked.
    pub fn take(folder: &Path) -> Result<Self> {
        let inner = crate::staging::register_lock(|| {
            let held = ccpp_io::lock::FolderLock::take(folder)?;
            Ok((held.path().to_path_buf(), held))
        })?;
        Ok(Self { inner })
    }
}

impl Drop for FolderLock {
    /// Forgets the file in the interrupt cleanup; the inner lock then removes it and releases
    /// the lock.
    fn drop(&mut self) {
        crate::staging::unregister_lock(self.inner.path());
    }
}
