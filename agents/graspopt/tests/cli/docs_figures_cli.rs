//! The figures in docs/figures against the commands the docs cite for them. Each is listed in
//! docs/figures/figures.txt with the file its command writes and the POSIX `cksum` (CRC and
//! size) of the command's CSV, written by docs/figures/regenerate.sh. The tests rerun the
//! commands and fail when a CSV changed: the figure no longer shows what its command draws.
//! PNG and SVG bytes are not compared (a font or an encoder may differ between machines); the
//! numbers are.
//!
//! The commands of at most [`FAST_BYTES`] of CSV run in `cargo test`; the others (the star
//! prism's 87,241-point scan, about a minute) in the ignored test that `.ci/run` runs.

use std::path::{Path, PathBuf};

use crate::support::{graspopt_ok, tempdir};

/// CSVs up to this size are checked by the test that is not ignored.
const FAST_BYTES: u64 = 1_000_000;

/// One line of figures.txt.
#[derive(Debug)]
struct Figure {
    /// The figure's file in docs/figures.
    figure: String,
    /// The file the command writes into its `--out` folder.
    written: String,
    /// `cksum` of the command's CSV: CRC and size in bytes.
    crc: u32,
    bytes: u64,
    /// The command's arguments.
    args: Vec<String>,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The figures of docs/figures/figures.txt.
fn figures() -> Vec<Figure> {
    let list = std::fs::read_to_string(root().join("docs/figures/figures.txt")).unwrap();
    list.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            assert!(words.len() > 4, "figures.txt: {l}");
            Figure {
                figure: words[0].into(),
                written: words[1].into(),
                crc: words[2].parse().unwrap_or_else(|_| panic!("CRC in {l}")),
                bytes: words[3].parse().unwrap_or_else(|_| panic!("size in {l}")),
                args: words[4..].iter().map(|w| w.to_string()).collect(),
            }
        })
        .collect()
}

/// The checksum of POSIX `cksum`: CRC-32 with the polynomial 0x04C11DB7, most significant
/// bit first, over the data and then its length (least significant byte first, as few bytes
/// as it takes), complemented.
fn cksum(data: &[u8]) -> u32 {
    fn feed(crc: u32, byte: u8) -> u32 {
        let mut crc = crc ^ (u32::from(byte) << 24);
        for _ in 0..8 {
            crc = if crc & 0x8000_0000 != 0 {
                (crc << 1) ^ 0x04C1_1DB7
            } else {
                crc << 1
            };
        }
        crc
    }
    let mut crc = data.iter().fold(0, |crc, &b| feed(crc, b));
    let mut n = data.len();
    while n > 0 {
        crc = feed(crc, (n & 0xff) as u8);
        n >>= 8;
    }
    !crc
}

#[test]
fn cksum_is_posix_cksum() {
    // `printf 123456789 | cksum` and `printf '' | cksum`.
    assert_eq!(cksum(b"123456789"), 930_766_865);
    assert_eq!(cksum(b""), 4_294_967_295);
}

/// README.md and docs/*.md, each with its whitespace runs made single spaces (a command
/// wrapped across lines reads as one line).
fn docs() -> Vec<(PathBuf, String)> {
    let mut paths = vec![root().join("README.md")];
    for entry in std::fs::read_dir(root().join("docs")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "md") {
            paths.push(path);
        }
    }
    paths
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).unwrap();
            (p, text.split_whitespace().collect::<Vec<_>>().join(" "))
        })
        .collect()
}

#[test]
fn every_figure_in_the_docs_is_listed_and_its_command_cited_beside_it() {
    let figures = figures();
    let mut on_disk: Vec<String> = std::fs::read_dir(root().join("docs/figures"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n != "figures.txt" && n != "regenerate.sh")
        .collect();
    on_disk.sort();
    let mut listed: Vec<String> = figures.iter().map(|f| f.figure.clone()).collect();
    listed.sort();
    assert_eq!(on_disk, listed, "docs/figures and figures.txt differ");
    let docs = docs();
    for f in &figures {
        let command = format!("graspopt {}", f.args.join(" "));
        let citing = docs
            .iter()
            .find(|(_, text)| text.contains(&format!("figures/{}", f.figure)))
            .unwrap_or_else(|| panic!("no doc shows {}", f.figure));
        assert!(
            citing.1.contains(&command),
            "{} shows {} without citing `{command}`",
            citing.0.display(),
            f.figure
        );
        let stem = Path::new(&f.written).file_stem().unwrap().to_string_lossy();
        let ext = |p: &str| Path::new(p).extension().map(|e| e.to_owned());
        assert_eq!(ext(&f.figure), ext(&f.written), "{f:?}");
        assert!(f.args[0] == "scan" && !stem.is_empty(), "{f:?}");
    }
}

/// Runs the command of every figure that `run` picks and compares its CSV with the recorded
/// checksum; fails naming every figure whose command's CSV changed.
fn check(run: impl Fn(&Figure) -> bool) {
    let dir = tempdir("docs-figures");
    let mut changed = Vec::new();
    let mut ran = 0;
    for (k, f) in figures().iter().filter(|f| run(f)).enumerate() {
        let out = dir.join(k.to_string());
        let mut args: Vec<&str> = f.args.iter().map(String::as_str).collect();
        args.extend(["--out", out.to_str().unwrap()]);
        graspopt_ok(&args);
        ran += 1;
        assert!(out.join(&f.written).is_file(), "{} not written", f.written);
        let stem = Path::new(&f.written).file_stem().unwrap().to_string_lossy();
        let csv = std::fs::read(out.join(format!("{stem}.csv"))).unwrap();
        let now = (cksum(&csv), csv.len() as u64);
        if now != (f.crc, f.bytes) {
            changed.push(format!(
                "{}: `graspopt {}` gives a CSV of cksum {} {}, figures.txt records {} {}",
                f.figure,
                f.args.join(" "),
                now.0,
                now.1,
                f.crc,
                f.bytes
            ));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(ran > 0, "no figure checked");
    assert!(
        changed.is_empty(),
        "figures that no longer show what their command draws (run docs/figures/regenerate.sh \
         FIGURE, look at it, and update the numbers the docs give about it):\n{}",
        changed.join("\n")
    );
}

#[test]
fn the_figures_of_small_scans_show_what_their_commands_draw_now() {
    check(|f| f.bytes <= FAST_BYTES);
}

#[test]
#[ignore = "the star prism's 87,241-point scan takes about a minute: .ci/run runs it"]
fn the_figures_of_large_scans_show_what_their_commands_draw_now() {
    check(|f| f.bytes > FAST_BYTES);
}
