//! What a run waits for, and when to say so: in the run's status ([`Waits::shown`]) and in
//! the coordinator's log ([`Waits::message`]). No network, no clock: times are passed in.

use std::collections::BTreeMap;

use graspopt_protocol::{WaitReason, Waiting, describe_waits};

/// A wait shows (status, monitor, log) once it has lasted this long: agents that join within
/// a moment of the coordinator, as in every ordinary start, make no message.
pub const SHOW_AFTER_MS: i64 = 1_000;
/// While the waits last, the log says them again this often.
pub const REPEAT_MS: i64 = 5_000;
/// A planner question unanswered this long is a wait (an answer usually takes far less; a
/// planner that is not there at all is a wait at once).
pub const PLANNER_SLOW_MS: i64 = 5_000;

/// The waits of one run.
#[derive(Debug, Default, Clone)]
pub struct Waits {
    /// Each current wait and when it began.
    since: BTreeMap<WaitReason, i64>,
    /// What the log last said the run waits for, and when (`None`: nothing is being said).
    told: Option<(i64, Vec<WaitReason>)>,
}

impl Waits {
    /// Notes whether the run waits for `reason`: `Some(t)` if it does, since `t` (a wait that
    /// goes on keeps the time it began), `None` if it does not.
    pub fn set(&mut self, reason: WaitReason, since_ms: Option<i64>) {
        match since_ms {
            Some(t) => {
                self.since.entry(reason).or_insert(t);
            }
            None => {
                self.since.remove(&reason);
            }
        }
    }

    /// The waits that have lasted [`SHOW_AFTER_MS`] at `now_ms`, in [`WaitReason`] order.
    pub fn shown(&self, now_ms: i64) -> Vec<Waiting> {
        self.since
            .iter()
            .filter(|(_, since)| now_ms - **since >= SHOW_AFTER_MS)
            .map(|(&reason, &since_ms)| Waiting { reason, since_ms })
            .collect()
    }

    /// What to log at `now_ms` (`None`: nothing): the waits when they first show or change,
    /// again every [`REPEAT_MS`] while they last, and once when they are over.
    pub fn message(&mut self, now_ms: i64) -> Option<String> {
        let shown = self.shown(now_ms);
        let reasons: Vec<WaitReason> = shown.iter().map(|w| w.reason).collect();
        match &self.told {
            None if shown.is_empty() => None,
            Some(_) if shown.is_empty() => {
                self.told = None;
                Some("is no longer waiting".to_string())
            }
            Some((at, before)) if *before == reasons && now_ms - at < REPEAT_MS => None,
            _ => {
                self.told = Some((now_ms, reasons));
                Some(format!("is waiting: {}", describe_waits(&shown, now_ms)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn waits_show_after_a_second_repeat_and_end_with_a_word() {
        let mut w = Waits::default();
        w.set(WaitReason::MetricAgent, Some(0));
        w.set(WaitReason::Hand, Some(0));
        // An ordinary start: nothing said before a second has passed.
        assert_eq!(w.message(500), None);
        assert!(w.shown(500).is_empty());
        assert_eq!(
            w.message(1_000).as_deref(),
            Some("is waiting: no metric agent (1 s), no hand (1 s)")
        );
        assert_eq!(
            w.shown(1_000),
            [
                Waiting {
                    reason: WaitReason::MetricAgent,
                    since_ms: 0
                },
                Waiting {
                    reason: WaitReason::Hand,
                    since_ms: 0
                }
            ]
        );
        assert_eq!(w.message(3_000), None);
        // A wait that goes on keeps its start.
        w.set(WaitReason::Hand, Some(2_000));
        assert_eq!(
            w.message(6_000).as_deref(),
            Some("is waiting: no metric agent (6 s), no hand (6 s)")
        );
        // A change is said at once.
        w.set(WaitReason::Hand, None);
        assert_eq!(
            w.message(6_500).as_deref(),
            Some("is waiting: no metric agent (6 s)")
        );
        w.set(WaitReason::MetricAgent, None);
        assert_eq!(w.message(7_000).as_deref(), Some("is no longer waiting"));
        assert_eq!(w.message(20_000), None);
    }
}
