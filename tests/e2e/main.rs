//! End-to-end tests: the `graspopt` binary and its agents run as users run them, as real
//! processes on loopback. One module per topic in one test binary of the `graspopt` package
//! (agents/graspopt/Cargo.toml), so that `CARGO_BIN_EXE_graspopt` is the binary of this very
//! build. A new file here needs a `mod` line below.
//!
//! The slow suites of fault injection and malformed traffic (`faults`, `fuzz`, `reliability`)
//! are ignored by `cargo test --workspace`; `.ci/run` runs them as their own step:
//! `cargo test -p graspopt --test e2e -- --ignored faults:: fuzz:: reliability::`. The
//! multi-machine test (`netns`, network namespaces) needs root: `.ci/run` runs it alone with
//! `GRASPOPT_REQUIRE_NETNS=1`, which makes a skip a failure.

mod connect;
mod equivalence;
mod faults;
mod ft;
mod fuzz;
mod journeys;
mod launch;
mod lifecycle;
mod monitor;
mod netns;
mod pipeline;
mod reliability;
mod replay;
mod resume;
mod scratch;
mod security;
mod shm;
mod support;
mod topic;
mod waiting;
