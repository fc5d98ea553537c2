//! Thesis claim 3 (section 4.4, figure 4.8) on the seven objects: where the best grasp of a
//! scan lies when torques are taken about the object's centre, the world origin, or the palm
//! at the reference pose (fixed for the scan), with the torque scale fixed at 0.05 m.
//!
//! `cargo run --release -p graspopt-trial --features tools --example frames -- [N1] [NX NY]`: for each object,
//! the 1D approach scan of `N1` points (default 61) and the 2D approach x vertical scan of
//! `NX x NY` points (default 15 x 15), default bounds, Barrett hand, default scoring. Prints
//! the argmax in each frame and, per frame, how many grid cells it lies from the object
//! frame's (the smallest Chebyshev distance between the two sets of tied maxima).

use graspopt_sim::hand::hand_by_name;
use graspopt_sim::{Object, TrialSpace, reference_pose};
use graspopt_trial::scan::{grid_axes, scan_grid};
use graspopt_trial::{Evaluator, ReferenceFrame};

/// The grid indices of the maximal cells of a scan in `frame`.
fn argmax(object: &str, space_2d: bool, steps: &[usize], frame: ReferenceFrame) -> Vec<Vec<usize>> {
    let object = Object::by_name(object).expect("a built-in object");
    let space = if space_2d {
        TrialSpace::approach_vertical_2d(&object)
    } else {
        TrialSpace::approach_1d(&object)
    };
    let mut ev = Evaluator::new(object, hand_by_name("barrett").expect("hand"), space);
    ev.score.frame = frame;
    ev.score.torque_scale = Some(0.05);
    let axes = grid_axes(&ev.space.bounds(), steps);
    let points = scan_grid(&ev, &axes, 0, &|_| {}).expect("the scan runs");
    let top = points
        .iter()
        .map(|p| p.score.score)
        .fold(f64::NEG_INFINITY, f64::max);
    points
        .iter()
        .filter(|p| p.score.score == top)
        .map(|p| {
            p.params
                .iter()
                .zip(&axes)
                .map(|(v, axis)| axis.iter().position(|a| a == v).expect("a grid value"))
                .collect()
        })
        .collect()
}

/// The smallest Chebyshev distance between two sets of cells.
fn cells_apart(a: &[Vec<usize>], b: &[Vec<usize>]) -> usize {
    a.iter()
        .flat_map(|x| {
            b.iter().map(move |y| {
                x.iter()
                    .zip(y)
                    .map(|(i, j)| i.abs_diff(*j))
                    .max()
                    .unwrap_or(0)
            })
        })
        .min()
        .unwrap_or(usize::MAX)
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse().expect("a number of points"))
        .collect();
    let n1 = args.first().copied().unwrap_or(61);
    let (nx, ny) = (
        args.get(1).copied().unwrap_or(15),
        args.get(2).copied().unwrap_or(15),
    );
    println!(
        "| object | 1D ({n1}): object-frame argmax | world: cells off | palm: cells off | 2D ({nx} x {ny}): object-frame argmax | world: cells off | palm: cells off |"
    );
    println!("|---|---|---|---|---|---|---|");
    for name in Object::names() {
        let object = Object::by_name(name).expect("a built-in object");
        let origin = reference_pose(&object).translation.vector;
        let palm = ReferenceFrame::Point([origin.x, origin.y, origin.z]);
        let mut row = format!("| {name} |");
        for (space_2d, steps) in [(false, vec![n1]), (true, vec![nx, ny])] {
            let reference = argmax(name, space_2d, &steps, ReferenceFrame::Object);
            row += &format!(" {:?} |", reference);
            for frame in [ReferenceFrame::World, palm] {
                let other = argmax(name, space_2d, &steps, frame);
                row += &format!(" {} |", cells_apart(&reference, &other));
            }
        }
        println!("{row}");
    }
}
