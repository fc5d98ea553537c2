//! The fixed little-endian layout of [`ContactClouds`] that hands write straight into a
//! shared-memory sample and metric agents read back, with validation, in one pass (no bincode,
//! no intermediate buffer). Zenoh keeps the portable encodings of [`crate::codec`].
//!
//! ```text
//! offset size  field (every number little-endian)
//!      0    4  magic "GPCL"
//!      4    2  u16 wire version (WIRE_VERSION)
//!      6    2  u16 flags: bit 0 min_gap present, bit 1 error present (other bits 0)
//!      8    8  u64 trial_id
//!     16    4  u32 attempt
//!     20    4  u32 F, the number of finger clouds
//!     24    8  i64 executed_ms
//!     32    8  f64 min_gap (0 when absent)
//!     40   56  f64 x 7 palm_pose: translation x y z, rotation w x y z
//!     96   16  u32 x 4 byte lengths of run_id, worker, hand, error (0 when absent)
//!    112 16 F  per finger: u32 has_finger (0 palm, 1 finger), u32 finger (0 for the palm),
//!              u32 number of links, u32 number of points
//!              run_id, worker, hand, error: UTF-8 bytes, no terminator
//!              per finger, per link: u32 byte length, UTF-8 bytes
//!              zero bytes up to a multiple of 8
//!              points, finger after finger, 56 bytes each: f64 p x y z, n x y z, w
//! ```
//!
//! The payload is exactly that long. [`read_clouds`] refuses a payload whose sizes disagree
//! (naming the field it could not read), then checks what [`Message::validate`] checks, with
//! the same messages, as it reads each point.

use crate::WIRE_VERSION;
use crate::codec::{DecodeError, EncodeError, MAX_PAYLOAD};
use crate::error::ValidationError;
use crate::keys::RunId;
use crate::messages::{CloudPoint, ContactClouds, FingerCloud, Message, Pose};
use zerocopy::{FromBytes, IntoBytes};

/// The first four bytes of every payload in this layout.
pub const MAGIC: [u8; 4] = *b"GPCL";
/// Bytes of the fixed part of the header.
pub const FIXED_HEADER: usize = 112;
/// Bytes of one finger's entry in the finger table.
pub const FINGER_ENTRY: usize = 16;
/// Bytes of one point.
pub const POINT_BYTES: usize = 56;
const _: () = assert!(size_of::<CloudPoint>() == POINT_BYTES);

const FORMAT: &str = "shm layout";
const HAS_MIN_GAP: u16 = 1;
const HAS_ERROR: u16 = 2;

fn too_big(detail: String) -> EncodeError {
    EncodeError {
        message_type: ContactClouds::TYPE,
        format: FORMAT,
        detail,
    }
}

fn len_u32(field: &str, len: usize) -> Result<u32, EncodeError> {
    u32::try_from(len).map_err(|_| too_big(format!("{field} has {len} elements, more than 2^32")))
}

/// Bytes of `msg` in this layout, before padding to 8: header, finger table and texts.
fn header_len(msg: &ContactClouds) -> usize {
    let texts = msg.run_id.as_str().len()
        + msg.worker.len()
        + msg.hand.len()
        + msg.error.as_deref().map_or(0, str::len);
    let links: usize = msg
        .fingers
        .iter()
        .flat_map(|f| &f.links)
        .map(|l| 4 + l.len())
        .sum();
    FIXED_HEADER + FINGER_ENTRY * msg.fingers.len() + texts + links
}

/// Bytes `msg` takes in this layout; an error if a count does not fit its field or the total
/// exceeds [`MAX_PAYLOAD`].
pub fn clouds_len(msg: &ContactClouds) -> Result<usize, EncodeError> {
    let total = header_len(msg).next_multiple_of(8) + POINT_BYTES * msg.point_count();
    if total > MAX_PAYLOAD {
        return Err(too_big(format!(
            "{total} bytes, more than the {MAX_PAYLOAD}-byte limit"
        )));
    }
    Ok(total)
}

/// Writes `out[at..]` with `bytes` and returns the next offset.
#[inline]
fn put(out: &mut [u8], at: usize, bytes: &[u8]) -> usize {
    let end = at + bytes.len();
    out[at..end].copy_from_slice(bytes);
    end
}

