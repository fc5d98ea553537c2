//! Every `graspopt` command the docs show in a code block, checked against the binary of this
//! build: each one parses (in `cargo test --workspace`), and the cheap, self-contained ones
//! run and succeed (ignored tests: `.ci/run` runs the cheap ones, half a minute; the slow
//! one, two minutes, is run by hand).
//!
//! **What is read.** README.md, deploy/README.md, docs/*.md and the examples' docs (any
//! README.md under examples/, and the module docstring of each examples/**/*.py, whose
//! indented lines are a shell block). In a markdown file, the fenced code blocks: in a block
//! whose lines start with a `$ ` prompt (a console session), the prompted lines are the
//! commands and the others are output; in a `sh`, `bash`, `shell` or `console` block without
//! prompts, every line is a command. A `text` or unlabelled block without prompts holds no
//! command, and a line in it that reads as one (`graspopt <subcommand> ...`) fails the test:
//! label the block `sh` or prompt the line with `$ `. Lines ending in `\` continue; `#`
//! starts a comment; `;`, `&&`, `||`, `|` and `&` standing alone separate commands. A
//! command is `graspopt ARGS`, `<path>/graspopt ARGS` or `cargo run -p graspopt -- ARGS`;
//! other programs (cargo test, python3, pip) are not checked here.
//!
//! **Usage notation.** `[--flag value]` is an optional group, `a|b` inside a word a choice.
//! Each command gives variants: without its optional groups, and with all of them, once per
//! choice (the first choice of every word, then the second, ...). Every variant is parsed;
//! the first two (without the groups, with them and the first choices) run for real.
//!
//! **Placeholders** are substituted as whole words ([`PLACEHOLDERS`]): `FILE` by
//! tests/data/metric-cases.json, `R` by a run the test makes first, `ROUTER` by 127.0.0.1,
//! `my_gripper.urdf` by the journeys test's hand of its own (tests/data/hands/claw, its
//! settings and mesh beside it) under that name. A word in
//! capitals left after that fails the test: a new placeholder needs its entry. A word that
//! names a file of the repository (`deploy/local.toml`) is given as its absolute path: the
//! commands run in a scratch folder, which receives what they write (`results/...`,
//! `mug.jsonl`).
//!
//! **Parsing without running.** With `GRASPOPT_PARSE_ONLY=1` in its environment, `graspopt`
//! parses its command line as always (an unknown flag, a missing argument or a value clap
//! refuses exits 2 with clap's message) and then exits 0 without doing anything.
//!
//! **Commands not run.** Which commands are not run for real, and why, is listed here, not
//! in the docs: [`NOT_RUN`] (they serve until stopped, need a router or other agents, or take
//! minutes) and [`SLOW`] (self-contained but too slow for this test: the ignored test
//! `the_slow_commands_in_the_docs_run` runs them). A rule names a subcommand and, optionally,
//! words a variant must also contain, in order; every rule must match a variant of a command
//! of the docs. Every variant, listed or not, is parsed.

use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use crate::support::tempdir;

/// Commands not run for real: (rule, why). A rule is the subcommand, then words the variant
/// must also contain, in order.
const NOT_RUN: &[(&str, &str)] = &[
    (
        "router",
        "a router serves until it is stopped (the e2e tests start one for each run)",
    ),
    (
        "agent",
        "an agent serves a run on a router until it is stopped (tests/e2e/pipeline.rs, \
         replay.rs, security.rs run every kind)",
    ),
    (
        "launch",
        "starts a router and agents that do a whole run (tests/e2e/launch.rs runs \
         deploy/local.toml)",
    ),
    (
        "topic",
        "watches a live run on a router until stopped (tests/e2e/topic.rs)",
    ),
    (
        "bench",
        "the figures of docs/benchmarks.md: minutes even in a release build",
    ),
    (
        "run --workers 0",
        "waits for a hand to attach from outside (tests/e2e/journeys.rs attaches the Python \
         hands to it)",
    ),
];

/// Commands that are self-contained but too slow for this test: (rule, why). The ignored
/// test `the_slow_commands_in_the_docs_run` runs them.
const SLOW: &[(&str, &str)] = &[(
    "optimize-function",
    "10 seeds of 100 evaluations of the BO engine: 40 s in a debug build, 80 s with --batch 4",
)];

