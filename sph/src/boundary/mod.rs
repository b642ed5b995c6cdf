//! Wall boundary conditions. Both methods fill a [`crate::particles::Boundary`] set that the interaction
//! loops treat alike; they differ in where the particles come from and how their density is found.

pub mod dynamic;
pub mod mdbc;
pub mod mirror;
