//! The one place that asks the CPU which vector instructions it has.
//!
//! [`isa()`] returns the instruction-set level the lane kernels of the workspace may use:
//! detected once per process (cached in an atomic, so asking costs one relaxed load), then
//! capped by the environment variable `TEXMAP_ISA` when it is set:
//!
//! | `TEXMAP_ISA` | effect |
//! |---|---|
//! | `baseline` (or `sse2`, `scalar`) | only the baseline lanes ([`Isa::Baseline`]) |
//! | `avx2` | at most [`Isa::Avx2`] |
//! | `avx512` | at most [`Isa::Avx512`] (the same as unset) |
//!
//! The variable can only lower the level, never raise it above what the CPU has, so it is safe
//! to set on any machine; an unrecognised value is ignored. It is read once, at the first call
//! of [`isa()`]. Tests that compare two builds do not need it: they name the build they run
//! (the lane type, or the kernel function) and check [`Isa::detected`] before running it.

use std::sync::atomic::{AtomicU8, Ordering};

/// An instruction-set level of the lane kernels, ordered: a CPU that runs one level runs every
/// lower one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// The target's baseline, always available: SSE2 on x86-64 (part of the x86-64 ABI), plain
    /// arrays elsewhere.
    Baseline,
    /// AVX2 (x86-64 only).
    Avx2,
    /// AVX-512 F, VL, BW and DQ (x86-64 only; every CPU with these also has AVX2).
    Avx512,
}

impl Isa {
    /// What this CPU has, ignoring `TEXMAP_ISA` (detected once, then cached).
    #[inline]
    pub fn detected() -> Isa {
        match DETECTED.load(Ordering::Relaxed) {
            0 => init_detected(),
            v => decode(v),
        }
    }

    /// The level the kernels use: [`Isa::detected`] capped by `TEXMAP_ISA` (see the module
    /// documentation). The same as [`isa()`].
    #[inline]
    pub fn current() -> Isa {
        match CURRENT.load(Ordering::Relaxed) {
            0 => init_current(),
            v => decode(v),
        }
    }

    /// The level named `name` as `TEXMAP_ISA` spells it (case-insensitive, surrounding
    /// whitespace ignored), or `None`.
    pub fn parse(name: &str) -> Option<Isa> {
        match name.trim().to_ascii_lowercase().as_str() {
            "baseline" | "sse2" | "scalar" => Some(Isa::Baseline),
            "avx2" => Some(Isa::Avx2),
            "avx512" => Some(Isa::Avx512),
            _ => None,
        }
    }

    /// Whether code built for `self` may run where the kernels use [`isa()`].
    #[inline]
    pub fn enabled(self) -> bool {
        self <= isa()
    }
}

/// The level the lane kernels use ([`Isa::current`]).
#[inline]
pub fn isa() -> Isa {
    Isa::current()
}

/// `0` = not asked yet, else `1 + Isa as u8`.
static DETECTED: AtomicU8 = AtomicU8::new(0);
static CURRENT: AtomicU8 = AtomicU8::new(0);

// The first calls are out of line and cold, so that the callers (dispatch code inlined into
// large kernels) carry only the load and the compare. Two threads racing through them both
// store the same value.

#[cold]
#[inline(never)]
fn init_detected() -> Isa {
    let isa = probe();
    DETECTED.store(1 + isa as u8, Ordering::Relaxed);
    isa
}

#[cold]
#[inline(never)]
fn init_current() -> Isa {
    let hw = Isa::detected();
    let isa = match std::env::var("TEXMAP_ISA") {
        Ok(name) => Isa::parse(&name).map_or(hw, |cap| hw.min(cap)),
        Err(_) => hw,
    };
    CURRENT.store(1 + isa as u8, Ordering::Relaxed);
    isa
}

#[inline(always)]
fn decode(v: u8) -> Isa {
    match v {
        3 => Isa::Avx512,
        2 => Isa::Avx2,
        _ => Isa::Baseline,
    }
}

/// Ask the CPU.
#[cfg(target_arch = "x86_64")]
fn probe() -> Isa {
    use std::arch::is_x86_feature_detected as has;
    if has!("avx512f") && has!("avx512vl") && has!("avx512bw") && has!("avx512dq") && has!("avx2") {
        Isa::Avx512
    } else if has!("avx2") {
        Isa::Avx2
    } else {
        Isa::Baseline
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn probe() -> Isa {
    Isa::Baseline
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_parse_and_order() {
        assert_eq!(Isa::parse("sse2"), Some(Isa::Baseline));
        assert_eq!(Isa::parse(" Scalar "), Some(Isa::Baseline));
        assert_eq!(Isa::parse("baseline"), Some(Isa::Baseline));
        assert_eq!(Isa::parse("AVX2"), Some(Isa::Avx2));
        assert_eq!(Isa::parse("avx512"), Some(Isa::Avx512));
        assert_eq!(Isa::parse("avx3"), None);
        assert_eq!(Isa::parse(""), None);
        assert!(Isa::Baseline < Isa::Avx2 && Isa::Avx2 < Isa::Avx512);
        // A cap never raises the level.
        for hw in [Isa::Baseline, Isa::Avx2, Isa::Avx512] {
            for cap in [Isa::Baseline, Isa::Avx2, Isa::Avx512] {
                assert!(hw.min(cap) <= hw);
            }
        }
    }

    #[test]
    fn the_current_level_is_at_most_the_detected_one_and_stable() {
        let (d, c) = (Isa::detected(), isa());
        assert!(c <= d);
        assert!(Isa::Baseline.enabled());
        assert_eq!(Isa::detected(), d);
        assert_eq!(isa(), c);
        #[cfg(not(target_arch = "x86_64"))]
        assert_eq!(d, Isa::Baseline);
    }
}
