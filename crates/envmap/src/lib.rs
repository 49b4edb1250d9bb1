//! # texmap-envmap — Seed 003 dynamic environment mapping (not yet built)
//!
//! This crate will hold static and dynamic sphere maps (the other objects re-rendered into the
//! target's sphere map every frame, `m = 2·sqrt(r_x² + r_y² + (r_z + 1)²)`), cube maps and
//! refraction mapping, drawn with `texmap-raster` and measured against `texmap-reftrace`'s mirror
//! and refraction rays. It is scheduled by a later issue; today it is an empty library so that the
//! workspace layout of ARCHITECTURE.md is in place.
