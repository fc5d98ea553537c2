use super::*;
use crate::messages::Message;

#[test]
fn run_ids_are_single_chunks() {
    assert!(RunId::new("mug-2026_11.22").is_ok());
    for bad in ["", "a/b", "a*", "$x", "a b", ".hidden", &"x".repeat(65)] {
        let e = RunId::new(bad).unwrap_err();
        assert_eq!(e.value, bad);
    }
    assert!(serde_json::from_str::<RunId>("\"a/b\"").is_err());
}

#[test]
fn claim_keys_parse_back_and_nothing_else_does() {
    let run = RunId::new("r1").unwrap();
    for (nonce, phase) in [
        (0x00ab_cdef_0123_4567, ClaimPhase::Starting),
        (u64::MAX, ClaimPhase::Held),
        (7, ClaimPhase::Settled),
    ] {
        let claim = Claim { nonce, phase };
        let key = claim_token(&run, AgentKind::Hand, "hand-1", claim);
        assert_eq!(parse_claim_key(&key), Some(claim), "{key}");
    }
    assert_eq!(
        claim_token(
            &run,
            AgentKind::Coordinator,
            "any",
            Claim {
                nonce: 1,
                phase: ClaimPhase::Settled
            }
        ),
        "graspopt/r1/claim/coordinator/any/0000000000000001/settled"
    );
    for bad in [
        "graspopt/r1/claim/hand/h/+000000000000000/held",
        "graspopt/r1/claim/hand/h/00000000000000001/held",
        "graspopt/r1/claim/hand/h/0000000000000001/taken",
        "graspopt/r1/alive/hand/h/0000000000000001/held",
        "graspopt/r1/claim/hand/0000000000000001/held",
    ] {
        assert_eq!(parse_claim_key(bad), None, "{bad}");
    }
}

#[test]
fn keys_classify_back_to_their_topic() {
    let run = RunId::new("r1").unwrap();
    let cases = [
        (OBJECT.key(Runs::One(&run)).to_string(), Topic::Object),
        (
            COMMAND.worker_key(Runs::One(&run), "w-1").to_string(),
            Topic::Command,
        ),
        (CLOUDS.key(Runs::One(&run)).to_string(), Topic::Clouds),
        (RESULT.key(Runs::One(&run)).to_string(), Topic::Result),
        (STATUS.key(Runs::One(&run)).to_string(), Topic::Status),
    ];
    for (key, topic) in cases {
        assert_eq!(Topic::classify(&key), Some((run.clone(), topic)), "{key}");
    }
    assert_eq!(Topic::classify("graspopt/r1/unknown"), None);
    assert_eq!(Topic::classify("other/r1/result"), None);
}

#[test]
fn alive_keys_parse() {
    let run = RunId::new("r1").unwrap();
    let key = alive_token(&run, AgentKind::Hand, "host-a", "hand-1", None);
    assert_eq!(key, "graspopt/r1/alive/hand/host-a/hand-1");
    let parsed = parse_alive_key(&key).unwrap();
    assert_eq!(parsed.kind, AgentKind::Hand);
    assert_eq!(parsed.host, "host-a");
    assert_eq!(parsed.id, "hand-1");
    assert_eq!(parsed.encoding, Encoding::Bincode);
    assert!(parse_alive_key("graspopt/r1/alive/robot/h/i").is_none());
    // A JSON-speaking agent's token.
    let parsed = parse_alive_key(&format!("{key}/json")).unwrap();
    assert_eq!(
        (parsed.id.as_str(), parsed.encoding),
        ("hand-1", Encoding::Json)
    );
    assert!(parse_alive_key(&format!("{key}/xml")).is_none());
    assert_eq!(parsed.publishes, None);
    // A token that says which topic the agent publishes: one of its kind's, after `/json`.
    let ft = alive_token(
        &run,
        AgentKind::Hand,
        "host-a",
        "hand-1",
        Some(Topic::Wrenches),
    );
    assert_eq!(ft, "graspopt/r1/alive/hand/host-a/hand-1/wrenches");
    let parsed = parse_alive_key(&ft).unwrap();
    assert_eq!(
        (parsed.publishes, parsed.encoding),
        (Some(Topic::Wrenches), Encoding::Bincode)
    );
    let parsed = parse_alive_key(&format!("{key}/json/clouds")).unwrap();
    assert_eq!(
        (parsed.publishes, parsed.encoding),
        (Some(Topic::Clouds), Encoding::Json)
    );
    for bad in [
        "result",
        "clouds/json",
        "clouds/wrenches",
        "json/json",
        "wrenches/x",
    ] {
        assert!(parse_alive_key(&format!("{key}/{bad}")).is_none(), "{bad}");
    }
    // Only a topic the agent's kind publishes.
    let metric = alive_token(&run, AgentKind::Metric, "h", "m", None);
    assert!(parse_alive_key(&format!("{metric}/clouds")).is_none());
    assert!(
        parse_alive_key(&format!("{metric}/result"))
            .unwrap()
            .publishes
            == Some(Topic::Result)
    );
    assert!(parse_alive_key("graspopt/r/alive/hand/h/*").is_none());
    assert!(parse_alive_key("graspopt/r/alive/hand/**/h1").is_none());
}

