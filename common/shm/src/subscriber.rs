//! The subscriber side: a thread that sleeps on the event service, drains the samples and
//! hands each payload to a callback.

use super::*;

/// Subscriber ports. Field order is drop order.
pub(crate) struct SubscriberPorts {
    wake: Listener<Ipc>,
    acks: Notifier<Ipc>,
    pub(crate) subscriber: Subscriber<Ipc, [u8], ()>,
    endpoints: Endpoints,
    /// Publishers this subscriber has connected to and acknowledged.
    known_publishers: Vec<UniquePublisherId>,
}

impl SubscriberPorts {
    pub(crate) fn open(config: &ShmConfig, service: &str) -> Result<Self> {
        let endpoints = Endpoints::open(config, service, "graspopt-shm-subscriber")?;
        let wake = endpoints
            .wakes
            .listener_builder()
            .name(&port_name(service, WAKE_LISTENER)?)
            .create()
            .map_err(service_err(service, "create listener"))?;
        let acks = endpoints
            .acks
            .notifier_builder()
            .default_event_id(ACK)
            .create()
            .map_err(service_err(service, "create acknowledgement notifier"))?;
        let subscriber = endpoints
            .pubsub
            .subscriber_builder()
            .buffer_size(config.subscriber_buffer)
            .create()
            .map_err(service_err(service, "create subscriber"))?;
        let mut ports = Self {
            wake,
            acks,
            subscriber,
            endpoints,
            known_publishers: Vec::new(),
        };
        // Connected to every existing publisher before `open` returns, so
        // nothing sent afterwards is dropped for want of a connection.
        ports
            .connect_publishers()
            .map_err(service_err(service, "connect to publishers"))?;
        Ok(ports)
    }

    /// Connects to the publishers that appeared since the last call and
    /// acknowledges each to its publisher (which waits for it in `open`).
    fn connect_publishers(&mut self) -> Result<(), impl Display + use<>> {
        let mut current: Vec<(UniquePublisherId, UniqueNodeId)> = Vec::new();
        self.endpoints
            .pubsub
            .dynamic_config()
            .list_publishers(|details| {
                current.push((details.publisher_id, details.node_id));
                CallbackProgression::Continue
            });
        if current.len() == self.known_publishers.len()
            && current
                .iter()
                .all(|(id, _)| self.known_publishers.contains(id))
        {
            return Ok(());
        }
        let connected = self.subscriber.update_connections();
        let new_nodes: Vec<UniqueNodeId> = current
            .iter()
            .filter(|(id, _)| !self.known_publishers.contains(id))
            .map(|&(_, node)| node)
            .collect();
        if !new_nodes.is_empty() {
            self.acks.for_each_listener(|listener, details| {
                if new_nodes.contains(&details.node_id) {
                    // Unacknowledged, the publisher only waits longer.
                    let _ = listener.notify();
                }
                CallbackProgression::Continue
            });
        }
        self.known_publishers = current.into_iter().map(|(id, _)| id).collect();
        connected
    }

    /// Hands every queued payload to `on_message`; false if `stop` was set.
    fn drain(
        &self,
        stop: &AtomicBool,
        errors: &AtomicU64,
        on_message: &mut impl FnMut(&[u8]),
    ) -> bool {
        loop {
            if stop.load(Ordering::Acquire) {
                return false;
            }
            match self.subscriber.receive() {
                Ok(Some(sample)) => on_message(sample.payload()),
                Ok(None) => return true,
                Err(_) => {
                    errors.fetch_add(1, Ordering::Relaxed);
                    return true;
                }
            }
        }
    }

    fn run(mut self, stop: &AtomicBool, errors: &AtomicU64, mut on_message: impl FnMut(&[u8])) {
        while self.drain(stop, errors, &mut on_message) {
            if self.connect_publishers().is_err() {
                errors.fetch_add(1, Ordering::Relaxed);
            }
            // Sleep until a publisher's notification, or the poll period
            // (which bounds how long a stop request waits). Notifications
            // sent while draining are kept, so none is missed.
            match self.wake.timed_wait(|_| {}, SUBSCRIBER_POLL) {
                // A signal delivered to this thread: just look again.
                Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                Err(_) => {
                    errors.fetch_add(1, Ordering::Relaxed);
                    // Do not spin if the wait keeps failing.
                    std::thread::sleep(ERROR_BACKOFF);
                }
            }
        }
    }
}

/// Receives byte messages on one service on a dedicated thread.
///
/// Dropping it stops the thread (within about 20 ms plus the callback in
/// progress), waits for it, and releases the iceoryx2 resources; the callback
/// is never called after the drop returns.
pub struct ShmSubscriber {
    service: String,
    stop: Arc<AtomicBool>,
    errors: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for ShmSubscriber {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShmSubscriber")
            .field("service", &self.service)
            .finish_non_exhaustive()
    }
}

impl ShmSubscriber {
    /// Opens (creating if needed) `service` and subscribes to it. Every
    /// message sent after this returns is handed to `on_message`, in order
    /// per publisher, on the subscriber's thread; the slice points into shared
    /// memory and is valid only during the call. A slow callback makes
    /// publishers wait (see [`ShmConfig::delivery_timeout`]); a callback that
    /// panics ends the subscription (the thread stops and its ports close).
    pub fn open(
        config: &ShmConfig,
        service: &str,
        on_message: impl FnMut(&[u8]) + Send + 'static,
    ) -> Result<ShmSubscriber> {
        let ports = SubscriberPorts::open(config, service)?;
        let stop = Arc::new(AtomicBool::new(false));
        let errors = Arc::new(AtomicU64::new(0));
        let thread = {
            let stop = stop.clone();
            let errors = errors.clone();
            std::thread::Builder::new()
                .name(format!("shm-sub {service}"))
                .spawn(move || ports.run(&stop, &errors, on_message))
                .map_err(service_err(service, "spawn subscriber thread"))?
        };
        Ok(ShmSubscriber {
            service: service.to_owned(),
            stop,
            errors,
            thread: Some(thread),
        })
    }

    /// The service name.
    pub fn service(&self) -> &str {
        &self.service
    }

    /// Receive or wait errors met by the thread so far (it carries on after
    /// each).
    pub fn receive_errors(&self) -> u64 {
        self.errors.load(Ordering::Relaxed)
    }
}

impl Drop for ShmSubscriber {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            // Dropped from inside its own callback: the thread ends when the
            // callback returns; joining itself would deadlock.
            if thread.thread().id() != std::thread::current().id() {
                // A panic in the callback already ended the thread.
                let _ = thread.join();
            }
        }
    }
}
