//! Timing of the parts of one proposal at 100 observations in 6D.
use std::time::Instant;

use graspopt_bayesopt::fit::{FitSettings, fit_map};
use graspopt_bayesopt::rng::Rng;
use graspopt_bayesopt::{Gp, KernelKind, TestFunction, acquisition, direct};

fn main() {
    let f = TestFunction::Hartmann6;
    let mut rng = Rng::new(5);
    let x: Vec<Vec<f64>> = (0..100).map(|_| rng.unit_point(6)).collect();
    let y0: Vec<f64> = x.iter().map(|p| -f.eval(p)).collect();
    let m = y0.iter().sum::<f64>() / 100.0;
    let sd = (y0.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / 100.0).sqrt();
    let y: Vec<f64> = y0.iter().map(|v| (v - m) / sd).collect();
    let st = FitSettings::default();
    let t = Instant::now();
    let Ok((h, _)) = fit_map(KernelKind::Matern32, &st, &x, &y, None, 2, &mut rng) else { return };
    println!("fit 3 starts: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let t = Instant::now();
    let _ = fit_map(KernelKind::Matern32, &st, &x, &y, Some(&h), 0, &mut rng);
    println!("fit warm: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let t = Instant::now();
    let Ok(gp) = Gp::new(x.clone(), y.clone(), h.kernel(KernelKind::Matern32), h.noise) else { return };
    println!("gp: {:.2} ms", t.elapsed().as_secs_f64() * 1e3);
    let best = y.iter().copied().fold(f64::MIN, f64::max);
    let t = Instant::now();
    let ds = direct::DirectSettings { max_evals: 3000, ..Default::default() };
    let Ok(r) = direct::maximize(
        |u| {
            let (mu, v) = gp.predict(u);
            acquisition::log_expected_improvement(mu, v, best, 0.0)
        },
        &[0.0; 6],
        &[1.0; 6],
        &ds,
        3,
    ) else { return };
    println!("direct 3000: {:.1} ms ({} evals)", t.elapsed().as_secs_f64() * 1e3, r.evals);
    let t = Instant::now();
    let mut n = 0;
    for _ in 0..3000 {
        let u = rng.unit_point(6);
        let (mu, v) = gp.predict(&u);
        if acquisition::log_expected_improvement(mu, v, best, 0.0) > -1e9 { n += 1; }
    }
    println!("3000 predicts: {:.1} ms {n}", t.elapsed().as_secs_f64() * 1e3);
    let t = Instant::now();
    let mut dm = [0.0; 6];
    let mut dv = [0.0; 6];
    for (s, _) in &r.top {
        let _ = direct::polish(
            |u, g| {
                let (mu, v) = gp.predict_with_grad(u, &mut dm, &mut dv);
                acquisition::log_ei_with_grad(mu, v, &dm, &dv, best, 0.0, g)
            },
            s,
            &[0.0; 6],
            &[1.0; 6],
            30,
        );
    }
    println!("polish 3: {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
}
