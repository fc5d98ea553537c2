//! The open-file limit of a run with every agent in one process.
//!
//! Each hand worker of an embedded run holds about 25 descriptors: its shared-memory node,
//! ports and their event sockets, and its share of the metric agent's (measured with
//! `graspopt run --method random`: 67 descriptors with 1 worker, 842 with 32, 1,642 with
//! 64). A shell's default soft limit is often 1,024, which about 40 workers exceed; past it
//! sockets and shared-memory segments fail to open one by one, as lost trials and fallbacks
//! far from the cause. So a run raises its soft limit up to the hard one when it needs more,
//! and refuses to start, naming both numbers, when even the hard limit is too low.

use crate::error::RunnerError;

type Result<T> = std::result::Result<T, RunnerError>;
use nix::sys::resource::{Resource, getrlimit, setrlimit};

/// Descriptors of an embedded run apart from its hand workers (the Zenoh session, the
/// journal, the agents but the hands), with room to spare.
const BASE: u64 = 128;
/// Descriptors per hand worker, rounded up from the measured 25.
const PER_WORKER: u64 = 28;

/// The open files an embedded run with `workers` hand workers needs.
pub fn needed(workers: usize) -> u64 {
    BASE.saturating_add(PER_WORKER.saturating_mul(workers as u64))
}

/// What [`ensure`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Limit {
    /// The soft limit was enough.
    Enough(u64),
    /// The soft limit was raised from the first number to the second.
    Raised(u64, u64),
}

/// Makes sure this process may open the files a run of `workers` hand workers needs,
/// raising the soft limit towards the hard one if needed.
pub fn ensure(workers: usize) -> Result<Limit> {
    let need = needed(workers);
    let (soft, hard) = getrlimit(Resource::RLIMIT_NOFILE)?;
    check(workers, need, soft, hard)?;
    if soft >= need {
        return Ok(Limit::Enough(soft));
    }
    // Raised to the hard limit, as servers do: descriptors cost nothing until opened.
    setrlimit(Resource::RLIMIT_NOFILE, hard, hard)?;
    Ok(Limit::Raised(soft, hard))
}

/// The refusal when even the hard limit is too low.
fn check(workers: usize, need: u64, soft: u64, hard: u64) -> Result<()> {
    if hard < need {
        let most = hard.saturating_sub(BASE) / PER_WORKER;
        return Err(RunnerError::OpenFiles {
            workers,
            need,
            hard,
            soft,
            most,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limit_too_low_even_when_raised_is_refused_with_the_numbers() {
        assert_eq!(needed(64), 128 + 28 * 64);
        assert!(check(64, needed(64), 1024, 4096).is_ok());
        let e = check(64, needed(64), 1024, 1024).unwrap_err().to_string();
        assert!(
            e.contains("--workers 64 needs about 1920 open files")
                && e.contains("at most 1024")
                && e.contains("use at most 32 workers"),
            "{e}"
        );
    }

    #[test]
    fn a_run_that_fits_the_soft_limit_changes_nothing() {
        let (soft, hard) = getrlimit(Resource::RLIMIT_NOFILE).unwrap();
        assert_eq!(ensure(1).unwrap(), Limit::Enough(soft));
        assert_eq!(getrlimit(Resource::RLIMIT_NOFILE).unwrap(), (soft, hard));
    }
}
