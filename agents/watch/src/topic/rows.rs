//! The rows of `topic list`: what the live agents publish and answer.

use std::collections::BTreeMap;

use graspopt_protocol::keys::AliveKey;
use graspopt_protocol::keys::{COMMAND, Entry, TABLE};
use graspopt_protocol::{AgentKind, RunId, Runs};
use serde_json::{Value, json};

/// One row of `topic list`.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub run: String,
    pub key: String,
    /// What travels on it ([`graspopt_protocol::keys::Entry::describe`]).
    pub message: String,
    /// `id@host` of each publisher.
    pub publishers: Vec<String>,
}

/// The topics the live agents publish (and the queries they answer), by run then key.
pub fn topic_rows(agents: &[AliveKey]) -> Vec<Row> {
    let mut by_run: BTreeMap<String, Vec<&AliveKey>> = BTreeMap::new();
    for a in agents {
        by_run
            .entry(a.run.as_str().to_string())
            .or_default()
            .push(a);
    }
    let mut rows = Vec::new();
    for (run, agents) in by_run {
        let Ok(id) = RunId::new(&run) else { continue };
        // The agents of the row's kind; of those whose token says what they publish (a
        // hand: clouds or wrenches), only the ones that publish the row's topic.
        let of = |entry: Entry| -> Vec<String> {
            let mut v: Vec<String> = agents
                .iter()
                .filter(|a| a.kind == entry.by)
                .filter(|a| a.publishes.is_none_or(|t| t.entry() == entry))
                .map(|a| format!("{}@{}", a.id, a.host))
                .collect();
            v.sort();
            v
        };
        let mut hands: Vec<&str> = agents
            .iter()
            .filter(|a| a.kind == AgentKind::Hand)
            .map(|a| a.id.as_str())
            .collect();
        hands.sort();
        for entry in TABLE {
            let publishers = of(entry);
            if publishers.is_empty() {
                continue;
            }
            // A worker's topic has one key per live hand.
            let keys: Vec<String> = if entry == COMMAND.entry() {
                hands
                    .iter()
                    .map(|h| COMMAND.worker_key(Runs::One(&id), h).to_string())
                    .collect()
            } else {
                vec![entry.key_expr(Runs::One(&id))]
            };
            for key in keys {
                rows.push(Row {
                    run: run.clone(),
                    key,
                    message: entry.describe(),
                    publishers: publishers.clone(),
                });
            }
        }
    }
    rows.sort_by(|a, b| (&a.run, &a.key).cmp(&(&b.run, &b.key)));
    rows
}

/// The rows as one JSON array.
pub fn rows_json(rows: &[Row]) -> Value {
    rows.iter()
        .map(|r| json!({"run": r.run, "key": r.key, "type": r.message, "publishers": r.publishers}))
        .collect()
}

/// The rows as a table (a header line, then one line per row).
pub fn rows_table(rows: &[Row]) -> Vec<String> {
    let w = rows.iter().map(|r| r.key.len()).max().unwrap_or(0);
    let t = rows.iter().map(|r| r.message.len()).max().unwrap_or(0);
    let mut out = vec![format!("{:w$}  {:t$}  PUBLISHERS", "TOPIC", "TYPE")];
    for r in rows {
        out.push(format!(
            "{:w$}  {:t$}  {}",
            r.key,
            r.message,
            r.publishers.join(", ")
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_protocol::Topic;

    #[test]
    fn list_rows_follow_the_live_agents() {
        let run = RunId::new("r").unwrap();
        let a = |kind, id: &str, publishes| AliveKey {
            run: run.clone(),
            kind,
            host: "h".into(),
            id: id.into(),
            encoding: graspopt_protocol::Encoding::Bincode,
            publishes,
        };
        // hand-1 says it publishes clouds, hand-3 wrenches; hand-2 does not say (an older
        // token): it is listed under both.
        let rows = topic_rows(&[
            a(AgentKind::Metric, "metric", None),
            a(AgentKind::Hand, "hand-2", None),
            a(AgentKind::Hand, "hand-1", Some(Topic::Clouds)),
            a(AgentKind::Hand, "hand-3", Some(Topic::Wrenches)),
            a(AgentKind::Coordinator, "coordinator", None),
        ]);
        let keys: Vec<&str> = rows.iter().map(|r| r.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "graspopt/r/clouds",
                "graspopt/r/coordinator/state",
                "graspopt/r/hand/hand-1/command",
                "graspopt/r/hand/hand-2/command",
                "graspopt/r/hand/hand-3/command",
                "graspopt/r/result",
                "graspopt/r/status",
                "graspopt/r/wrenches"
            ]
        );
        let clouds = &rows[0];
        assert_eq!(clouds.message, "ContactClouds");
        assert_eq!(clouds.publishers, ["hand-1@h", "hand-2@h"]);
        assert_eq!(rows[7].publishers, ["hand-2@h", "hand-3@h"]);
        let table = rows_table(&rows[..2]);
        assert_eq!(
            table,
            [
                "TOPIC                         TYPE                PUBLISHERS",
                "graspopt/r/clouds             ContactClouds       hand-1@h, hand-2@h",
                "graspopt/r/coordinator/state  query -> RunStatus  coordinator@h",
            ]
        );
        assert_eq!(rows_json(&rows)[1]["type"], "query -> RunStatus");
    }
}
