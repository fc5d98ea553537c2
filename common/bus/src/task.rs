//! A background task owned by a value: aborted when the value is dropped.

/// A spawned task that lives as long as its owner.
pub(crate) struct OwnedTask(tokio::task::JoinHandle<()>);

impl OwnedTask {
    /// Spawns `task` on the current runtime.
    pub(crate) fn spawn(task: impl std::future::Future<Output = ()> + Send + 'static) -> Self {
        OwnedTask(tokio::spawn(task))
    }
}

impl Drop for OwnedTask {
    fn drop(&mut self) {
        self.0.abort();
    }
}