/// Placeholders of the docs and what stands for them (`{run}`, `{hand}`, `{repo}`: filled in
/// by [`Placeholders::new`]).
const PLACEHOLDERS: &[(&str, &str)] = &[
    ("FILE", "{repo}/tests/data/metric-cases.json"),
    ("R", "{run}"),
    ("ROUTER", "127.0.0.1"),
    ("my_gripper.urdf", "{hand}"),
];

/// The run id of the run the test makes first, for `R`.
const RUN: &str = "docs";

/// How long a command may take: parsing, and a real run.
const PARSE_DEADLINE: Duration = Duration::from_secs(60);
const RUN_DEADLINE: Duration = Duration::from_secs(300);

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// One command of a doc: where, and its arguments as written (after `graspopt`).
#[derive(Debug, Clone, PartialEq)]
struct DocCommand {
    at: String,
    words: Vec<String>,
}

impl DocCommand {
    fn text(&self) -> String {
        format!("graspopt {}", self.words.join(" "))
    }
}

/// The shell lines of a code block, with the line number of each.
struct Block {
    lang: String,
    lines: Vec<(usize, String)>,
}

/// The fenced code blocks of a markdown text.
fn fenced_blocks(text: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut open: Option<(String, Block)> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        let fence = ["```", "~~~"].into_iter().find(|f| trimmed.starts_with(f));
        match (&mut open, fence) {
            (None, Some(f)) => {
                let lang = trimmed[f.len()..].split_whitespace().next().unwrap_or("");
                let block = Block {
                    lang: lang.to_string(),
                    lines: Vec::new(),
                };
                open = Some((f.to_string(), block));
            }
            (Some((f, _)), Some(g)) if *f == g && trimmed.trim_end() == g => {
                blocks.push(open.take().unwrap().1);
            }
            (Some((_, block)), _) => block.lines.push((i + 1, line.to_string())),
            (None, None) => {}
        }
    }
    blocks
}

/// The indented lines of a Python file's module docstring, as one shell block.
fn docstring_block(text: &str) -> Vec<Block> {
    let Some(start) = text.find("\"\"\"") else {
        return Vec::new();
    };
    let end = text[start + 3..]
        .find("\"\"\"")
        .map_or(text.len(), |e| start + 3 + e);
    let first = text[..start].lines().count();
    let lines = text[start + 3..end]
        .lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("    "))
        .map(|(i, l)| (first + i + 1, l.to_string()))
        .collect();
    vec![Block {
        lang: "sh".into(),
        lines,
    }]
}

/// Splits a shell line into words (quotes group, and are removed); separators (`;`, `&&`,
/// `||`, `|`, `&`) standing alone are words of their own.
fn shell_words(line: &str) -> Vec<String> {
    let mut words = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    let mut started = false;
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                started = true;
            }
            (None, c) if c.is_whitespace() => {
                if started || !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
                started = false;
            }
            (None, ';') => {
                if !word.is_empty() {
                    words.push(std::mem::take(&mut word));
                }
                words.push(";".into());
            }
            (None, c) => word.push(c),
        }
    }
    if started || !word.is_empty() {
        words.push(word);
    }
    words
}

/// The arguments of the `graspopt` invocation in one simple command, if it is one.
fn graspopt_args(words: &[String]) -> Option<Vec<String>> {
    // Leading keywords and environment assignments.
    let start = words.iter().position(|w| {
        !(["do", "then", "else", "time"].contains(&w.as_str()) || is_assignment(w))
    })?;
    let words = &words[start..];
    let program = words.first()?;
    if program == "graspopt" || program.ends_with("/graspopt") {
        return Some(words[1..].to_vec());
    }
    let package = words
        .windows(2)
        .any(|w| ["-p", "--package"].contains(&w[0].as_str()) && w[1] == "graspopt");
    if program == "cargo" && words.get(1).is_some_and(|w| w == "run") && package {
        let dashes = words.iter().position(|w| w == "--")?;
        return Some(words[dashes + 1..].to_vec());
    }
    None
}

fn is_assignment(word: &str) -> bool {
    word.split_once('=').is_some_and(|(name, _)| {
        !name.is_empty() && name.chars().all(|c| c.is_ascii_uppercase() || c == '_')
    })
}

