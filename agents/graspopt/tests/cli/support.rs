//! Helpers shared by the CLI tests: run the binary, a scratch folder, decode a PNG.
#![allow(dead_code)] // each test file uses its own subset

use std::fs::File;
use std::io::BufReader;
use std::path::Path;
use std::process::{Command, Output};

/// Runs the `graspopt` binary built for these tests.
pub fn graspopt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_graspopt"))
        .args(args)
        .output()
        .expect("run graspopt")
}

/// Runs the `graspopt` binary and asserts it succeeded, showing its stderr if not.
pub fn graspopt_ok(args: &[&str]) -> Output {
    let out = graspopt(args);
    assert!(
        out.status.success(),
        "graspopt {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

pub use crate::scratch::tempdir;

/// Width, height and RGB pixels of an 8-bit RGB PNG.
pub fn decode_png(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let file = BufReader::new(File::open(path).unwrap());
    let mut reader = png::Decoder::new(file).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    let px = buf[..info.buffer_size()]
        .chunks(3)
        .map(|c| [c[0], c[1], c[2]])
        .collect();
    (info.width, info.height, px)
}
