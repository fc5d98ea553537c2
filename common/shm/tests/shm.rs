//! Integration tests over real iceoryx2 shared memory. Each test has its own
//! prefix, so tests running in parallel never see each other's services.
//!
//! The SIGKILL tests re-invoke this test binary (`--exact <child> --nocapture`)
//! with `SHM_TEST_CHILD` set; the child entry points do nothing otherwise.

use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::sync::{Arc, Barrier};
use std::thread;
use std::time::{Duration, Instant};

use graspopt_shm::{
    MAX_PREFIX_LEN, ShmConfig, ShmError, ShmPublisher, ShmSubscriber, available, clean_stale,
    clean_stale_prefixes, run_prefix,
};

const WAIT: Duration = Duration::from_secs(20);
const CHILD_ROLE: &str = "SHM_TEST_CHILD";
const CHILD_PREFIX: &str = "SHM_TEST_PREFIX";
const CHILD_SERVICE: &str = "SHM_TEST_SERVICE";

/// A prefix no other test (nor an earlier run of this one) uses.
fn prefix(tag: &str) -> (String, Cleanup) {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    let p = format!("gst{tag}_{}_{nanos:x}_", std::process::id());
    assert!(p.len() <= MAX_PREFIX_LEN, "{p}");
    (p.clone(), Cleanup(p))
}

/// iceoryx2 keeps one 16-byte segment per prefix in /dev/shm (its node
/// counter) after every node is gone; the library cannot remove it without
/// unsafe code, but a test owns its prefix and removes it when done. Declare
/// it before the ports, so that it is dropped after them.
struct Cleanup(String);

impl Drop for Cleanup {
    fn drop(&mut self) {
        let Ok(entries) = std::fs::read_dir("/dev/shm") else {
            return;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if name.starts_with(&self.0) && name.ends_with(".global_mgmt") {
                let _ = std::fs::remove_file(entry.path());
            }
        }
    }
}

fn config(tag: &str) -> (ShmConfig, Cleanup) {
    let (prefix, cleanup) = prefix(tag);
    let config = ShmConfig {
        prefix,
        ..ShmConfig::default()
    };
    (config, cleanup)
}

/// A subscriber that copies each message into a channel.
fn collect(config: &ShmConfig, service: &str) -> (ShmSubscriber, Receiver<Vec<u8>>) {
    let (tx, rx) = channel();
    let subscriber = ShmSubscriber::open(config, service, move |bytes: &[u8]| {
        let _ = tx.send(bytes.to_vec());
    })
    .unwrap();
    (subscriber, rx)
}

fn payload(index: usize, len: usize) -> Vec<u8> {
    (0..len)
        .map(|j| (j.wrapping_mul(31) ^ (j >> 8) ^ index.wrapping_mul(7)) as u8)
        .collect()
}

fn wait_until(what: &str, mut condition: impl FnMut() -> bool) {
    let start = Instant::now();
    while !condition() {
        assert!(start.elapsed() < WAIT, "timed out waiting for {what}");
        thread::sleep(Duration::from_millis(2));
    }
}

#[test]
fn messages_of_1_byte_to_2_mib_arrive_in_order() {
    let (config, _cleanup) = config("order");
    let service = "graspopt/test/order";
    let (subscriber, rx) = collect(&config, service);
    let publisher = ShmPublisher::open(&config, service).unwrap();

    let sizes: Vec<usize> = (0..100)
        .map(|i| 2f64.powf(21.0 * i as f64 / 99.0).round() as usize)
        .collect();
    assert_eq!((sizes[0], sizes[99]), (1, 2 << 20));
    for (i, &len) in sizes.iter().enumerate() {
        publisher.send(&payload(i, len)).unwrap();
    }
    for (i, &len) in sizes.iter().enumerate() {
        let got = rx.recv_timeout(WAIT).unwrap();
        assert_eq!(
            got.len(),
            len,
            "message {i} errors {} discarded {}",
            subscriber.receive_errors(),
            publisher.discarded_deliveries()
        );
        assert!(got == payload(i, len), "message {i} differs");
    }
    assert!(rx.recv_timeout(Duration::from_millis(50)).is_err());
    assert_eq!(publisher.discarded_deliveries(), 0);
    assert_eq!(subscriber.receive_errors(), 0);
}

