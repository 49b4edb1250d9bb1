//! # texmap-study — the speed-versus-accuracy study of the sphere methods
//!
//! (being built)

pub mod elements;
pub mod md;
pub mod rng;
pub mod scenes;
