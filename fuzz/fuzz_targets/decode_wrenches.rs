//! `FingertipWrenches` from untrusted bytes, bincode and JSON: see `common/mod.rs` for the checks.
#![no_main]

mod common;

use graspopt_protocol::FingertipWrenches;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    common::check::<FingertipWrenches>(data, |_| true);
});
