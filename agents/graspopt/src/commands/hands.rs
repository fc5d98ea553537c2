//! `graspopt hands`: the built-in hands (name, fingers, joints, source file), or one hand's
//! joints, links, mimic joints and closing axis (`graspopt hands NAME|FILE.urdf`).

use anyhow::Result;
use clap::Args;
use graspopt_sim::{Hand, UrdfHand, builtin_hands};

#[derive(Args, Debug)]
pub struct HandsArgs {
    /// A hand to describe in detail: a built-in name or a URDF file.
    pub hand: Option<String>,
}

pub fn run(args: &HandsArgs) -> Result<std::process::ExitCode> {
    match &args.hand {
        None => crate::out::print(format_args!("{}", table()?))?,
        Some(name) => {
            // Its errors name the hand (the file, or the unknown name).
            let hand = UrdfHand::by_name(name)?;
            crate::out::print(format_args!("{}{}", describe(&hand), hand.summary()))?;
        }
    }
    Ok(std::process::ExitCode::SUCCESS)
}

/// One line per built-in hand.
fn table() -> Result<String> {
    let mut out = format!(
        "{:<14} {:>7} {:>6}  {:<28} source\n",
        "name", "fingers", "joints", "aliases"
    );
    for b in builtin_hands() {
        let hand = b.build()?;
        let source = match b.settings_source {
            Some(s) => format!("{} (+ {})", b.source, s),
            None => b.source.to_string(),
        };
        out.push_str(&format!(
            "{:<14} {:>7} {:>6}  {:<28} {source}\n",
            b.name,
            hand.finger_count(),
            hand.joint_names().len(),
            b.aliases.join(", "),
        ));
    }
    out.push_str(
        "any other hand: --hand FILE.urdf (settings in FILE.toml beside it; see docs/hands.md)\n",
    );
    Ok(out)
}

/// A hand's joints (limits, open value) and links (finger, shape).
fn describe(hand: &dyn Hand) -> String {
    let mut out = format!(
        "{}: {} fingers\njoints:\n",
        hand.name(),
        hand.finger_count()
    );
    let open = hand.open_configuration();
    for ((name, (lo, hi)), o) in hand.joint_names().iter().zip(hand.joint_limits()).zip(open) {
        out.push_str(&format!("  {name:<16} [{lo:.4}, {hi:.4}] open {o:.4}\n"));
    }
    out.push_str("links:\n");
    for l in hand.links() {
        let finger = l
            .finger
            .map_or("palm".to_string(), |f| format!("finger {}", f + 1));
        out.push_str(&format!(
            "  {:<16} {finger:<9} {}\n",
            l.name,
            l.shape.kind()
        ));
    }
    out
}
