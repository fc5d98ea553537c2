//! The contact-cloud channel from hand to metric agents.
//!
//! A hand sends each trial's clouds through iceoryx2 shared memory when a metric agent of the
//! same run listens on the same host (the shared-memory service has a subscriber), and over
//! Zenoh otherwise; the choice is made per message, so a metric agent that starts or stops is
//! followed. A metric agent listens on both paths at once. Zenoh carries the portable bincode
//! encoding; shared memory the fixed layout of [`graspopt_protocol::layout`], written straight
//! into the loaned sample and read back with validation in one pass.

use graspopt_protocol::keys::{CLOUDS, Key, shm_clouds_service};
use graspopt_protocol::{ContactClouds, DecodeError, Encoding, RunId, layout};
use graspopt_shm::{ShmPublisher, ShmSubscriber};
use tokio::sync::mpsc;

use crate::task::OwnedTask;
use crate::{Bus, BusError};

/// Which path a cloud took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudPath {
    SharedMemory,
    Zenoh,
}

impl CloudPath {
    pub fn as_str(self) -> &'static str {
        match self {
            CloudPath::SharedMemory => "shm",
            CloudPath::Zenoh => "zenoh",
        }
    }
}

/// Sends contact clouds.
pub struct CloudSender {
    bus: Bus,
    key: Key<ContactClouds>,
    shm: Option<ShmPublisher>,
}

impl CloudSender {
    /// A sender for the run's clouds. Shared memory is used when available (and not disabled
    /// on the bus); if it cannot be opened, a warning is logged and Zenoh alone is used.
    ///
    /// Opening the shared-memory publisher blocks (iceoryx2 lists the host's nodes and waits
    /// for the subscribers' acknowledgements: 45-180 ms measured with thousands of dead
    /// nodes on the host), so it runs on a blocking thread: 64 hands in one process start
    /// side by side instead of holding the runtime's worker threads in turn.
    pub async fn open(bus: &Bus, run: &RunId) -> CloudSender {
        let opened = match bus.shm().cloned() {
            Some(cfg) => {
                let service = shm_clouds_service(run);
                tokio::task::spawn_blocking(move || ShmPublisher::open(&cfg, &service))
                    .await
                    .map_err(|e| e.to_string())
                    .and_then(|r| r.map_err(|e| e.to_string()))
                    .map(Some)
            }
            None => Ok(None),
        };
        let shm = opened.unwrap_or_else(|e| {
            tracing::warn!("shared memory unavailable, clouds go over Zenoh: {e}");
            None
        });
        CloudSender {
            bus: bus.clone(),
            key: CLOUDS.key(run.into()),
            shm,
        }
    }

    /// Sends one trial's clouds and says which path they took.
    pub async fn send(&self, clouds: &ContactClouds) -> Result<CloudPath, BusError> {
        if let Some(shm) = &self.shm
            && shm.subscriber_count().unwrap_or(0) > 0
        {
            let len = layout::clouds_len(clouds)?;
            let sent = shm.send_with(len, |buf| {
                layout::write_clouds(clouds, buf).map_err(BusError::from)
            });
            match sent {
                Ok(()) => return Ok(CloudPath::SharedMemory),
                Err(e) => tracing::warn!("shared-memory send failed, using Zenoh: {e}"),
            }
        }
        self.bus.put(&self.key, clouds, Encoding::Bincode).await?;
        Ok(CloudPath::Zenoh)
    }
}

/// Clouds received on either path.
#[derive(Debug)]
pub struct ReceivedClouds {
    pub path: CloudPath,
    pub size: usize,
    pub message: Result<ContactClouds, DecodeError>,
}

/// Receives contact clouds from both paths.
pub struct CloudReceiver {
    rx: mpsc::Receiver<ReceivedClouds>,
    _shm: Option<ShmSubscriber>,
    _task: OwnedTask,
}

impl CloudReceiver {
    /// Listens for the run's clouds on Zenoh and, when available, on shared memory.
    pub async fn open(bus: &Bus, run: &RunId) -> Result<CloudReceiver, BusError> {
        let (tx, rx) = mpsc::channel(1024);
        let shm = match bus.shm() {
            Some(cfg) => {
                let tx = tx.clone();
                let on_message = move |bytes: &[u8]| {
                    let received = ReceivedClouds {
                        path: CloudPath::SharedMemory,
                        size: bytes.len(),
                        message: layout::read_clouds(bytes),
                    };
                    // The receiver gone means the agent is stopping: nothing to do.
                    let _ = tx.blocking_send(received);
                };
                match ShmSubscriber::open(cfg, &shm_clouds_service(run), on_message) {
                    Ok(s) => Some(s),
                    Err(e) => {
                        tracing::warn!("shared memory unavailable, clouds come over Zenoh: {e}");
                        None
                    }
                }
            }
            None => None,
        };
        let sub = bus.subscribe(&CLOUDS.key(run.into())).await?;
        let task = OwnedTask::spawn(async move {
            while let Some(r) = sub.recv().await {
                let received = ReceivedClouds {
                    path: CloudPath::Zenoh,
                    size: r.size,
                    message: r.message,
                };
                if tx.send(received).await.is_err() {
                    break;
                }
            }
        });
        Ok(CloudReceiver {
            rx,
            _shm: shm,
            _task: task,
        })
    }

    /// The next clouds; `None` when both paths closed.
    pub async fn recv(&mut self) -> Option<ReceivedClouds> {
        self.rx.recv().await
    }
}