/// Writes `msg` into `out`, which must be exactly [`clouds_len`] bytes long (a loaned
/// shared-memory slice); every byte of it is written.
pub fn write_clouds(msg: &ContactClouds, out: &mut [u8]) -> Result<(), EncodeError> {
    let len = clouds_len(msg)?;
    if out.len() != len {
        return Err(too_big(format!(
            "the buffer has {} bytes, the message needs {len}",
            out.len()
        )));
    }
    let error = msg.error.as_deref().unwrap_or("");
    let flags = if msg.min_gap.is_some() {
        HAS_MIN_GAP
    } else {
        0
    } | if msg.error.is_some() { HAS_ERROR } else { 0 };
    let mut at = put(out, 0, &MAGIC);
    at = put(out, at, &WIRE_VERSION.to_le_bytes());
    at = put(out, at, &flags.to_le_bytes());
    at = put(out, at, &msg.trial_id.to_le_bytes());
    at = put(out, at, &msg.attempt.to_le_bytes());
    at = put(
        out,
        at,
        &len_u32("fingers", msg.fingers.len())?.to_le_bytes(),
    );
    at = put(out, at, &msg.executed_ms.to_le_bytes());
    at = put(out, at, &msg.min_gap.unwrap_or(0.0).to_le_bytes());
    let pose = &msg.palm_pose;
    for v in pose.translation.iter().chain(&pose.rotation) {
        at = put(out, at, &v.to_le_bytes());
    }
    let texts = [msg.run_id.as_str(), &msg.worker, &msg.hand, error];
    for (name, text) in ["run_id", "worker", "hand", "error"].iter().zip(texts) {
        at = put(out, at, &len_u32(name, text.len())?.to_le_bytes());
    }
    for (i, f) in msg.fingers.iter().enumerate() {
        at = put(out, at, &u32::from(f.finger.is_some()).to_le_bytes());
        at = put(out, at, &f.finger.unwrap_or(0).to_le_bytes());
        at = put(
            out,
            at,
            &len_u32(&format!("fingers[{i}].links"), f.links.len())?.to_le_bytes(),
        );
        at = put(
            out,
            at,
            &len_u32(&format!("fingers[{i}].points"), f.points.len())?.to_le_bytes(),
        );
    }
    for text in texts {
        at = put(out, at, text.as_bytes());
    }
    for link in msg.fingers.iter().flat_map(|f| &f.links) {
        at = put(out, at, &len_u32("link", link.len())?.to_le_bytes());
        at = put(out, at, link.as_bytes());
    }
    let start = at.next_multiple_of(8);
    out[at..start].fill(0);
    let mut at = start;
    for f in &msg.fingers {
        let block = &mut out[at..at + POINT_BYTES * f.points.len()];
        block.copy_from_slice(f.points.as_bytes());
        swap_if_big_endian(block);
        at += block.len();
    }
    Ok(())
}

/// Turns points' bytes in memory into the layout's, and the layout's back into memory's:
/// nothing on a little-endian host, each `f64`'s bytes reversed on a big-endian one.
fn swap_if_big_endian(points: &mut [u8]) {
    if cfg!(target_endian = "big") {
        for word in points.as_chunks_mut::<8>().0 {
            word.reverse();
        }
    }
}

/// A finger's points from their bytes in the layout: one copy of the block (10,000 points:
/// 14 µs, against 62 µs converted point by point, on the 2-core machine of
/// docs/benchmarks.md), straight from the payload when it is aligned for `f64` (an iceoryx2
/// 0.10 sample is, by its header's size, though the service asks only for bytes), through an
/// aligned buffer otherwise.
fn points_from(block: &[u8]) -> Vec<CloudPoint> {
    let mut points = match <[CloudPoint]>::ref_from_bytes(block) {
        Ok(points) => points.to_vec(),
        Err(_) => {
            let zero = CloudPoint {
                p: [0.0; 3],
                n: [0.0; 3],
                w: 0.0,
            };
            let mut points = vec![zero; block.len() / POINT_BYTES];
            points.as_mut_bytes().copy_from_slice(block);
            points
        }
    };
    swap_if_big_endian(points.as_mut_bytes());
    points
}

/// Reads the payload front to back; each read names the field, for the error if the payload
/// ends first.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