/// `send_with` hands a zero-filled slice of the asked length to the caller, sends what it
/// wrote, and sends nothing when it fails.
#[test]
fn send_with_writes_into_the_sample_and_sends_nothing_on_error() {
    let (config, _cleanup) = config("with");
    let service = "graspopt/test/with";
    let (_subscriber, rx) = collect(&config, service);
    let publisher = ShmPublisher::open(&config, service).unwrap();
    for len in [1, 100, 300_000] {
        publisher
            .send_with(len, |buf: &mut [u8]| {
                assert_eq!(buf.len(), len);
                assert!(buf.iter().all(|&b| b == 0), "the slice is zero-filled");
                buf[len - 1] = 7;
                Ok::<_, ShmError>(())
            })
            .unwrap();
        let got = rx.recv_timeout(WAIT).unwrap();
        assert_eq!(got.len(), len);
        assert_eq!(got[len - 1], 7);
    }
    let refused = publisher.send_with(16, |buf: &mut [u8]| {
        buf[0] = 1;
        Err(ShmError::InvalidConfig("the caller's own error".into()))
    });
    assert!(matches!(refused, Err(ShmError::InvalidConfig(_))));
    assert!(rx.recv_timeout(Duration::from_millis(100)).is_err());
    // The sample was returned: the next send works.
    publisher.send(b"after").unwrap();
    assert_eq!(rx.recv_timeout(WAIT).unwrap(), b"after");
}

/// More than 16 publishers on one service (the hands of a run on one host): the default
/// capacity admits them (it was 16). The e2e test `shm::` runs 64 hands; opening a publisher
/// takes a while on a host whose iceoryx2 node directory holds many dead nodes.
#[test]
fn the_default_service_admits_more_than_16_publishers() {
    let (config, _cleanup) = config("many");
    let service = "graspopt/test/many";
    let (_subscriber, rx) = collect(&config, service);
    let publishers: Vec<ShmPublisher> = (0..24)
        .map(|i| {
            ShmPublisher::open(&config, service).unwrap_or_else(|e| panic!("publisher {i}: {e}"))
        })
        .collect();
    for (i, p) in publishers.iter().enumerate() {
        p.send(&[i as u8]).unwrap();
    }
    let mut got: Vec<u8> = (0..24).map(|_| rx.recv_timeout(WAIT).unwrap()[0]).collect();
    got.sort();
    assert_eq!(got, (0..24).collect::<Vec<u8>>());
}

#[test]
fn two_publishers_on_two_threads_all_arrive() {
    let (config, _cleanup) = config("two");
    let service = "graspopt/test/two";
    let (_subscriber, rx) = collect(&config, service);
    const PER_PUBLISHER: u32 = 300;

    let barrier = Arc::new(Barrier::new(2));
    let senders: Vec<_> = (0..2u8)
        .map(|id| {
            let config = config.clone();
            let barrier = barrier.clone();
            thread::spawn(move || {
                let publisher = ShmPublisher::open(&config, service).unwrap();
                barrier.wait();
                for seq in 0..PER_PUBLISHER {
                    let mut message = vec![id];
                    message.extend_from_slice(&seq.to_le_bytes());
                    message.resize(5 + (seq as usize * 97) % 20_000, id);
                    publisher.send(&message).unwrap();
                }
            })
        })
        .collect();
    for sender in senders {
        sender.join().unwrap();
    }

    let mut next = [0u32; 2];
    for _ in 0..2 * PER_PUBLISHER {
        let message = rx.recv_timeout(WAIT).unwrap();
        let id = message[0] as usize;
        let seq = u32::from_le_bytes(message[1..5].try_into().unwrap());
        assert_eq!(seq, next[id], "publisher {id} out of order");
        assert_eq!(message.len(), 5 + (seq as usize * 97) % 20_000);
        assert!(message[5..].iter().all(|&b| b == id as u8));
        next[id] += 1;
    }
    assert_eq!(next, [PER_PUBLISHER; 2]);
    assert!(rx.recv_timeout(Duration::from_millis(50)).is_err());
}

