//! End-to-end and validation tests live in `tests/tests/`.

pub mod fuzz;
pub mod tree;
