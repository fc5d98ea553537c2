//! `graspopt export RUN`: a run's trials from its journal, as CSV or JSON.
//!
//! The journal is read completely before the output is touched, an output that is the journal
//! itself (or one of its SQLite side files) is refused, and an existing output file is only
//! replaced, atomically, once the export succeeded ([`graspopt_journal::output`]).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use graspopt_journal::output;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    Csv,
    Json,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The run id.
    pub run: String,
    /// The journal (default: results/<run>/journal.sqlite).
    #[arg(long)]
    pub journal: Option<PathBuf>,
    /// csv (one row per trial; a missing value is an empty cell) or json.
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// Output file (default: standard output). Must not be the journal; an existing file is
    /// replaced only once the export succeeded.
    #[arg(long, short, visible_alias = "out")]
    pub output: Option<PathBuf>,
}

pub fn run(args: &ExportArgs) -> Result<ExitCode> {
    let path = args.journal.clone().unwrap_or_else(|| {
        PathBuf::from("results")
            .join(&args.run)
            .join("journal.sqlite")
    });
    anyhow::ensure!(path.exists(), "no journal at {}", path.display());
    // Refuse an output that is the journal before opening anything.
    if let Some(out) = &args.output {
        output::refuse_journal(&path, out).context("--output")?;
    }
    let journal = graspopt_journal::Journal::open_existing(&path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    // The whole export, in memory: the journal is read before any output exists.
    let mut bytes = Vec::new();
    match args.format {
        Format::Csv => graspopt_journal::export::write_csv(&journal, &args.run, &mut bytes)?,
        Format::Json => graspopt_journal::export::write_json(&journal, &args.run, &mut bytes)?,
    }
    drop(journal);
    match &args.output {
        Some(p) => output::write_replacing(p, &bytes).context("--output")?,
        None => {
            let mut out = crate::out::stdout();
            out.write_all(&bytes)?;
            out.flush()?;
        }
    }
    Ok(ExitCode::SUCCESS)
}