/// iceoryx2 drops, rather than waits, for a subscriber whose queue is full
/// before it has connected to the publisher; `open` on either side makes sure
/// the connection exists before returning. A queue of 2 and a slow callback
/// make any gap show.
#[test]
fn bursts_right_after_open_lose_nothing() {
    let (config, _cleanup) = config("burst");
    let config = ShmConfig {
        subscriber_buffer: 2,
        ..config
    };
    let slow_collect = |service: &'static str| {
        let (tx, rx) = channel();
        let subscriber = ShmSubscriber::open(&config, service, move |bytes: &[u8]| {
            thread::sleep(Duration::from_micros(100));
            let _ = tx.send(bytes.to_vec());
        })
        .unwrap();
        (subscriber, rx)
    };
    let check = |publisher: &ShmPublisher, rx: &Receiver<Vec<u8>>| {
        for i in 0..200u32 {
            publisher.send(&i.to_le_bytes()).unwrap();
        }
        for i in 0..200u32 {
            assert_eq!(rx.recv_timeout(WAIT).unwrap(), i.to_le_bytes());
        }
        assert_eq!(publisher.discarded_deliveries(), 0);
    };

    // Subscriber first, then a publisher that sends at once.
    let (_first, rx) = slow_collect("graspopt/test/burst-a");
    let publisher = ShmPublisher::open(&config, "graspopt/test/burst-a").unwrap();
    check(&publisher, &rx);

    // Publisher first, then a subscriber; the publisher sends at once.
    let publisher = ShmPublisher::open(&config, "graspopt/test/burst-b").unwrap();
    let (_second, rx) = slow_collect("graspopt/test/burst-b");
    check(&publisher, &rx);
}

#[test]
fn subscriber_count_follows_subscribers() {
    let (config, _cleanup) = config("count");
    let service = "graspopt/test/count";
    let publisher = ShmPublisher::open(&config, service).unwrap();
    assert_eq!(publisher.subscriber_count().unwrap(), 0);

    let (subscriber, rx) = collect(&config, service);
    wait_until("one subscriber", || {
        publisher.subscriber_count().unwrap() == 1
    });
    publisher.send(b"hello").unwrap();
    assert_eq!(rx.recv_timeout(WAIT).unwrap(), b"hello");

    let clone = publisher.clone();
    drop(subscriber);
    wait_until("no subscriber", || clone.subscriber_count().unwrap() == 0);
    // Sending to nobody is fine.
    publisher.send(b"nobody").unwrap();
}

#[test]
fn dropping_a_subscriber_stops_its_callbacks() {
    let (config, _cleanup) = config("drop");
    let service = "graspopt/test/drop";
    let calls = Arc::new(AtomicU64::new(0));
    let subscriber = {
        let calls = calls.clone();
        ShmSubscriber::open(&config, service, move |_: &[u8]| {
            calls.fetch_add(1, Ordering::SeqCst);
        })
        .unwrap()
    };

    // Keep publishing while the subscriber is dropped and after.
    let stop = Arc::new(AtomicBool::new(false));
    let sender = {
        let (config, stop) = (config.clone(), stop.clone());
        thread::spawn(move || {
            let publisher = ShmPublisher::open(&config, service).unwrap();
            let message = vec![7u8; 1024];
            while !stop.load(Ordering::SeqCst) {
                publisher.send(&message).unwrap();
                thread::sleep(Duration::from_micros(50));
            }
            publisher.subscriber_count().unwrap()
        })
    };
    wait_until("100 callbacks", || calls.load(Ordering::SeqCst) >= 100);

    let start = Instant::now();
    drop(subscriber);
    let took = start.elapsed();
    let calls_at_drop = calls.load(Ordering::SeqCst);
    thread::sleep(Duration::from_millis(150));
    stop.store(true, Ordering::SeqCst);
    let subscribers_left = sender.join().unwrap();

    assert_eq!(calls.load(Ordering::SeqCst), calls_at_drop);
    // Not a speed figure (this machine is shared with other tests): only a
    // drop that waits on a message, not its stop flag, takes this long.
    assert!(took < DROP_BOUND, "drop took {took:?}");
    assert_eq!(subscribers_left, 0);
}

/// Longer than any scheduling delay, far shorter than forever: a subscriber
/// thread that blocked until the next message would never return when idle.
const DROP_BOUND: Duration = Duration::from_secs(3);

#[test]
fn dropping_an_idle_subscriber_returns() {
    let (config, _cleanup) = config("idle-drop");
    let service = "graspopt/test/idle-drop";
    let (subscriber, rx) = collect(&config, service);
    let publisher = ShmPublisher::open(&config, service).unwrap();
    publisher.send(b"one").unwrap();
    assert_eq!(rx.recv_timeout(WAIT).unwrap(), b"one");

    // Nothing is sent any more: once the thread sleeps, it must notice the
    // stop by itself.
    thread::sleep(Duration::from_millis(300));
    let start = Instant::now();
    drop(subscriber);
    let took = start.elapsed();
    assert!(took < DROP_BOUND, "drop took {took:?}");
    wait_until("no subscriber", || {
        publisher.subscriber_count().unwrap() == 0
    });
}

