//! Flags refused before a session opens.

use graspopt_bus::{Bus, BusConfig, BusError};

/// A `--shm-prefix` that iceoryx2 cannot use is refused by name, not left to a warning and
/// a silent fall-back to the network.
#[test]
fn an_unusable_shm_prefix_is_refused_by_name() {
    let rt = tokio::runtime::Runtime::new().unwrap();
    for (prefix, why) in [
        ("", "the prefix is empty"),
        ("a/b", "contains '/'"),
        (".hidden", "starts with '.'"),
    ] {
        let mut args = BusConfig::loopback(Vec::new(), Vec::new());
        args.shm_prefix = Some(prefix.to_string());
        match rt.block_on(Bus::open(&args)) {
            Err(e @ BusError::Config(_)) => {
                let msg = e.to_string();
                assert!(msg.contains("--shm-prefix") && msg.contains(why), "{msg}");
            }
            Err(e) => panic!("{prefix:?}: not a configuration error: {e}"),
            Ok(_) => panic!("{prefix:?} was accepted"),
        }
    }
}
