//! Simulated force/torque sensor noise (Nano17-like).

use nalgebra::Vector3;
use rand::RngExt;
use rand_distr::StandardNormal;
use serde::{Deserialize, Serialize};

use crate::contact::FingertipWrench;
use crate::error::{SensingError, check};

/// Force/torque sensor noise: each component gets a zero-mean Gaussian error whose
/// standard deviation is its resolution, then is rounded to the nearest multiple of the
/// resolution.
///
/// The default is an ATI Nano17's resolution (SI-25-0.25 calibration): 1/320 N for the
/// force and 1/64 N mm = 1.5625e-5 N m for the torque.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SensorNoise {
    /// The force resolution (N): the Gaussian's standard deviation and the quantum.
    pub force_resolution: f64,
    /// The torque resolution (N m): the Gaussian's standard deviation and the quantum.
    pub torque_resolution: f64,
}

impl Default for SensorNoise {
    fn default() -> Self {
        Self::NANO17
    }
}

impl SensorNoise {
    /// No noise: [`apply`](Self::apply) returns the reading unchanged and draws nothing.
    pub const NONE: SensorNoise = SensorNoise {
        force_resolution: 0.0,
        torque_resolution: 0.0,
    };

    /// An ATI Nano17's resolution: 1/320 N and 1/64 N mm.
    pub const NANO17: SensorNoise = SensorNoise {
        force_resolution: 1.0 / 320.0,
        torque_resolution: 1.0 / 64.0 * 1e-3,
    };

    /// Checks that both resolutions are finite and >= 0.
    pub fn validate(&self) -> Result<(), SensingError> {
        let non_negative = |v: f64| v >= 0.0;
        check(
            "force_resolution",
            self.force_resolution,
            ">= 0",
            non_negative,
        )?;
        check(
            "torque_resolution",
            self.torque_resolution,
            ">= 0",
            non_negative,
        )
    }

    /// The reading `r` as the sensor reports it. Each component x whose resolution q is
    /// positive takes one standard normal draw e from `rng` (in the order force x, y, z,
    /// then torque x, y, z) and becomes q * round((x + q e) / q). A component whose
    /// resolution is 0 (or not a finite positive number) is returned unchanged and draws
    /// nothing.
    pub fn apply<R: rand::Rng + ?Sized>(
        &self,
        r: &FingertipWrench,
        rng: &mut R,
    ) -> FingertipWrench {
        FingertipWrench {
            force: perturb(&r.force, self.force_resolution, rng),
            torque: perturb(&r.torque, self.torque_resolution, rng),
        }
    }
}

fn perturb<R: rand::Rng + ?Sized>(v: &Vector3<f64>, q: f64, rng: &mut R) -> Vector3<f64> {
    if !(q > 0.0 && q.is_finite()) {
        return *v;
    }
    v.map(|x| {
        let e: f64 = rng.sample(StandardNormal);
        ((x + q * e) / q).round() * q
    })
}
