//! The start-up probe that chooses shared memory or the network, and the removal of resources
//! left by processes that died.

use super::*;
use crate::subscriber::SubscriberPorts;

/// True if iceoryx2 works here: a throwaway service under `config.prefix`
/// carries one message from a publisher to a subscriber. Takes a few
/// milliseconds; call it once at start-up to choose between shared memory and
/// the network.
pub fn available(config: &ShmConfig) -> bool {
    std::panic::catch_unwind(|| probe(config).is_ok()).unwrap_or(false)
}

pub(super) fn probe(config: &ShmConfig) -> Result<()> {
    static PROBES: AtomicU64 = AtomicU64::new(0);
    let service = format!(
        "{}/{}/{}",
        config.probe_service,
        std::process::id(),
        PROBES.fetch_add(1, Ordering::Relaxed)
    );
    let config = ShmConfig {
        max_publishers: 1,
        max_subscribers: 1,
        subscriber_buffer: 1,
        initial_payload: 64,
        ..config.clone()
    };
    // Publisher first: the subscriber connects to it while opening, and no
    // thread of the subscriber's has to acknowledge it.
    let publisher = PublisherPorts::open(
        &config,
        &service,
        Arc::new(AtomicBool::new(false)),
        Arc::new(AtomicU64::new(0)),
    )?;
    let subscriber = SubscriberPorts::open(&config, &service)?;
    let message = b"graspopt shm probe";
    publisher.send(&service, message)?;
    match subscriber.subscriber.receive() {
        Ok(Some(sample)) if sample.payload() == message => Ok(()),
        Ok(_) => Err(ShmError::Service {
            service,
            operation: "probe",
            detail: "the probe message did not arrive".into(),
        }),
        Err(e) => Err(service_err(&service, "probe receive")(e)),
    }
}

/// Removes the resources of dead processes (nodes whose process is gone,
/// with their ports, connections and services nobody else uses) under
/// `config.prefix`, and returns how many dead nodes were removed. Opening a
/// publisher or subscriber also does this; call it at start-up to reclaim
/// shared memory early.
pub fn clean_stale(config: &ShmConfig) -> Result<usize> {
    init_logging();
    let ice = config.iceoryx()?;
    let mut removed = 0;
    Node::<Ipc>::list(&ice, |state| {
        if let NodeState::Dead(dead) = state
            && dead.blocking_remove_stale_resources(CLEANUP_WAIT).is_ok()
        {
            removed += 1;
        }
        CallbackProgression::Continue
    })
    .map_err(|e| ShmError::Host {
        prefix: config.prefix.clone(),
        operation: "list nodes",
        detail: e.to_string(),
    })?;
    Ok(removed)
}

/// Runs [`clean_stale`] for every prefix that starts with `start` (for
/// instance [`PREFIX_BASE`]) and has nodes on this host; returns how many
/// dead nodes were removed in all.
///
/// With one prefix per run, [`clean_stale`] at start-up only sees the new
/// run's prefix, so what a crashed earlier run left (its shared memory
/// included) would stay until someone used that prefix again; this finds
/// those prefixes. Best effort: a prefix whose cleanup fails is skipped. It
/// reads iceoryx2's node directory, laid out (in iceoryx2 0.10) as
/// `<root>/nodes/<node id>/<prefix>node.details`.
pub fn clean_stale_prefixes(start: &str) -> Result<usize> {
    init_logging();
    let config = Config::default();
    let node_dir = config.global.node_dir();
    let suffix = format!("node{}", config.global.node.static_config_suffix.as_str());
    let nodes = match std::fs::read_dir(node_dir.as_str()) {
        Ok(nodes) => nodes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
        Err(e) => {
            return Err(ShmError::Host {
                prefix: start.to_owned(),
                operation: "list the node directory",
                detail: format!("{node_dir}: {e}"),
            });
        }
    };
    let mut prefixes = std::collections::BTreeSet::new();
    for node in nodes.flatten() {
        // Node monitors are files next to the node directories: skipped.
        let Ok(files) = std::fs::read_dir(node.path()) else {
            continue;
        };
        for file in files.flatten() {
            if let Some(prefix) = file
                .file_name()
                .to_str()
                .and_then(|name| name.strip_suffix(suffix.as_str()))
                && prefix.starts_with(start)
            {
                prefixes.insert(prefix.to_owned());
            }
        }
    }
    Ok(prefixes
        .into_iter()
        .filter_map(|prefix| {
            clean_stale(&ShmConfig {
                prefix,
                ..ShmConfig::default()
            })
            .ok()
        })
        .sum())
}
