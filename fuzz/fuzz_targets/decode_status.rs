//! `RunStatus` from untrusted bytes, bincode and JSON: see `common/mod.rs` for the checks.
#![no_main]

mod common;

use graspopt_protocol::RunStatus;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    // Validation leaves the scores unchecked: bincode can carry NaN there, JSON cannot.
    common::check::<RunStatus>(data, |m| {
        common::finite(&m.best_history)
            && m.best
                .as_ref()
                .is_none_or(|b| b.score.is_finite() && common::finite(&b.params))
    });
});
