//! The shared-memory layout of contact clouds (`layout`): round trips, and refusal of bad
//! points and inconsistent payloads with the messages `decode` gives.

use graspopt_protocol::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;
use common::clouds;

/// `c` written through the layout into a buffer of junk (every byte must be written).
fn layout_bytes(c: &ContactClouds) -> Vec<u8> {
    let mut out = vec![0xa5; layout::clouds_len(c).unwrap()];
    layout::write_clouds(c, &mut out).unwrap();
    out
}

/// Clouds with every optional field set, a palm cloud and more than one link and point.
fn full_clouds() -> ContactClouds {
    let mut c = clouds();
    c.min_gap = Some(0.0125);
    c.fingers[1].points = vec![
        CloudPoint {
            p: [-0.5, 0.25, 1e10],
            n: [1.0, 0.0, 0.0],
            w: 3.5e-6,
        };
        3
    ];
    c.fingers.push(FingerCloud {
        finger: Some(u32::MAX),
        links: vec!["é-link".into(), String::new(), "f3_proximal".into()],
        points: vec![],
    });
    c
}

#[test]
fn clouds_round_trip_through_the_shm_layout() {
    let mut failed = clouds();
    failed.fingers.clear();
    failed.error = Some("unreachable: joint 2 at its limit".into());
    failed.executed_ms = -5;
    for c in [clouds(), full_clouds(), failed] {
        let bytes = layout_bytes(&c);
        assert_eq!(&bytes[..4], b"GPCL");
        assert_eq!(
            bytes.len() % 8,
            0,
            "points start 8-aligned and take 56 bytes each"
        );
        assert_eq!(layout::read_clouds(&bytes).unwrap(), c);
    }
    // The header of `clouds()`: 112 fixed bytes, two finger entries, the texts
    // "run-1" "hand-1" "barrett", the links "f1_distal" and "palm" with their lengths,
    // padding from 183 to 184, then one point.
    let bytes = layout_bytes(&clouds());
    assert_eq!(bytes.len(), 184 + 56);
    assert_eq!(u64::from_le_bytes(bytes[8..16].try_into().unwrap()), 7);
    assert_eq!(
        f64::from_le_bytes(bytes[184 + 32..184 + 40].try_into().unwrap()),
        0.6
    );
    // Points are copied as one block when the payload is aligned for f64 (an iceoryx2 0.10
    // sample is) and through an aligned buffer when not: both read the same clouds.
    let full = full_clouds();
    let bytes = layout_bytes(&full);
    let mut words = vec![0u64; bytes.len() / 8 + 1];
    let aligned = zerocopy::IntoBytes::as_mut_bytes(words.as_mut_slice());
    aligned[..bytes.len()].copy_from_slice(&bytes);
    assert_eq!(layout::read_clouds(&aligned[..bytes.len()]).unwrap(), full);
    aligned[1..=bytes.len()].copy_from_slice(&bytes);
    assert_eq!(
        layout::read_clouds(&aligned[1..=bytes.len()]).unwrap(),
        full
    );
    // A buffer of the wrong size is refused, not overrun.
    let c = clouds();
    let mut short = vec![0; layout::clouds_len(&c).unwrap() - 1];
    assert!(layout::write_clouds(&c, &mut short).is_err());
}

/// The layout refuses bad points with the message `decode` gives for the same clouds in
/// bincode.
#[test]
fn the_shm_layout_refuses_bad_points_as_validate_does() {
    type Spoil = fn(&mut CloudPoint);
    let cases: [(&str, Spoil); 4] = [
        ("fingers[1].points[2].p[1] is not finite (NaN)", |p| {
            p.p[1] = f64::NAN
        }),
        ("fingers[1].points[2].n[2] is not finite (-inf)", |p| {
            p.n[2] = f64::NEG_INFINITY
        }),
        (
            "fingers[1].points[2].n is not a unit normal (norm 0.5)",
            |p| p.n = [0.5, 0.0, 0.0],
        ),
        (
            "fingers[1].points[2].w must be finite and > 0, got 0",
            |p| p.w = 0.0,
        ),
    ];
    for (expected, spoil) in cases {
        let mut c = full_clouds();
        spoil(&mut c.fingers[1].points[2]);
        let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
        let DecodeError::Invalid { detail, about, .. } = &e else {
            panic!("{expected}: {e:?}");
        };
        assert_eq!(detail.to_string(), expected);
        assert_eq!(about.as_ref().unwrap().trial_id, 7);
        let bincode =
            decode::<ContactClouds>(&encode(&c, Encoding::Bincode).unwrap(), Encoding::Bincode)
                .unwrap_err();
        assert_eq!(e, bincode);
    }
    let mut c = full_clouds();
    c.min_gap = Some(-1.0);
    let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
    assert!(e.to_string().contains("min_gap must be finite"), "{e}");
    let mut c = full_clouds();
    c.worker = "hand/1".into();
    let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
    assert!(e.to_string().contains("worker"), "{e}");
}

