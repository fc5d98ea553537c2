//! `ObjectEstimate` from untrusted bytes, bincode and JSON: see `common/mod.rs` for the checks.
#![no_main]

mod common;

use graspopt_protocol::ObjectEstimate;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::check::<ObjectEstimate>(data, |_| true);
});
