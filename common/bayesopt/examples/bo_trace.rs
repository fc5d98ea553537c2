//! Debug trace of one seed: proposals, values and fitted hyperparameters.
use graspopt_bayesopt::benchmark::recommended_settings;
use graspopt_bayesopt::{Optimizer, TestFunction};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let f = TestFunction::from_name(args.get(1).map_or("branin", |s| s)).unwrap_or(TestFunction::Branin);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0);
    let budget: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(30);
    let mut s = recommended_settings();
    s.minimize = true;
    s.n_init = Some(if f.dim() == 2 { 5 } else { 10 });
    let (lo, hi) = f.bounds();
    let b: Vec<(f64, f64)> = lo.into_iter().zip(hi).collect();
    let Ok(mut opt) = Optimizer::new(&b, s, seed) else { return };
    for i in 0..budget {
        let Ok(p) = opt.suggest(1) else { return };
        let y = f.eval(&p[0]);
        let _ = opt.observe(&p[0], y);
        let h = opt.hyperparameters();
        println!(
            "{i:3} y {y:10.5} regret {:.2e} ei {:?} x {:?} ls {:?} s {:?} noise {:?}",
            f.regret(opt.best().map_or(y, |b| b.1)),
            opt.last_round().best_ei,
            p[0].iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>(),
            h.map(|h| h.length_scales.iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>()),
            h.map(|h| h.signal_variance),
            h.map(|h| h.noise)
        );
    }
}