/// Whether a line of a block that holds no commands reads as a graspopt command.
fn looks_like_a_command(line: &str) -> bool {
    simple_commands(line.trim_end_matches('\\'))
        .iter()
        .any(|words| {
            graspopt_args(words).is_some_and(|args| {
                args.first().is_some_and(|sub| {
                    sub.chars().all(|c| c.is_ascii_lowercase() || c == '-') && !sub.starts_with('-')
                })
            })
        })
}

/// The simple commands of a shell line: its words up to a comment, split at separators.
fn simple_commands(line: &str) -> Vec<Vec<String>> {
    let mut words = shell_words(line);
    if let Some(c) = words.iter().position(|w| w.starts_with('#')) {
        words.truncate(c);
    }
    let separators = [";", "&&", "||", "|", "&"];
    words
        .split(|w| separators.contains(&w.as_str()))
        .map(<[String]>::to_vec)
        .collect()
}

/// The graspopt commands of `blocks` (of the file `file`), and the lines of blocks that
/// hold no commands but read as one (errors).
fn commands_of(file: &str, blocks: &[Block]) -> (Vec<DocCommand>, Vec<String>) {
    let mut commands = Vec::new();
    let mut errors = Vec::new();
    for block in blocks {
        let prompted = block
            .lines
            .iter()
            .any(|(_, l)| l.trim_start().starts_with("$ "));
        let shell = ["sh", "bash", "shell", "console", "zsh"].contains(&block.lang.as_str());
        let mut pending: Option<(usize, String)> = None;
        for (n, line) in &block.lines {
            let line = line.trim();
            let (n, line) = match pending.take() {
                Some((first, head)) => (first, format!("{head} {line}")),
                None if prompted => match line.strip_prefix("$ ") {
                    Some(rest) => (*n, rest.to_string()),
                    None => continue,
                },
                None if shell => (*n, line.to_string()),
                None => {
                    if ["text", ""].contains(&block.lang.as_str()) && looks_like_a_command(line) {
                        errors.push(format!(
                            "{file}:{n}: a command in a block that holds none (label it sh, \
                             or prompt it with `$ `): {line}"
                        ));
                    }
                    continue;
                }
            };
            if let Some(head) = line.strip_suffix('\\') {
                pending = Some((n, head.trim_end().to_string()));
                continue;
            }
            for simple in simple_commands(&line) {
                if let Some(args) = graspopt_args(&simple) {
                    commands.push(DocCommand {
                        at: format!("{file}:{n}"),
                        words: args,
                    });
                }
            }
        }
    }
    (commands, errors)
}

/// Every graspopt command of the docs, and the errors of reading them.
fn doc_commands(root: &Path) -> (Vec<DocCommand>, Vec<String>) {
    let mut files = vec![root.join("README.md"), root.join("deploy/README.md")];
    let mut docs: Vec<PathBuf> = fs::read_dir(root.join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    files.extend(docs);
    let mut examples = Vec::new();
    walk(&root.join("examples"), &mut examples);
    examples.sort();
    files.extend(examples);
    let mut commands = Vec::new();
    let mut errors = Vec::new();
    for path in files {
        let text = fs::read_to_string(&path).unwrap();
        let name = path.strip_prefix(root).unwrap().display().to_string();
        let blocks = if name.ends_with(".py") {
            docstring_block(&text)
        } else {
            fenced_blocks(&text)
        };
        let (c, e) = commands_of(&name, &blocks);
        commands.extend(c);
        errors.extend(e);
    }
    (commands, errors)
}

/// The README.md and .py files under `dir`.
fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            walk(&path, out);
        } else if path.file_name().is_some_and(|n| n == "README.md")
            || path.extension().is_some_and(|e| e == "py")
        {
            out.push(path);
        }
    }
}

/// The variants of a command's words (see the module doc): without the optional groups,
/// then with them, once per choice. The first two are the ones run.
fn variants(words: &[String]) -> Vec<Vec<String>> {
    let mut bare = Vec::new();
    let mut full = Vec::new();
    let mut depth = 0usize;
    for word in words {
        let opens = word.starts_with('[');
        let w = word.trim_start_matches('[');
        let closes = w.ends_with(']') && depth + usize::from(opens) > 0;
        let w = if closes { w.trim_end_matches(']') } else { w };
        depth += usize::from(opens);
        if depth == 0 {
            bare.push(w.to_string());
        }
        full.push(w.to_string());
        if closes {
            depth = depth.saturating_sub(1);
        }
    }
    let choices = full.iter().map(|w| w.split('|').count()).max().unwrap_or(1);
    let mut out = vec![pick(&bare, 0)];
    for k in 0..choices {
        let v = pick(&full, k);
        if !out.contains(&v) {
            out.push(v);
        }
    }
    out
}