/// The branch-free check (which `validate` and the bulk readers run first) accepts exactly
/// the points the rule accepts, written here plainly: p and n finite, |n| within 1e-3 of 1,
/// w finite and > 0; edge values included (infinities times zero, norms just inside and
/// outside 1e-3, a norm whose square overflows). `validate` gives an error exactly then.
#[test]
fn the_fast_point_check_agrees_with_validate() {
    let values = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        0.9991,
        0.9989,
        1.0009,
        1.0011,
        1e-300,
        1e200,
        f64::MAX,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
    ];
    let mut checked = 0;
    let mut accepted = 0;
    for &a in &values {
        for &b in &values {
            for &c in &values {
                for &w in &values {
                    for pt in [
                        CloudPoint {
                            p: [a, b, c],
                            n: [0.0, 0.0, 1.0],
                            w,
                        },
                        CloudPoint {
                            p: [w, 0.0, 0.0],
                            n: [a, b, c],
                            w: 1.0,
                        },
                        CloudPoint {
                            p: [0.0; 3],
                            n: [a, b, c],
                            w,
                        },
                    ] {
                        let norm = pt.n.iter().map(|v| v * v).sum::<f64>().sqrt();
                        let rule = pt.p.iter().chain(&pt.n).all(|v| v.is_finite())
                            && (norm - 1.0).abs() <= 1e-3
                            && pt.w.is_finite()
                            && pt.w > 0.0;
                        assert_eq!(pt.is_valid(), rule, "{pt:?}");
                        assert_eq!(pt.validate(0, 0).is_ok(), rule, "{pt:?}");
                        checked += 1;
                        accepted += usize::from(pt.is_valid());
                    }
                }
            }
        }
    }
    assert_eq!(checked, 3 * values.len().pow(4));
    // Both outcomes occur: the comparison is not vacuous.
    assert!(
        accepted > 0 && accepted < checked,
        "{accepted} of {checked}"
    );
}

/// Of several bad points, the layout names the first, as `validate` does.
#[test]
fn the_shm_layout_names_the_first_bad_point() {
    let mut c = full_clouds();
    c.fingers[1].points[2].w = f64::INFINITY;
    c.fingers[1].points[1].p[0] = f64::NEG_INFINITY;
    let last = c.fingers.len() - 1;
    c.fingers[last].points.push(CloudPoint {
        p: [0.0; 3],
        n: [0.0; 3],
        w: 1.0,
    });
    let e = layout::read_clouds(&layout_bytes(&c)).unwrap_err();
    assert!(
        e.to_string()
            .contains("fingers[1].points[1].p[0] is not finite (-inf)"),
        "{e}"
    );
}

#[test]
fn a_truncated_or_inconsistent_shm_layout_is_refused_naming_the_field() {
    let bytes = layout_bytes(&full_clouds());
    let refused = |b: &[u8]| layout::read_clouds(b).unwrap_err().to_string();
    for cut in 0..bytes.len() {
        refused(&bytes[..cut]);
    }
    let e = refused(&bytes[..50]);
    assert!(
        e.contains("truncated: palm_pose[1] needs 8 bytes at offset 48"),
        "{e}"
    );
    let e = refused(&bytes[..130]);
    assert!(e.contains("the finger table (3 fingers)"), "{e}");
    // Cut inside the third finger's first link name ("é-link", after the texts).
    let link = bytes
        .windows(7)
        .position(|w| w == "é-link".as_bytes())
        .unwrap();
    let e = refused(&bytes[..link + 3]);
    assert!(
        e.contains("truncated: fingers[2].links[0] needs 7 bytes"),
        "{e}"
    );
    // Cut inside the points, or one byte too many.
    let e = refused(&bytes[..bytes.len() - 8]);
    assert!(
        e.contains("declares 4 points (224 bytes), the payload has 216"),
        "{e}"
    );
    let mut long = bytes.clone();
    long.extend_from_slice(&[0; 8]);
    assert!(refused(&long).contains("the payload has 232"));
    // A finger table declaring more points or links than the payload holds, a bad tag,
    // a wrong magic or version, unknown flags.
    let mut more = bytes.clone();
    more[112 + 12..112 + 16].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(refused(&more).contains("declares 4294967298 points"));
    let mut links = bytes.clone();
    links[112 + 8..112 + 12].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = refused(&links);
    assert!(e.contains("truncated: fingers[0].links["), "{e}");
    let mut tag = bytes.clone();
    tag[112 + 16] = 2;
    assert!(refused(&tag).contains("fingers[1].finger has tag 2"));
    let mut magic = bytes.clone();
    magic[0] = b'X';
    assert!(refused(&magic).contains("magic"));
    let mut version = bytes.clone();
    version[4] = version[4].wrapping_add(1);
    assert!(matches!(
        layout::read_clouds(&version),
        Err(DecodeError::WrongVersion { .. })
    ));
    let mut flags = bytes.clone();
    flags[6] = 4;
    assert!(refused(&flags).contains("unknown bits"));
    // Bincode is not this layout, and pseudo-random bytes after a valid magic never panic.
    let bincode = encode(&full_clouds(), Encoding::Bincode).unwrap();
    assert!(refused(&bincode).contains("magic"));
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    for len in 0..3000 {
        let mut junk = bytes[..8].to_vec();
        junk.extend((0..len % 400).map(|_| rng.random::<u8>()));
        let _ = layout::read_clouds(&junk);
    }
}
