//! The `graspopt` command's CLI tests, one module per topic in one test binary (one link
//! instead of one per file). They run the binary of this build (`CARGO_BIN_EXE_graspopt`).
//! A new file here needs a `mod` line below.

mod cli_bad_input;
mod doc_commands;
mod doc_facts;
mod docs_figures_cli;
mod experiment_report_cli;
mod forces_cli;
mod messages_cli;
mod pipe_cli;
mod quality_cli;
mod ranges_cli;
mod render_cli;
mod run_pictures_cli;
mod scene_cli;
#[path = "../../../../tests/e2e/scratch.rs"]
mod scratch;
mod sim_cli;
mod support;