/// Each word's `k`-th choice (its last if it has fewer).
fn pick(words: &[String], k: usize) -> Vec<String> {
    words
        .iter()
        .map(|w| {
            let choices: Vec<&str> = w.split('|').collect();
            choices[k.min(choices.len() - 1)].to_string()
        })
        .collect()
}

/// Whether `words` match `rule` (its subcommand, then words in order).
fn matches_rule(words: &[String], rule: &str) -> bool {
    let mut rule = rule.split_whitespace();
    let Some(sub) = rule.next() else {
        return false;
    };
    if words.first().is_none_or(|w| w != sub) {
        return false;
    }
    let mut rest = words[1..].iter();
    rule.all(|r| rest.any(|w| w == r))
}

/// What stands for the docs' placeholders in this test.
struct Placeholders {
    values: Vec<(&'static str, String)>,
    root: PathBuf,
}

impl Placeholders {
    fn new(root: &Path, hand: &Path) -> Placeholders {
        let root = root.canonicalize().unwrap();
        let values = PLACEHOLDERS
            .iter()
            .map(|(name, value)| {
                let value = value
                    .replace("{repo}", root.to_str().unwrap())
                    .replace("{run}", RUN)
                    .replace("{hand}", hand.to_str().unwrap());
                (*name, value)
            })
            .collect();
        Placeholders { values, root }
    }

    /// `words` with the placeholders substituted and the repository's paths made absolute;
    /// an error names a word in capitals left over.
    fn apply(&self, words: &[String]) -> Result<Vec<String>, String> {
        let mut out = Vec::new();
        for word in words {
            let mut w = String::new();
            let mut token = String::new();
            for c in word.chars().chain(std::iter::once('\0')) {
                if c.is_ascii_alphanumeric() || "_.-".contains(c) {
                    token.push(c);
                    continue;
                }
                let value = self.values.iter().find(|(name, _)| *name == token);
                match value {
                    Some((_, v)) => w.push_str(v),
                    None if token.starts_with(|c: char| c.is_ascii_uppercase())
                        && token
                            .chars()
                            .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || c == '_') =>
                    {
                        return Err(format!(
                            "a placeholder the test does not know: {token} (add it to PLACEHOLDERS)"
                        ));
                    }
                    None => w.push_str(&token),
                }
                token.clear();
                if c != '\0' {
                    w.push(c);
                }
            }
            let in_repo = self.root.join(&w);
            if w.contains('/') && !w.starts_with('-') && !w.starts_with('/') && in_repo.is_file() {
                w = in_repo.to_str().unwrap().to_string();
            }
            out.push(w);
        }
        Ok(out)
    }
}

/// Runs `graspopt args` in `dir` (with `GRASPOPT_PARSE_ONLY=1` if `parse_only`); an error
/// says how it failed, with its output.
fn run(dir: &Path, args: &[String], parse_only: bool, deadline: Duration) -> Result<(), String> {
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    let n = RUNS.fetch_add(1, Ordering::Relaxed);
    let (stdout, stderr) = (dir.join(format!(".out-{n}")), dir.join(format!(".err-{n}")));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_graspopt"));
    cmd.args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(fs::File::create(&stdout).unwrap())
        .stderr(fs::File::create(&stderr).unwrap());
    if parse_only {
        cmd.env("GRASPOPT_PARSE_ONLY", "1");
    } else {
        cmd.env_remove("GRASPOPT_PARSE_ONLY");
    }
    let mut child = cmd.spawn().unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if start.elapsed() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let tail = |p: &Path| {
        let text = fs::read_to_string(p).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        lines[lines.len().saturating_sub(8)..].join("\n")
    };
    match status {
        Some(s) if s.success() => Ok(()),
        Some(s) => Err(format!("{s}:\n{}", tail(&stderr))),
        None => Err(format!(
            "still running after {deadline:?} (one that serves until stopped belongs in NOT_RUN)"
        )),
    }
}

