//! # texmap-terrain — terrain databases for Seed 000 (not yet built)
//!
//! This crate will turn gridded elevation models into error-bounded level-of-detail meshes, cut
//! geospecific textures made from aerial photographs into mip-pyramid map tiles, choose the
//! active-area map set of Seed 000 Eq. (5)–(7), export glTF/OBJ, and render flight views with the
//! span-parallel sampler of `texmap-core`. It is scheduled by a later issue; today it is an empty
//! library so that the workspace layout of ARCHITECTURE.md is in place.
