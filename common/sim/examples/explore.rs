use graspopt_sim::hand::{BarrettHand, ParallelJawGripper, Hand};
use graspopt_sim::pose::TrialSpace;
use graspopt_sim::{ContactModelSettings, Object, run_trial};

fn main() {
    let hands: Vec<Box<dyn Hand>> = vec![Box::new(BarrettHand::default()), Box::new(ParallelJawGripper::default())];
    for hand in &hands {
        for name in Object::names() {
            let o = Object::by_name(name).unwrap();
            let space = TrialSpace::approach_1d(&o);
            for a in [-0.1, -0.06, -0.03, 0.0, 0.02] {
                let pose = space.palm_pose(&[a]).unwrap();
                let t0 = std::time::Instant::now();
                let g = hand.close(&o, &pose).unwrap();
                let tc = t0.elapsed();
                let _ = g;
                let t0 = std::time::Instant::now();
                let out = run_trial(&o, hand.as_ref(), &pose, &ContactModelSettings::default()).unwrap();
                let dt = t0.elapsed();
                let counts: Vec<usize> = out.fingers.iter().map(|f| f.cloud.len()).collect();
                let surf: Vec<usize> = out.fingers.iter().map(|f| f.surface.len()).collect();
                println!(
                    "{} {name:15} a={a:+.2} retreat={:.4} joints={:?} clouds={counts:?} palm={} surf={surf:?} {:?} close {tc:?}",
                    hand.name(),
                    out.grasp.retreat,
                    out.grasp.joints.iter().map(|j| (j * 1000.0).round() / 1000.0).collect::<Vec<_>>(),
                    out.palm.cloud.len(),
                    dt
                );
            }
        }
    }
}
