//! graspopt-quality's integration tests, one module per topic in one test binary (one link
//! instead of one per file). A new file here needs a `mod` line below.

mod bad_input;
mod forces;
mod forces_numerical;
mod known_values;
mod properties;
mod reference_cases;
mod support;
