//! Standard normal samples for the simulated noise (perception's pose error, the contacts'
//! noise of thesis 4.7): one Box-Muller draw from a ChaCha8 stream.
//!
//! Written here rather than taken from `rand_distr` (whose ziggurat sampler would serve):
//! recorded runs and the experiments' figures depend on these exact streams, and one copy
//! serves every crate.

use rand::RngExt;
use rand_chacha::ChaCha8Rng;

/// One standard normal sample (Box-Muller, cosine branch; two uniform draws).
pub fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}
