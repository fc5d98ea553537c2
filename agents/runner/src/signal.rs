//! The signals that stop a run or an agent cleanly.

use std::future::Future;

/// A future that resolves on Ctrl-C (SIGINT), SIGTERM or SIGHUP (the terminal closed). The
/// handlers are registered when this is called, not when the future is first polled: a
/// signal that arrives in between (a run that has just recorded itself, say) is not lost,
/// and does not kill the process with the default action.
pub fn shutdown_signal() -> impl Future<Output = ()> + Send + 'static {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{Signal, SignalKind, signal};
        let interrupt = signal(SignalKind::interrupt()).ok();
        let terminate = signal(SignalKind::terminate()).ok();
        let hangup = signal(SignalKind::hangup()).ok();
        async fn wait(signal: Option<Signal>) {
            match signal {
                Some(mut s) => {
                    s.recv().await;
                }
                None => std::future::pending::<()>().await,
            }
        }
        async move {
            tokio::select! {
                _ = wait(interrupt) => {},
                _ = wait(terminate) => {},
                _ = wait(hangup) => {},
            }
        }
    }
    #[cfg(not(unix))]
    {
        async {
            let _ = tokio::signal::ctrl_c().await;
        }
    }
}
