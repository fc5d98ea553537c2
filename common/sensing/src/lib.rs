//! Intrinsic contact sensing: the contact point, normal, force and torsion on a fingertip
//! from the wrench its force/torque sensor measures (A. Bicchi, J. K. Salisbury and D. L.
//! Brock, "Contact sensing from force measurements", The International Journal of
//! Robotics Research 12(3), 1993). No bus, no files: [`locate`] turns one reading into a
//! [`SensedContact`] or a [`NoContact`] that says why there is none; [`wrench_of`] is the
//! forward model; [`SensorNoise`] simulates a Nano17's resolution.
//!
//! # Conventions
//!
//! - Everything is in the **sensor frame**, in metres, newtons and newton metres. The
//!   fingertip's [`FingertipSurface`] is given in that frame; moving the contact into the
//!   world with the sensor's pose is the caller's business.
//! - A [`FingertipWrench`] is the wrench **the object applies to the fingertip**: force F, and
//!   torque τ about the sensor frame's origin. (A driver whose sensor reports the
//!   opposite wrench negates both.)
//! - A contact at surface point p has the fingertip's **outward** normal n(p), which
//!   points into the object. The fingertip applies the force f = -F to the object and the
//!   moment t about n (soft finger; 0 for a point contact). The forward model is
//!   therefore F = -f, τ = p × F - t n.
//! - The contact **pushes** when f · n > 0 (F · n < 0). A solution where it would pull is
//!   never returned.
//! - `base_z` (optional, per surface): the fingertip is mounted below this height, and
//!   surface points with z < base_z cannot be touched. A real fingertip shell ends where
//!   it meets its sensor or phalanx; a plane z = base_z in the sensor frame, whose z axis
//!   runs out along the finger, models that for the usual mountings.
//!
//! # Method
//!
//! **Point contact** (`ContactKind::Point`). τ = p × F, so τ · F = 0 and p lies on the
//! force's line of action p0 + λ F with p0 = F × τ / |F|². The measured torque's part
//! along F divided by |F|, a wrench pitch τ · F / |F|² (m), is what a point contact cannot
//! explain: up to `pitch_tolerance` it is taken as noise and removed, beyond it the
//! reading is refused ([`NoContact::Torsion`]). A line meets a convex surface at most
//! twice: where it enters (moving along F) F · n < 0, so the contact pushes; where it
//! leaves, it would pull. The contact is the entry point. When the line misses the
//! surface (noise on a grazing contact) by at most `surface_tolerance`, the contact is
//! the surface point nearest the line; farther, [`NoContact::MissesSurface`].
//!
//! **Soft finger** (`ContactKind::SoftFinger`). τ = p × F - t n(p): three equations, three
//! unknowns (two for p on the surface, and t). Bicchi et al. use that the gradient of a
//! quadric is linear in p: writing t n = k ∇ turns the equations into a linear system in
//! p for each value of one scalar k, and the surface equation into one scalar equation in
//! k. For the shapes here that equation is solved in closed form (derived for this crate),
//! so no iteration limits the accuracy.
//!
//! - **Ellipsoid and sphere** (a sphere is an ellipsoid with equal semi-axes). With
//!   u = p - c, D = diag(semi-axes), A = D⁻², τc = τ - c × F, the surface is uᵀ A u = 1,
//!   ∇ ∝ A u and t n = k A u (t = k |A u|): u × F - k A u = τc. In the coordinates
//!   v = D⁻¹ u the ellipsoid is the unit sphere and the equation becomes
//!   v × G - k v = b with G = det(D) D⁻¹ F and b = D τc. Split v = α Ĝ + w (w ⟂ G), let
//!   g = |G|, β = b · Ĝ and b⊥ the rest of b: then k α = -β, |w|² (g² + k²) = |b⊥|² and
//!   α² + |w|² = 1, so x = k² solves x² + (g² - |b|²) x - β² g² = 0. Its two roots have
//!   the product -β² g² ≤ 0: exactly one is ≥ 0. Pushing means G · v < 0, i.e. α < 0,
//!   which fixes the sign of k (that of β); then w = -(g b⊥ × Ĝ + k b⊥) / (g² + k²),
//!   α = -√(1 - |w|²). So **every** reading has exactly one pushing soft-finger solution
//!   on an ellipsoid; `torsion_ratio_limit` is what refuses the implausible ones. The
//!   point contact is the case β = 0, k = 0 (miss when |w| > 1 there).
//! - **Capsule**: three pieces. The cylinder x² + y² = r² (about the centre) has a
//!   horizontal normal n, so the torque about the axis, τc,z = r (n × F)_z, fixes n's
//!   angle: sin φ = τc,z / (r |Fxy|) with φ the angle from n to F's horizontal part, and
//!   pushing (cos φ < 0) picks one of its two solutions. Then the F component of the
//!   equation gives t = -τc · F / (n · F) (0 for a point contact) and the z × F component
//!   gives the height. The two caps are spheres solved as above, each kept only on its
//!   hemisphere. A solution beyond its piece by at most `surface_tolerance` (noise near a
//!   seam) is snapped onto the surface. Random readings in the tests never gave two
//!   distinct pushing points; if they ever did, the reading is refused
//!   ([`NoContact::Ambiguous`]).
//!
//! The nearest surface point to a line (point contact, grazing): the sphere in closed
//! form; the capsule from the closest pair of the line and the axis segment; the
//! ellipsoid by a golden-section search along the line of the (convex) distance to the
//! ellipsoid, each distance by Newton's method on the ellipsoid's distance equation.
//!
//! Noise-free round trips recover the point to about 1e-17 m, the normal to about 2e-15
//! rad and the torsion to about 3e-17 N m (the tests assert 1e-9 m, 1e-9 rad, 1e-12 N m).
//! With [`SensorNoise::default`] (Nano17) on a 12 mm sphere and forces of 1 to 5 N, the
//! median errors are about 0.02 mm and 0.2 degrees.
//!
//! # Refusals
//!
//! [`locate`] never returns a point it cannot justify. [`NoContact`] says why:
//! [`BelowThreshold`](NoContact::BelowThreshold) (|F| < `force_threshold`, or zero),
//! [`Torsion`](NoContact::Torsion) (point contact, pitch beyond `pitch_tolerance`),
//! [`TorsionBeyondLimit`](NoContact::TorsionBeyondLimit) (soft finger, |t| more than
//! `torsion_ratio_limit` times the normal force),
//! [`MissesSurface`](NoContact::MissesSurface) (no surface point explains the reading),
//! [`Pulling`](NoContact::Pulling) (the pushing point is on the mount and the only usable
//! one pulls), [`OnMount`](NoContact::OnMount) (the only solution is on the mount),
//! [`Ambiguous`](NoContact::Ambiguous) (two distinct points) and
//! [`Invalid`](NoContact::Invalid) (a non-finite reading, an invalid surface or invalid
//! settings).
#![cfg_attr(not(test), warn(clippy::unwrap_used, clippy::expect_used))]

mod contact;
mod error;
mod noise;
mod surface;

pub use contact::{
    ContactKind, FingertipWrench, MAX_WRENCH, MIN_FORCE, NoContact, SensedContact, SensingSettings,
    locate, wrench_of,
};
pub use error::SensingError;
pub use noise::SensorNoise;
pub use surface::{FingertipSurface, MAX_SIZE, MIN_SIZE};