#[test]
fn payload_of_64_mib_and_empty_payload() {
    let (config, _cleanup) = config("big");
    let service = "graspopt/test/big";
    let (_subscriber, rx) = collect(&config, service);
    let publisher = ShmPublisher::open(&config, service).unwrap();
    let big = payload(3, 64 << 20);
    publisher.send(&big).unwrap();
    publisher.send(&[]).unwrap();
    publisher.send(b"after").unwrap();
    assert!(rx.recv_timeout(WAIT).unwrap() == big);
    assert_eq!(rx.recv_timeout(WAIT).unwrap(), b"");
    assert_eq!(rx.recv_timeout(WAIT).unwrap(), b"after");
}

#[test]
fn probe_clean_and_bad_names() {
    let (config, _cleanup) = config("misc");
    assert!(available(&config));
    assert_eq!(clean_stale(&config).unwrap(), 0);

    let bad = ShmConfig {
        prefix: "graspopt/run 1".into(),
        ..config.clone()
    };
    let err = ShmPublisher::open(&bad, "graspopt/test/misc").unwrap_err();
    assert!(matches!(err, ShmError::InvalidConfig(_)), "{err}");
    assert!(err.to_string().contains("graspopt/run 1"), "{err}");
    assert!(!available(&bad));
    assert!(clean_stale(&bad).is_err());

    let err = ShmSubscriber::open(&config, "", |_: &[u8]| {}).unwrap_err();
    assert!(matches!(err, ShmError::InvalidServiceName { .. }), "{err}");
    assert!(ShmConfig::for_run("run 7/α").validate().is_ok());
    assert_eq!(run_prefix("run 7"), "graspopt_run_7_");
}

#[test]
fn capacity_errors_name_the_service() {
    let (config, _cleanup) = config("cap");
    let config = ShmConfig {
        max_publishers: 1,
        ..config
    };
    let service = "graspopt/test/cap";
    let _first = ShmPublisher::open(&config, service).unwrap();
    let err = ShmPublisher::open(&config, service).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains(service) && text.contains("create publisher"),
        "{text}"
    );
}

// ---------------------------------------------------------------------------
// A process killed with SIGKILL must not keep others from the service.

/// Both sides of the SIGKILL tests: one publisher and one subscriber at most,
/// so a slot held by the dead process would make a new open fail.
fn single_config(prefix: String) -> ShmConfig {
    ShmConfig {
        prefix,
        max_publishers: 1,
        max_subscribers: 1,
        subscriber_buffer: 8,
        delivery_timeout: Duration::from_secs(5),
        ..ShmConfig::default()
    }
}

fn spawn_child(role: &str, entry: &str, prefix: &str, service: &str) -> Child {
    Command::new(std::env::current_exe().unwrap())
        .args(["--exact", entry, "--nocapture", "--test-threads=1"])
        .env(CHILD_ROLE, role)
        .env(CHILD_PREFIX, prefix)
        .env(CHILD_SERVICE, service)
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap()
}

fn child_env(role: &str) -> Option<(ShmConfig, String)> {
    if std::env::var(CHILD_ROLE).ok()? != role {
        return None;
    }
    let prefix = std::env::var(CHILD_PREFIX).unwrap();
    let service = std::env::var(CHILD_SERVICE).unwrap();
    Some((single_config(prefix), service))
}

/// Child side: publishes numbered 256 KiB messages until killed.
#[test]
fn child_publisher_entry() {
    let Some((config, service)) = child_env("publisher") else {
        return;
    };
    let publisher = ShmPublisher::open(&config, &service).unwrap();
    let mut message = vec![0u8; 256 * 1024];
    for seq in 0u64.. {
        message[..8].copy_from_slice(&seq.to_le_bytes());
        publisher.send(&message).unwrap();
    }
}

/// Child side: subscribes, with a callback that never returns after the
/// first message, so its buffer fills up; waits to be killed.
#[test]
fn child_subscriber_entry() {
    let Some((config, service)) = child_env("subscriber") else {
        return;
    };
    let _subscriber = ShmSubscriber::open(&config, &service, |_: &[u8]| {
        thread::sleep(Duration::from_secs(3600));
    })
    .unwrap();
    thread::sleep(Duration::from_secs(3600));
}

