//! Sloshing as a naval architect measures it: linear theory for a rectangular tank ([`theory`]), reading
//! free-decay and forced records ([`signal`]), and those experiments run on the solver ([`experiment`]).

pub mod experiment;
pub mod signal;
pub mod theory;
