//! `graspopt topic list|echo|hz|bw`: watch the bus from a terminal. The flags become the
//! settings of graspopt_watch::topic, which lists, echoes and measures.

use std::process::ExitCode;

use anyhow::Result;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Subcommand};
use graspopt_bus::Bus;
use graspopt_protocol::RunId;
use graspopt_runner::signal::shutdown_signal;
use graspopt_watch::topic::{self, EchoSettings, Format, MIN_WINDOW, Measure, RateSettings};

use super::bus::BusArgs;
use super::setup::count;

use crate::out::outln;

#[derive(Args, Debug)]
pub struct TopicArgs {
    #[command(subcommand)]
    pub what: TopicCommand,
    #[command(flatten)]
    pub bus: BusArgs,
}

/// `--format`: text or json.
fn format_parser() -> impl TypedValueParser<Value = Format> {
    PossibleValuesParser::new([
        PossibleValue::new("text").help("For people"),
        PossibleValue::new("json").help("One JSON document per line (per message for echo)"),
    ])
    .map(|s| {
        if s == "json" {
            Format::Json
        } else {
            Format::Text
        }
    })
}

/// Which messages to watch.
#[derive(Args, Debug, Clone)]
pub struct Watch {
    /// A key expression, or a topic name: object, command, clouds, result, status.
    pub key: String,
    /// The run (with a topic name; default: every run).
    #[arg(long)]
    pub run: Option<String>,
    /// Stop after this many seconds.
    #[arg(long)]
    pub duration: Option<f64>,
}

#[derive(Subcommand, Debug)]
pub enum TopicCommand {
    /// The topics of the live agents, with message type and publishers.
    List {
        /// Only this run.
        #[arg(long)]
        run: Option<String>,
        /// text (a table) or json.
        #[arg(long, default_value = "text", value_parser = format_parser())]
        format: Format,
    },
    /// Print the messages on a topic, decoded.
    Echo {
        #[command(flatten)]
        watch: Watch,
        /// text (decoded, indented) or json (one object per line).
        #[arg(long, default_value = "text", value_parser = format_parser())]
        format: Format,
        /// Stop after this many messages.
        #[arg(long, value_parser = count::<u64>(0, u64::MAX))]
        count: Option<u64>,
    },
    /// Message rate of a topic.
    Hz {
        #[command(flatten)]
        watch: Watch,
        /// Messages in the sliding window (at least 3: a rate needs two intervals).
        #[arg(long, default_value_t = 100, value_parser = count::<usize>(MIN_WINDOW as u64, u64::MAX))]
        window: usize,
    },
    /// Bandwidth of a topic.
    #[command(name = "bw")]
    Bandwidth {
        #[command(flatten)]
        watch: Watch,
        /// Messages in the sliding window (at least 3: a rate needs two intervals).
        #[arg(long, default_value_t = 100, value_parser = count::<usize>(MIN_WINDOW as u64, u64::MAX))]
        window: usize,
    },
}

/// What to do, checked before connecting to anything.
enum Plan {
    List(Option<RunId>, Format),
    Echo(EchoSettings),
    Rate(RateSettings),
}

fn plan(what: &TopicCommand) -> Result<Plan> {
    let key = |w: &Watch| topic::resolve_key(&w.key, w.run.as_deref());
    let rate = |watch: &Watch, window: usize, measure| -> Result<Plan> {
        topic::check_window(window)?;
        Ok(Plan::Rate(RateSettings {
            key: key(watch)?,
            measure,
            window,
            duration: topic::check_duration(watch.duration)?,
        }))
    };
    Ok(match what {
        TopicCommand::List { run, format } => {
            Plan::List(run.as_deref().map(RunId::new).transpose()?, *format)
        }
        TopicCommand::Echo {
            watch,
            format,
            count,
        } => Plan::Echo(EchoSettings {
            key: key(watch)?,
            format: *format,
            count: *count,
            duration: topic::check_duration(watch.duration)?,
        }),
        TopicCommand::Hz { watch, window } => rate(watch, *window, Measure::Rate)?,
        TopicCommand::Bandwidth { watch, window } => rate(watch, *window, Measure::Bandwidth)?,
    })
}

pub fn run(args: &TopicArgs) -> Result<ExitCode> {
    let plan = plan(&args.what)?;
    tokio::runtime::Runtime::new()?.block_on(async {
        // `list` says itself when nothing answers where it connects.
        let bus = Bus::open_watcher(&args.bus.config(), matches!(plan, Plan::List(..))).await?;
        let mut out = std::io::stdout();
        let result = match &plan {
            Plan::List(run, format) => list(&bus, run.as_ref(), *format).await,
            Plan::Echo(s) => Ok(topic::echo(&bus, s, &mut out, shutdown_signal()).await?),
            Plan::Rate(s) => Ok(topic::rate(&bus, s, &mut out, shutdown_signal()).await?),
        };
        let _ = bus.close().await;
        result.map(|()| ExitCode::SUCCESS)
    })
}

async fn list(bus: &Bus, run: Option<&RunId>, format: Format) -> Result<()> {
    let rows = topic::list(bus, run).await?;
    // An empty listing where nothing answers is that address's fault, not an idle bus's.
    if rows.is_empty() {
        bus.check_linked().await?;
    }
    match format {
        Format::Json => outln!("{}", topic::rows_json(&rows))?,
        Format::Text if rows.is_empty() => {
            eprintln!("no live agents (check --connect, or the run id)")
        }
        Format::Text => {
            for line in topic::rows_table(&rows) {
                outln!("{line}")?;
            }
        }
    }
    Ok(())
}
