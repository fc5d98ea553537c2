//! `ContactClouds` from untrusted bytes in the shared-memory layout (`graspopt_protocol::layout`):
//! reading never panics, and clouds that read back write again to clouds that read back equal
//! (and encode as bincode and decode back equal).
#![no_main]

use graspopt_protocol::{ContactClouds, Encoding, decode, encode, layout};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(msg) = layout::read_clouds(data) else {
        return;
    };
    let len = layout::clouds_len(&msg).expect("clouds that were read have a length");
    let mut out = vec![0xa5; len];
    layout::write_clouds(&msg, &mut out).expect("clouds that were read write again");
    let again = layout::read_clouds(&out).expect("written clouds read back");
    assert_eq!(again, msg, "the layout changed the clouds");
    let bincode = encode(&msg, Encoding::Bincode).expect("clouds encode as bincode");
    let back: ContactClouds = decode(&bincode, Encoding::Bincode).expect("and decode back");
    assert_eq!(back, msg, "bincode changed clouds read from the layout");
});