fn malformed(detail: String) -> DecodeError {
    DecodeError::Malformed {
        message_type: ContactClouds::TYPE,
        format: FORMAT,
        detail,
    }
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, field: impl Fn() -> String) -> Result<&'a [u8], DecodeError> {
        let end = self
            .at
            .checked_add(n)
            .filter(|&end| end <= self.bytes.len());
        let Some(end) = end else {
            return Err(malformed(format!(
                "truncated: {} needs {n} bytes at offset {}, the payload has {}",
                field(),
                self.at,
                self.bytes.len()
            )));
        };
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn array<const N: usize>(&mut self, field: &str) -> Result<[u8; N], DecodeError> {
        let bytes = self.take(N, || field.to_owned())?;
        let mut out = [0; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }

    fn u16(&mut self, field: &str) -> Result<u16, DecodeError> {
        self.array(field).map(u16::from_le_bytes)
    }

    fn u32(&mut self, field: &str) -> Result<u32, DecodeError> {
        self.array(field).map(u32::from_le_bytes)
    }

    fn u64(&mut self, field: &str) -> Result<u64, DecodeError> {
        self.array(field).map(u64::from_le_bytes)
    }

    fn f64(&mut self, field: &str) -> Result<f64, DecodeError> {
        self.array(field).map(f64::from_le_bytes)
    }

    fn text(&mut self, len: u32, field: impl Fn() -> String) -> Result<String, DecodeError> {
        let bytes = self.take(len as usize, &field)?;
        String::from_utf8(bytes.to_vec())
            .map_err(|e| malformed(format!("{} is not UTF-8: {e}", field())))
    }
}

/// Reads and validates clouds written by [`write_clouds`]; the same checks, with the same
/// messages, as [`crate::decode`] runs. In the layout's order: the fixed header, the finger
/// table, the texts, the links, then the points.
pub fn read_clouds(bytes: &[u8]) -> Result<ContactClouds, DecodeError> {
    check_size(bytes)?;
    let mut r = Reader { bytes, at: 0 };
    let header = read_header(&mut r)?;
    let shape = read_finger_table(&mut r, header.finger_count)?;
    let [run_len, worker_len, hand_len, error_len] = header.lens;
    let run_id = r.text(run_len, || "run_id".into())?;
    let run_id = RunId::new(&run_id).map_err(|e| malformed(format!("run_id: {e}")))?;
    let worker = r.text(worker_len, || "worker".into())?;
    let hand = r.text(hand_len, || "hand".into())?;
    let error = r.text(error_len, || "error".into())?;
    let fingers = read_links(&mut r, &shape)?;
    let points_at = points_start(&mut r, &shape)?;
    let pose = header.pose;
    let msg = ContactClouds {
        run_id,
        trial_id: header.trial_id,
        attempt: header.attempt,
        worker,
        hand,
        palm_pose: Pose {
            translation: [pose[0], pose[1], pose[2]],
            rotation: [pose[3], pose[4], pose[5], pose[6]],
        },
        fingers: Vec::new(),
        min_gap: (header.flags & HAS_MIN_GAP != 0).then_some(header.min_gap),
        error: (header.flags & HAS_ERROR != 0).then_some(error),
        executed_ms: header.executed_ms,
    };
    read_points(msg, fingers, &shape, &bytes[points_at..])
}

/// A payload that is empty or over [`MAX_PAYLOAD`] is refused before it is read.
fn check_size(bytes: &[u8]) -> Result<(), DecodeError> {
    let message_type = ContactClouds::TYPE;
    if bytes.is_empty() {
        return Err(DecodeError::Empty { message_type });
    }
    if bytes.len() > MAX_PAYLOAD {
        return Err(DecodeError::TooLarge {
            message_type,
            size: bytes.len(),
        });
    }
    Ok(())
}

/// The fixed part of the header, as read.
struct Header {
    flags: u16,
    trial_id: u64,
    attempt: u32,
    finger_count: usize,
    executed_ms: i64,
    min_gap: f64,
    pose: [f64; 7],
    /// The byte lengths of run_id, worker, hand and error.
    lens: [u32; 4],
}

/// Reads the fixed header, checking the magic, the wire version and the flags.
fn read_header(r: &mut Reader) -> Result<Header, DecodeError> {
    let magic = r.array::<4>("magic")?;
    if magic != MAGIC {
        return Err(malformed(format!(
            "magic is {magic:?}, not {MAGIC:?} (\"GPCL\"): not contact clouds in this layout"
        )));
    }
    let version = r.u16("wire version")?;
    if version != WIRE_VERSION {
        return Err(DecodeError::WrongVersion {
            message_type: ContactClouds::TYPE,
            found: u64::from(version),
            expected: WIRE_VERSION,
        });
    }
    let flags = r.u16("flags")?;
    if flags & !(HAS_MIN_GAP | HAS_ERROR) != 0 {
        return Err(malformed(format!("flags has unknown bits: {flags:#06x}")));
    }
    let trial_id = r.u64("trial_id")?;
    let attempt = r.u32("attempt")?;
    let finger_count = r.u32("finger count")? as usize;
    let executed_ms = r.array("executed_ms").map(i64::from_le_bytes)?;
    let min_gap = r.f64("min_gap")?;
    let mut pose = [0.0; 7];
    for (i, v) in pose.iter_mut().enumerate() {
        *v = r.f64(&format!("palm_pose[{i}]"))?;
    }
    let mut lens = [0u32; 4];
    let names = ["run_id", "worker", "hand", "error"];
    for (len, name) in lens.iter_mut().zip(names) {
        *len = r.u32(&format!("{name} length"))?;
    }
    Ok(Header {
        flags,
        trial_id,
        attempt,
        finger_count,
        executed_ms,
        min_gap,
        pose,
        lens,
    })
}