#[test]
fn the_table_builds_every_documented_key() {
    let run = RunId::new("r1").unwrap();
    let one = Runs::One(&run);
    // (row, its key in run r1, its key in every run, what travels, who sends or answers)
    let documented = [
        (
            "object",
            "graspopt/r1/object",
            "ObjectEstimate",
            AgentKind::Perception,
        ),
        (
            "command",
            "graspopt/r1/hand/*/command",
            "TrialCommand",
            AgentKind::Coordinator,
        ),
        (
            "clouds",
            "graspopt/r1/clouds",
            "ContactClouds",
            AgentKind::Hand,
        ),
        (
            "wrenches",
            "graspopt/r1/wrenches",
            "FingertipWrenches",
            AgentKind::Hand,
        ),
        (
            "result",
            "graspopt/r1/result",
            "TrialResult",
            AgentKind::Metric,
        ),
        (
            "status",
            "graspopt/r1/status",
            "RunStatus",
            AgentKind::Coordinator,
        ),
        (
            "suggest",
            "graspopt/r1/planner/suggest",
            "query SuggestRequest -> SuggestReply",
            AgentKind::Planner,
        ),
        (
            "state",
            "graspopt/r1/coordinator/state",
            "query -> RunStatus",
            AgentKind::Coordinator,
        ),
    ];
    assert_eq!(TABLE.len(), documented.len());
    for (entry, (name, key, what, by)) in TABLE.iter().zip(documented) {
        assert_eq!(
            (
                entry.name,
                entry.key_expr(one).as_str(),
                entry.describe().as_str(),
                entry.by
            ),
            (name, key, what, by)
        );
        let all = key.replacen("graspopt/r1/", "graspopt/*/", 1);
        assert_eq!(entry.key_expr(Runs::All), all);
    }
    // The typed keys are the rows' keys, and each is bound to its row's message type.
    fn bound<M: Message>(key: &Key<M>) -> (&str, &'static str) {
        (key.as_str(), M::TYPE)
    }
    assert_eq!(
        bound(&OBJECT.key(one)),
        ("graspopt/r1/object", "ObjectEstimate")
    );
    assert_eq!(
        bound(&COMMAND.worker_key(one, "hand-1")),
        ("graspopt/r1/hand/hand-1/command", "TrialCommand")
    );
    assert_eq!(
        bound(&CLOUDS.key(one)),
        ("graspopt/r1/clouds", "ContactClouds")
    );
    assert_eq!(
        bound(&RESULT.key(one)),
        ("graspopt/r1/result", "TrialResult")
    );
    assert_eq!(
        bound(&STATUS.key(Runs::All)),
        ("graspopt/*/status", "RunStatus")
    );
    fn asks<Q: Message, R: Message>(key: &QueryKey<Q, R>) -> (&str, &'static str, &'static str) {
        (key.as_str(), Q::TYPE, R::TYPE)
    }
    assert_eq!(
        asks(&SUGGEST.key(&run)),
        (
            "graspopt/r1/planner/suggest",
            "SuggestRequest",
            "SuggestReply"
        )
    );
    fn replies<R: Message>(key: &QueryKey<(), R>) -> (&str, &'static str) {
        (key.as_str(), R::TYPE)
    }
    assert_eq!(
        replies(&STATE.key(&run)),
        ("graspopt/r1/coordinator/state", "RunStatus")
    );
    // Liveliness, claims, everything of a run, the shared-memory service.
    assert_eq!(
        alive_token(&run, AgentKind::Hand, "h", "hand-1", None),
        "graspopt/r1/alive/hand/h/hand-1"
    );
    assert_eq!(
        alive_key(one, Some(AgentKind::Coordinator)),
        "graspopt/r1/alive/coordinator/**"
    );
    assert_eq!(alive_key(Runs::All, None), "graspopt/*/alive/**");
    assert_eq!(
        claim_slot_key(&run, AgentKind::Hand, "hand-1"),
        "graspopt/r1/claim/hand/hand-1/**"
    );
    assert_eq!(all_key(one), "graspopt/r1/**");
    assert_eq!(shm_clouds_service(&run), "graspopt/r1/clouds");
    assert_eq!(shm_probe_service(), "graspopt/shm-probe");
    // The topics are the table's topic rows, by name.
    for t in Topic::ALL {
        assert_eq!(Topic::named(t.entry().name), Some(t));
        assert!(!t.entry().is_query());
    }
    assert_eq!(Topic::named("state"), None);
}

#[test]
fn sanitize_makes_valid_chunks() {
    for text in ["my host.local", "", ".x", "a/b*c"] {
        let s = sanitize_chunk(text);
        assert!(check_agent_id(&s).is_ok(), "{text:?} -> {s:?}");
    }
    assert_eq!(sanitize_chunk("a b/c"), "a_b_c");
}

/// Fuzz seeds name a topic by its place in `Topic::ALL` (fuzz/examples/gen_seeds.rs): the
/// places of the topics there never move, and a topic's row says its place.
#[test]
fn topics_keep_their_places() {
    assert_eq!(
        Topic::ALL,
        [
            Topic::Object,
            Topic::Command,
            Topic::Clouds,
            Topic::Result,
            Topic::Status,
            Topic::Wrenches
        ]
    );
    for (place, topic) in Topic::ALL.into_iter().enumerate() {
        assert_eq!(topic as usize, place);
    }
}