/// The scratch folder the commands run in: a hand of its own for `my_gripper.urdf`, and a small
/// run `RUN` for `R`.
fn prepare(dir: &Path) -> PathBuf {
    // A hand of a user's own: the journeys test's (URDF, settings, a mesh link).
    let hands = dir.join("hands");
    fs::create_dir_all(hands.join("meshes")).unwrap();
    let claw = repo_root().join("tests/data/hands/claw");
    for (from, to) in [
        ("claw.urdf", "my_gripper.urdf"),
        ("claw.toml", "my_gripper.toml"),
        ("meshes/finger.obj", "meshes/finger.obj"),
    ] {
        fs::copy(claw.join(from), hands.join(to)).unwrap();
    }
    let args: Vec<String> = ["run", "--object", "sphere", "--trials", "6", "--run", RUN]
        .map(String::from)
        .to_vec();
    run(dir, &args, false, RUN_DEADLINE).unwrap();
    hands.join("my_gripper.urdf")
}

/// Which list a command is in, if any: (`NOT_RUN` or `SLOW`, the rule).
fn listed(words: &[String]) -> Option<(&'static str, &'static str)> {
    let not_run = NOT_RUN.iter().map(|(r, _)| ("NOT_RUN", *r));
    let slow = SLOW.iter().map(|(r, _)| ("SLOW", *r));
    not_run.chain(slow).find(|(_, r)| matches_rule(words, r))
}

/// Parses every command of the docs, and runs for real the variants to run of those that
/// `select` takes; returns the failures.
fn check(select: impl Fn(Option<&str>) -> bool, parse: bool) -> Vec<String> {
    let root = repo_root();
    let (commands, mut failures) = doc_commands(&root);
    assert!(
        commands.iter().any(|c| c.at.starts_with("README.md"))
            && commands.iter().any(|c| c.at.starts_with("docs/hands.md"))
            && commands.iter().any(|c| c.at.starts_with("examples/")),
        "the docs' commands were not found: {commands:?}"
    );
    let dir = tempdir("doc-commands");
    let hand = prepare(&dir);
    let placeholders = Placeholders::new(&root, &hand);
    for command in &commands {
        for (k, variant) in variants(&command.words).iter().enumerate() {
            let list = listed(variant).map(|(list, _)| list);
            let words = match placeholders.apply(variant) {
                Ok(words) => words,
                Err(e) => {
                    failures.push(format!("{}: {}: {e}", command.at, command.text()));
                    continue;
                }
            };
            let shown = format!("{}: graspopt {}", command.at, variant.join(" "));
            if parse && let Err(e) = run(&dir, &words, true, PARSE_DEADLINE) {
                failures.push(format!("{shown}: does not parse: {e}"));
                continue;
            }
            if k < 2 && select(list) {
                let start = Instant::now();
                match run(&dir, &words, false, RUN_DEADLINE) {
                    Ok(()) => eprintln!("ran in {:.1?}: {shown}", start.elapsed()),
                    Err(e) => failures.push(format!("{shown}: fails: {e}")),
                }
            }
        }
    }
    failures
}

#[test]
fn every_command_in_the_docs_parses() {
    let failures = check(|_| false, true);
    assert!(
        failures.is_empty(),
        "commands of the docs that do not parse:\n{}",
        failures.join("\n")
    );
}

/// Half a minute: `cargo test --workspace` keeps to parsing them (above).
#[test]
#[ignore = "half a minute of real runs; .ci/run runs it"]
fn the_cheap_commands_in_the_docs_run() {
    let failures = check(|list| list.is_none(), false);
    assert!(
        failures.is_empty(),
        "commands of the docs that fail:\n{}",
        failures.join("\n")
    );
}

#[test]
#[ignore = "slow: two minutes (the README's optimize-function); run it by hand, .ci/run parses it only"]
fn the_slow_commands_in_the_docs_run() {
    let failures = check(|list| list == Some("SLOW"), false);
    assert!(
        failures.is_empty(),
        "slow commands of the docs that fail:\n{}",
        failures.join("\n")
    );
}

