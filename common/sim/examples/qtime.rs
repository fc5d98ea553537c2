use graspopt_sim::hand::{BarrettHand, Hand, LinkGeometry};
use graspopt_sim::pose::TrialSpace;
use graspopt_sim::Object;
use nalgebra::Isometry3;

fn main() {
    let hand = BarrettHand::default();
    let geo = LinkGeometry::new(hand.links());
    for name in ["wine_glass", "mug", "cylinder", "star_prism"] {
        let o = Object::by_name(name).unwrap();
        let space = TrialSpace::approach_1d(&o);
        let palm = space.palm_pose(&[0.0]).unwrap();
        let rel = hand.link_poses(&[0.0, 0.3, 0.1, 0.3, 0.1, 0.3, 0.1]).unwrap();
        for i in 0..7 {
            let p: Isometry3<f64> = palm * rel[i];
            let pose = parry_pose(&p);
            let t0 = std::time::Instant::now();
            let mut d = 0.0;
            for _ in 0..100 {
                d = geo.distance(&o, i, &pose, 0.0).unwrap();
            }
            println!("{name} link {i} d={d:.4} {:?}/query", t0.elapsed() / 100);
        }
    }
}
fn parry_pose(i: &Isometry3<f64>) -> parry3d_f64::math::Pose {
    let q = i.rotation.quaternion();
    let t = i.translation.vector;
    parry3d_f64::math::Pose::from_parts(parry3d_f64::math::Vector::new(t.x, t.y, t.z), parry3d_f64::math::Rotation::from_xyzw(q.i, q.j, q.k, q.w))
}