/// One finger's entry of the finger table.
struct FingerShape {
    finger: Option<u32>,
    links: usize,
    points: usize,
}

/// Reads the finger table; its size is checked against the payload before anything is
/// allocated for it.
fn read_finger_table(r: &mut Reader, finger_count: usize) -> Result<Vec<FingerShape>, DecodeError> {
    let table = r.take(finger_count.saturating_mul(FINGER_ENTRY), || {
        format!("the finger table ({finger_count} fingers)")
    })?;
    let mut shape = Vec::with_capacity(finger_count);
    for (f, entry) in table.as_chunks::<FINGER_ENTRY>().0.iter().enumerate() {
        let word =
            |k: usize| u32::from_le_bytes([entry[k], entry[k + 1], entry[k + 2], entry[k + 3]]);
        let finger = match word(0) {
            0 => None,
            1 => Some(word(4)),
            tag => {
                return Err(malformed(format!(
                    "fingers[{f}].finger has tag {tag}, not 0 (palm) or 1"
                )));
            }
        };
        shape.push(FingerShape {
            finger,
            links: word(8) as usize,
            points: word(12) as usize,
        });
    }
    Ok(shape)
}

/// Reads each finger's links: the fingers, without their points yet.
fn read_links(r: &mut Reader, shape: &[FingerShape]) -> Result<Vec<FingerCloud>, DecodeError> {
    let mut fingers = Vec::with_capacity(shape.len());
    for (f, s) in shape.iter().enumerate() {
        // Each link takes at least 4 bytes: no more is reserved than the payload can hold,
        // and a count too large ends in a truncation error naming the link.
        let mut names = Vec::with_capacity(s.links.min((r.bytes.len() - r.at) / 4));
        for l in 0..s.links {
            let len = r.u32(&format!("fingers[{f}].links[{l}] length"))?;
            names.push(r.text(len, || format!("fingers[{f}].links[{l}]"))?);
        }
        fingers.push(FingerCloud {
            finger: s.finger,
            links: names,
            points: Vec::new(),
        });
    }
    Ok(fingers)
}

/// Skips the padding before the points and returns where they start, once the rest of the
/// payload is exactly the points the finger table declares.
fn points_start(r: &mut Reader, shape: &[FingerShape]) -> Result<usize, DecodeError> {
    let padding = r.at.next_multiple_of(8) - r.at;
    r.take(padding, || "padding before the points".into())?;
    let points_len = r.bytes.len() - r.at;
    let declared: usize = shape.iter().map(|s| s.points).sum();
    if declared.checked_mul(POINT_BYTES) != Some(points_len) {
        return Err(malformed(format!(
            "points: the finger table declares {declared} points ({} bytes), the payload has {points_len} bytes for them",
            declared.saturating_mul(POINT_BYTES)
        )));
    }
    Ok(r.at)
}

/// Validates `msg`'s header, then reads each finger's points from `points` (every point of
/// the payload, finger after finger) and checks them; `msg` with its fingers.
fn read_points(
    mut msg: ContactClouds,
    mut fingers: Vec<FingerCloud>,
    shape: &[FingerShape],
    points: &[u8],
) -> Result<ContactClouds, DecodeError> {
    let invalid = |msg: &ContactClouds, detail: ValidationError| DecodeError::Invalid {
        message_type: ContactClouds::TYPE,
        detail,
        about: msg.attempt_ref().map(Box::new),
    };
    if let Err(detail) = msg.validate_header() {
        return Err(invalid(&msg, detail));
    }
    let mut at = 0;
    for (f, (finger, s)) in fingers.iter_mut().zip(shape).enumerate() {
        let block = &points[at..at + s.points * POINT_BYTES];
        at += block.len();
        // Copied first, then checked in one branch-free sweep; the error is formatted only
        // for the first point that fails (`graspopt bench clouds`: 88 µs to 43 µs for 10,000
        // points against checking each point as it is read).
        finger.points = points_from(block);
        if !finger.points.iter().fold(true, |ok, pt| ok & pt.is_valid()) {
            for (i, pt) in finger.points.iter().enumerate() {
                pt.validate(f, i).map_err(|detail| invalid(&msg, detail))?;
            }
        }
    }
    msg.fingers = fingers;
    Ok(msg)
}