/// Every rule of `NOT_RUN` and `SLOW` matches a command of the docs (a rule left over from a
/// command since removed would keep a new one from running).
#[test]
fn every_command_not_run_is_in_the_docs() {
    let (commands, _) = doc_commands(&repo_root());
    for (rule, why) in NOT_RUN.iter().chain(SLOW) {
        assert!(!why.is_empty());
        assert!(
            commands
                .iter()
                .flat_map(|c| variants(&c.words))
                .any(|v| matches_rule(&v, rule)),
            "no command of the docs matches `{rule}`: remove it"
        );
    }
}

#[test]
fn parse_only_refuses_what_the_cli_refuses_and_does_nothing() {
    let dir = tempdir("parse-only");
    let args = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    // Parsed, and nothing written.
    run(
        &dir,
        &args(&["scan", "--out", "scan", "--steps", "5"]),
        true,
        PARSE_DEADLINE,
    )
    .unwrap();
    assert!(!dir.join("scan").exists());
    // A server returns at once.
    run(
        &dir,
        &args(&["router", "--listen", "tcp/127.0.0.1:0"]),
        true,
        PARSE_DEADLINE,
    )
    .unwrap();
    // What clap refuses is refused: an unknown flag, a missing argument, a bad choice.
    for (bad, says) in [
        (&["trial", "--no-such-flag"][..], "--no-such-flag"),
        (&["export"][..], "<RUN>"),
        (&["export", "r", "--format", "xml"][..], "xml"),
    ] {
        let e = run(&dir, &args(bad), true, PARSE_DEADLINE).unwrap_err();
        assert!(
            e.contains("exit status: 2") && e.contains(says),
            "{bad:?}: {e}"
        );
    }
}

#[test]
fn commands_are_read_as_a_user_reads_them() {
    let doc = "\
```sh
# a comment
graspopt trial --object mug   # what follows is a comment
for i in 1 2; do target/release/graspopt bench coordinator \\
    --workers 1,2; done
cargo run -p graspopt -- run --trials 3
RUST_LOG=info graspopt hands &
python3 hand.py --run mug
```

```text
$ graspopt topic list
graspopt/demo/clouds   ContactClouds
```

```
graspopt          agents/graspopt   the one binary
graspopt hands
```
";
    let (commands, errors) = commands_of("doc.md", &fenced_blocks(doc));
    let found: Vec<(String, String)> = commands.iter().map(|c| (c.at.clone(), c.text())).collect();
    let expected = [
        ("doc.md:3", "graspopt trial --object mug"),
        ("doc.md:4", "graspopt bench coordinator --workers 1,2"),
        ("doc.md:6", "graspopt run --trials 3"),
        ("doc.md:7", "graspopt hands"),
        ("doc.md:12", "graspopt topic list"),
    ];
    let expected: Vec<(String, String)> = expected
        .iter()
        .map(|(a, t)| (a.to_string(), t.to_string()))
        .collect();
    assert_eq!(found, expected);
    // The diagram's line is no command; the bare `graspopt hands` in an unlabelled block is
    // one the test would not see.
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0].starts_with("doc.md:18:"), "{errors:?}");
    let words = |s: &str| s.split_whitespace().map(String::from).collect::<Vec<_>>();
    assert_eq!(
        variants(&words(
            "quality --input FILE [--format json|table] [--timing]"
        )),
        [
            words("quality --input FILE"),
            words("quality --input FILE --format json --timing"),
            words("quality --input FILE --format table --timing"),
        ]
    );
    let placeholders = Placeholders::new(&repo_root(), Path::new("/h/g.urdf"));
    let applied = placeholders
        .apply(&words(
            "agent hand --run R --connect tcp/ROUTER:7447 --set hand=my_gripper.urdf",
        ))
        .unwrap();
    assert_eq!(
        applied,
        words("agent hand --run docs --connect tcp/127.0.0.1:7447 --set hand=/h/g.urdf")
    );
    let launch = placeholders
        .apply(&words("launch deploy/local.toml"))
        .unwrap();
    assert!(Path::new(&launch[1]).is_absolute() && Path::new(&launch[1]).exists());
    assert!(placeholders.apply(&words("export RUN")).is_err());
    assert!(matches_rule(
        &words("quality --input f --timing"),
        "quality --timing"
    ));
    assert!(!matches_rule(
        &words("quality --input f"),
        "quality --timing"
    ));
}
