//! Fast paths with no physics in them: the layouts and loops that make the schemes' pair sums quick (SIMD
//! lanes of neighbour candidates, kernel gradients in half precision, pair sums in independent chains). Each
//! is checked in its tests against the naive loop it replaces.

pub mod candidates;
pub mod half;
pub mod near;
pub mod pair_sums;
