//! Messages and sizes for people, and echo's two formats.

use graspopt_bus::RawSample;
use graspopt_protocol::{Topic, decode_topic};
use serde_json::{Value, json};

use super::Format;

/// Bytes for people: `812 B`, `12.4 KB`, `3.10 MB`.
pub fn human_bytes(b: f64) -> String {
    if b < 1e3 {
        format!("{b:.0} B")
    } else if b < 1e6 {
        format!("{:.1} KB", b / 1e3)
    } else {
        format!("{:.2} MB", b / 1e6)
    }
}

/// Arrays longer than this print their first items and a count.
const LONG_ARRAY: usize = 8;

/// A decoded message as indented `field: value` lines; long arrays are shortened.
pub fn render_text(value: &Value, indent: usize, out: &mut String) {
    let pad = "  ".repeat(indent);
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                match v {
                    Value::Object(m) if !m.is_empty() => {
                        out.push_str(&format!("{pad}{k}:\n"));
                        render_text(v, indent + 1, out);
                    }
                    Value::Array(a) if a.iter().any(|x| x.is_object()) => {
                        out.push_str(&format!("{pad}{k}: ({} items)\n", a.len()));
                        for (i, x) in a.iter().enumerate().take(LONG_ARRAY) {
                            out.push_str(&format!("{pad}  - [{i}]\n"));
                            render_text(x, indent + 2, out);
                        }
                        if a.len() > LONG_ARRAY {
                            out.push_str(&format!("{pad}  ... {} more\n", a.len() - LONG_ARRAY));
                        }
                    }
                    _ => out.push_str(&format!("{pad}{k}: {}\n", scalar(v))),
                }
            }
        }
        other => out.push_str(&format!("{pad}{}\n", scalar(other))),
    }
}

fn scalar(v: &Value) -> String {
    match v {
        Value::Array(a) if a.len() > LONG_ARRAY => {
            let head: Vec<String> = a.iter().take(3).map(scalar).collect();
            format!("[{}, ... ({} items)]", head.join(", "), a.len())
        }
        Value::Array(a) => {
            let items: Vec<String> = a.iter().map(scalar).collect();
            format!("[{}]", items.join(", "))
        }
        Value::String(s) => s.clone(),
        Value::Null => "-".into(),
        Value::Object(_) => v.to_string(),
        other => other.to_string(),
    }
}

/// One echoed sample: a `---` header and the decoded fields (text), or one JSON object and a
/// newline (json).
pub fn echo_sample(sample: &RawSample, format: Format) -> String {
    let topic = Topic::classify(&sample.key).map(|(_, t)| t);
    let decoded = match topic {
        Some(t) => decode_topic(t, &sample.bytes, sample.encoding).map_err(|e| e.to_string()),
        None => Err("not a graspopt topic".to_string()),
    };
    let type_name = topic.map_or("?", Topic::message_type);
    match format {
        Format::Json => {
            let (field, value) = match decoded {
                Ok(m) => ("message", m),
                Err(e) => ("error", Value::String(e)),
            };
            let mut v = json!({"key": sample.key, "type": type_name, "bytes": sample.bytes.len()});
            v[field] = value;
            format!("{v}\n")
        }
        Format::Text => {
            let mut out = format!(
                "--- {}  {type_name}  {} {}\n",
                sample.key,
                sample.encoding.mime(),
                human_bytes(sample.bytes.len() as f64)
            );
            match decoded {
                Ok(m) => render_text(&m, 1, &mut out),
                Err(e) => out.push_str(&format!("  cannot decode: {e}\n")),
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use graspopt_protocol::Encoding;

    #[test]
    fn long_arrays_are_shortened_and_nesting_indented() {
        let v = json!({"trial_id": 3, "params": [0.1, 0.2],
            "fingers": [{"finger": 0, "points": (0..100).collect::<Vec<_>>()}], "error": null});
        let mut out = String::new();
        render_text(&v, 0, &mut out);
        assert!(out.contains("trial_id: 3\n"), "{out}");
        assert!(out.contains("params: [0.1, 0.2]\n"), "{out}");
        assert!(out.contains("fingers: (1 items)\n"), "{out}");
        assert!(
            out.contains("    points: [0, 1, 2, ... (100 items)]\n"),
            "{out}"
        );
        assert!(out.contains("error: -\n"), "{out}");
    }

    #[test]
    fn samples_that_do_not_decode_are_echoed_with_the_reason() {
        let sample = RawSample {
            key: "graspopt/r/result".into(),
            encoding: Encoding::Json,
            bytes: b"{}".to_vec(),
        };
        let v: Value = serde_json::from_str(&echo_sample(&sample, Format::Json)).unwrap();
        assert_eq!(v["type"], "TrialResult");
        assert_eq!(v["bytes"], 2);
        assert!(v["error"].as_str().unwrap().contains("TrialResult"), "{v}");
        let text = echo_sample(&sample, Format::Text);
        assert!(
            text.starts_with(
                "--- graspopt/r/result  TrialResult  application/json 2 B\n  cannot decode: "
            ),
            "{text}"
        );
        let other = RawSample {
            key: "elsewhere/x".into(),
            ..sample
        };
        assert!(echo_sample(&other, Format::Text).contains("  ?  "));
    }
}