#[test]
fn publisher_killed_mid_send_does_not_block_the_service() {
    let (prefix, _cleanup) = prefix("kpub");
    let config = single_config(prefix.clone());
    let service = "graspopt/test/killed-publisher";

    let (old_subscriber, rx) = collect(&config, service);
    let mut child = spawn_child("publisher", "child_publisher_entry", &prefix, service);
    // The child is publishing: ten messages arrived.
    for _ in 0..10 {
        let message = rx.recv_timeout(WAIT).expect("child publisher never sent");
        assert_eq!(message.len(), 256 * 1024);
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();

    // The dead node is found and removed (its publisher held the only slot).
    // Before anything else here drops or creates a node: both clean up too.
    assert_eq!(clean_stale(&config).unwrap(), 1);
    drop(old_subscriber);

    let (_subscriber, rx) = collect(&config, service);
    let publisher = ShmPublisher::open(&config, service).unwrap();
    assert_eq!(publisher.subscriber_count().unwrap(), 1);
    for i in 0..20 {
        publisher.send(&payload(i, 1000 + i)).unwrap();
    }
    for i in 0..20 {
        assert!(rx.recv_timeout(WAIT).unwrap() == payload(i, 1000 + i));
    }
}

#[test]
fn subscriber_killed_with_full_buffer_does_not_block_the_service() {
    let (prefix, _cleanup) = prefix("ksub");
    let config = single_config(prefix.clone());
    let service = "graspopt/test/killed-subscriber";

    let publisher = ShmPublisher::open(&config, service).unwrap();
    let mut child = spawn_child("subscriber", "child_subscriber_entry", &prefix, service);
    wait_until("the child subscriber", || {
        publisher.subscriber_count().unwrap() == 1
    });
    // Fill the child's buffer: its callback never returns after the first
    // message, so it holds one and queues `subscriber_buffer` more.
    for i in 0..=config.subscriber_buffer {
        publisher.send(&payload(i, 64)).unwrap();
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();

    // Its subscriber held the only slot: opening a new one needs the dead
    // node removed, which opening does by itself.
    let (_subscriber, rx) = collect(&config, service);
    let start = Instant::now();
    for i in 0..50 {
        publisher.send(&payload(i, 64)).unwrap();
    }
    let took = start.elapsed();
    for i in 0..50 {
        assert!(rx.recv_timeout(WAIT).unwrap() == payload(i, 64));
    }
    // No send waited for the dead subscriber's full queue.
    assert!(took < config.delivery_timeout, "sends took {took:?}");
    assert_eq!(publisher.discarded_deliveries(), 0);
    assert_eq!(publisher.subscriber_count().unwrap(), 1);
}

#[test]
fn stale_nodes_of_an_earlier_run_are_found_by_prefix() {
    let (prefix, _cleanup) = prefix("kall");
    let config = single_config(prefix.clone());
    let service = "graspopt/test/earlier-run";
    let mut child = spawn_child("publisher", "child_publisher_entry", &prefix, service);
    {
        let (_subscriber, rx) = collect(&config, service);
        rx.recv_timeout(WAIT).expect("child publisher never sent");
    }
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();

    // Only the start of the prefix is given, as a new run would.
    let start = &prefix[..prefix.len() - 3];
    assert_eq!(clean_stale_prefixes(start).unwrap(), 1);
    assert_eq!(clean_stale(&config).unwrap(), 0);
    assert_eq!(clean_stale_prefixes("no-such-prefix-").unwrap(), 0);
}

/// Descriptors this process holds on files of `prefix` (shared memory, sockets' paths).
fn descriptors_of(prefix: &str) -> usize {
    std::fs::read_dir("/proc/self/fd")
        .unwrap()
        .flatten()
        .filter_map(|e| std::fs::read_link(e.path()).ok())
        .filter(|target| target.to_string_lossy().contains(prefix))
        .count()
}

/// A host's hands share one service: each hand's ports hold a fixed number of descriptors,
/// not one per other hand (the wake-ups and acknowledgements are two event services, and a
/// notifier connects only to the listeners of its own).
#[test]
fn descriptors_grow_linearly_with_publishers() {
    let (config, _cleanup) = config("fds");
    let service = "graspopt/test/fds";
    let (tx, _rx) = channel::<usize>();
    let _subscriber = ShmSubscriber::open(&config, service, move |b: &[u8]| {
        let _ = tx.send(b.len());
    })
    .unwrap();
    let base = descriptors_of(&config.prefix);
    let mut publishers = Vec::new();
    let mut counts = Vec::new();
    for n in 1..=24 {
        publishers.push(ShmPublisher::open(&config, service).unwrap());
        if n == 8 || n == 24 {
            counts.push(descriptors_of(&config.prefix) - base);
        }
    }
    let (at8, at24) = (counts[0], counts[1]);
    eprintln!("descriptors: subscriber {base}, 8 publishers {at8}, 24 publishers {at24}");
    // Linear: 24 publishers hold three times what 8 hold (quadratic growth: nine times).
    assert!(
        at24 <= 3 * at8 + 8,
        "8 publishers {at8}, 24 publishers {at24}"
    );
}
