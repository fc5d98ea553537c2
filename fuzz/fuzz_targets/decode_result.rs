//! `TrialResult` from untrusted bytes, bincode and JSON: see `common/mod.rs` for the checks.
#![no_main]

mod common;

use graspopt_protocol::TrialResult;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Validation checks the score only when there is no error: a failed trial's score may be
    // NaN in bincode, which JSON cannot carry.
    common::check::<TrialResult>(data, |m| m.score.is_finite());
});
