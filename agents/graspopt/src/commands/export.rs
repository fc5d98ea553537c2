//! `graspopt export RUN`: a run's trials from its journal, as CSV or JSON.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

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
    #[arg(long, value_enum, default_value_t = Format::Csv)]
    pub format: Format,
    /// Output file (default: standard output).
    #[arg(long, short)]
    pub output: Option<PathBuf>,
}

pub fn run(args: &ExportArgs) -> Result<ExitCode> {
    let path = args.journal.clone().unwrap_or_else(|| {
        PathBuf::from("results")
            .join(&args.run)
            .join("journal.sqlite")
    });
    anyhow::ensure!(path.exists(), "no journal at {}", path.display());
    let journal = graspopt_journal::Journal::open(&path)
        .with_context(|| format!("cannot open the journal {}", path.display()))?;
    let mut out: Box<dyn Write> = match &args.output {
        Some(p) => Box::new(std::io::BufWriter::new(
            std::fs::File::create(p).with_context(|| format!("cannot create {}", p.display()))?,
        )),
        None => Box::new(std::io::BufWriter::new(std::io::stdout().lock())),
    };
    match args.format {
        Format::Csv => graspopt_journal::export::write_csv(&journal, &args.run, &mut out)?,
        Format::Json => graspopt_journal::export::write_json(&journal, &args.run, &mut out)?,
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
