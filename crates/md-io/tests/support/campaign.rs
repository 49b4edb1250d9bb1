//! A deterministic, bounded fuzz campaign over a reader's fixtures: the mutants that damaged
//! real files show in practice, each run under `catch_unwind`, a heap cap and a clock, tallied
//! per outcome.
//!
//! For every fixture the campaign builds
//! - a truncation at every record boundary the fixture lists (line ends, Fortran records, frame
//!   headers) and at `seeded_cuts` seeded offsets,
//! - `flips` seeded single-bit flips and `flips / 4` seeded byte replacements (by 0x00, 0xFF,
//!   '\n', ' ', '9', 'e'),
//! - every listed header field set to each extreme of its type (0, ±1, 2^29, i32::MAX, 2^31,
//!   u32::MAX; 0, -1, NaN, ±inf, 1e-30, 1e38, f32::MAX; in text "-1", "0", "2147483648",
//!   "1e400", "nan", "inf", "1e38", a 30-digit count),
//! - the whole file with CRLF line ends and with a NUL byte in the middle (text fixtures).
//!
//! A reader joins with a closure `run(&Fixture, &[u8]) -> Verdict` and a list of [`Fixture`]s;
//! [`run_campaign`] returns a [`Tally`] whose `failures` must be empty: a panic, an error that
//! names no place, a broken invariant reported by `run`, a cut read back as a clean shorter file
//! where the format would have told, a heap peak over `mem_factor` × the mutant's size +
//! `mem_extra`, a run slower than `slow` (a hang guard, not a speed figure).
//!
//! Std only and free of any reader's types, so the tests of another crate (the terrain readers:
//! GeoTIFF, ASC, HGT, PNG) include it with `#[path = "../../md-io/tests/support/campaign.rs"]`
//! together with `alloc.rs` (whose `CountingAlloc` the including test binary must install).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;
use std::time::{Duration, Instant};

use super::alloc::measure;

/// SplitMix64 (Steele, Lea, Flood 2014): a seeded, portable stream of 64-bit values.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (n > 0; the modulo bias is irrelevant here).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// A header field the campaign sets to the extremes of its type.
#[derive(Clone, Copy, Debug)]
pub enum Field {
    I32Be(usize),
    I32Le(usize),
    F32Be(usize),
    F32Le(usize),
    F64Le(usize),
    /// Two copies of one count (e.g. XTC's atom count), set together so that a check of one
    /// against the other does not hide what the count alone does.
    I32BeTwice(usize, usize),
    /// A number written as text in bytes `start..end`.
    Text(usize, usize),
}

const INTS: [u32; 8] = [
    0,
    1,
    u32::MAX, // -1
    1 << 29,
    i32::MAX as u32,
    1 << 31, // i32::MIN
    u32::MAX - 1,
    1_000_000_000,
];
const FLOATS: [f64; 9] = [
    0.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e-30,
    1e38,
    f32::MAX as f64,
    1e300,
];
const TEXTS: [&str; 9] = [
    "-1",
    "0",
    "2147483648",
    "1e400",
    "nan",
    "inf",
    "1e38",
    "999999999999999999999999999999",
    "-0",
];

impl Field {
    fn extremes(self) -> usize {
        match self {
            Field::I32Be(_) | Field::I32Le(_) | Field::I32BeTwice(..) => INTS.len(),
            Field::F32Be(_) | Field::F32Le(_) => FLOATS.len() - 1,
            Field::F64Le(_) => FLOATS.len(),
            Field::Text(..) => TEXTS.len(),
        }
    }

    /// The fixture with this field set to extreme `k`.
    fn set(self, bytes: &[u8], k: usize) -> Vec<u8> {
        let mut b = bytes.to_vec();
        let mut put = |at: usize, v: &[u8]| {
            if at + v.len() <= b.len() {
                b[at..at + v.len()].copy_from_slice(v);
            }
        };
        match self {
            Field::I32Be(at) => put(at, &INTS[k].to_be_bytes()),
            Field::I32Le(at) => put(at, &INTS[k].to_le_bytes()),
            Field::I32BeTwice(a, z) => {
                put(a, &INTS[k].to_be_bytes());
                put(z, &INTS[k].to_be_bytes());
            }
            Field::F32Be(at) => put(at, &(FLOATS[k] as f32).to_be_bytes()),
            Field::F32Le(at) => put(at, &(FLOATS[k] as f32).to_le_bytes()),
            Field::F64Le(at) => put(at, &FLOATS[k].to_le_bytes()),
            Field::Text(s, e) => {
                return [&bytes[..s], TEXTS[k].as_bytes(), &bytes[e..]].concat();
            }
        }
        b
    }
}

/// What a cut short of the end must give.
#[derive(Clone, Debug)]
pub enum Cuts {
    /// The header declares the frame count: any cut short of the end is an error.
    Declared,
    /// A cut at one of these frame ends (0 included: an empty file) reads as exactly the frames
    /// before it; a cut anywhere else is an error.
    FrameEnds(Vec<usize>),
    /// Nothing tells (text: a cut after a complete number parses); only "no more frames than
    /// the whole file" is checked.
    Unchecked,
}

/// One file of a reader's campaign.
pub struct Fixture {
    pub name: String,
    pub bytes: Vec<u8>,
    /// Frames in the whole file.
    pub frames: usize,
    /// Byte offsets of record boundaries to cut at.
    pub boundaries: Vec<usize>,
    pub cuts: Cuts,
    /// Header fields to set to extremes, with a name for the tally.
    pub fields: Vec<(&'static str, Field)>,
    /// A text file: also try CRLF line ends and a NUL byte.
    pub text: bool,
}

/// What `run` found for one mutant.
#[derive(Debug)]
pub enum Verdict {
    /// Read to the end: the frames read.
    Ok { frames: usize },
    /// An error that names the place; the label (e.g. "Truncated") is tallied.
    Located(&'static str),
    /// The reader broke its contract (an unlocated error, an invalid frame, counts that
    /// disagree): a failure of the campaign.
    Broken(String),
}

/// The campaign's parameters.
#[derive(Clone, Debug)]
pub struct Settings {
    pub seed: u64,
    pub seeded_cuts: usize,
    pub flips: usize,
    pub mem_factor: usize,
    pub mem_extra: usize,
    pub slow: Duration,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            seed: 0x7e_47a9,
            seeded_cuts: 64,
            flips: 2048,
            mem_factor: 64,
            mem_extra: 1 << 20,
            slow: Duration::from_secs(2),
        }
    }
}

/// The campaign's record for one reader.
#[derive(Debug, Default)]
pub struct Tally {
    pub reader: String,
    pub mutants: usize,
    /// Mutants per family (cut, flip, field, ...).
    pub families: BTreeMap<&'static str, usize>,
    /// Mutants per outcome ("ok", "error: Truncated", ...).
    pub outcomes: BTreeMap<String, usize>,
    pub failures: Vec<String>,
    /// Largest heap peak over its cap, as a fraction of the cap.
    pub worst_peak: f64,
    pub slowest: Duration,
    pub elapsed: Duration,
}

impl Tally {
    /// The table the test prints.
    pub fn report(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{}: {} mutants in {:.2} s (slowest {:.1} ms, heap peak at most {:.1}% of its cap)",
            self.reader,
            self.mutants,
            self.elapsed.as_secs_f64(),
            self.slowest.as_secs_f64() * 1e3,
            self.worst_peak * 100.0
        );
        let fam: Vec<String> = self
            .families
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        let _ = writeln!(s, "  mutants: {}", fam.join(", "));
        let out: Vec<String> = self
            .outcomes
            .iter()
            .map(|(k, v)| format!("{k} {v}"))
            .collect();
        let _ = writeln!(s, "  outcomes: {}", out.join(", "));
        let _ = writeln!(s, "  failures: {}", self.failures.len());
        for f in self.failures.iter().take(10) {
            let _ = writeln!(s, "    {f}");
        }
        s
    }
}

thread_local! {
    static PANIC: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Keeps panic messages of campaign threads instead of printing them (installed once).
fn quiet_panics() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let caught = PANIC.with(|p| {
                let mut p = p.borrow_mut();
                if p.is_some() {
                    *p = Some(format!("{info}"));
                    true
                } else {
                    false
                }
            });
            if !caught {
                default(info);
            }
        }));
    });
}

/// The mutants of one fixture: (family, label, bytes).
fn mutants(fx: &Fixture, s: &Settings) -> Vec<(&'static str, String, Vec<u8>)> {
    let b = &fx.bytes;
    let n = b.len();
    let mut rng = Rng::new(
        s.seed
            ^ fx.name
                .bytes()
                .fold(0u64, |h, c| h.wrapping_mul(31) ^ c as u64),
    );
    let mut out = Vec::new();
    let mut cuts: Vec<usize> = fx.boundaries.iter().copied().filter(|&c| c < n).collect();
    cuts.sort_unstable();
    cuts.dedup();
    for c in cuts {
        out.push((
            "cut at a record boundary",
            format!("cut at {c}"),
            b[..c].to_vec(),
        ));
    }
    for _ in 0..s.seeded_cuts {
        let c = rng.below(n);
        out.push((
            "cut at a seeded offset",
            format!("cut at {c}"),
            b[..c].to_vec(),
        ));
    }
    for _ in 0..s.flips {
        let at = rng.below(n);
        let bit = 1u8 << rng.below(8);
        let mut m = b.clone();
        m[at] ^= bit;
        out.push(("bit flip", format!("byte {at} ^= {bit:#04x}"), m));
    }
    for _ in 0..s.flips / 4 {
        let at = rng.below(n);
        let v = [0x00, 0xFF, b'\n', b' ', b'9', b'e'][rng.below(6)];
        let mut m = b.clone();
        m[at] = v;
        out.push(("byte replaced", format!("byte {at} = {v:#04x}"), m));
    }
    for &(name, field) in &fx.fields {
        for k in 0..field.extremes() {
            out.push((
                "header field extreme",
                format!("{name} extreme #{k}"),
                field.set(b, k),
            ));
        }
    }
    if fx.text {
        let crlf: Vec<u8> = b
            .iter()
            .flat_map(|&c| {
                if c == b'\n' {
                    vec![b'\r', b'\n']
                } else {
                    vec![c]
                }
            })
            .collect();
        out.push(("text CRLF / NUL", "CRLF line ends".into(), crlf));
        let mut nul = b.clone();
        nul[n / 2] = 0;
        out.push(("text CRLF / NUL", format!("NUL at {}", n / 2), nul));
    }
    out
}

/// A text file's record boundaries: 0 and every line start.
pub fn line_starts(bytes: &[u8]) -> Vec<usize> {
    let mut starts = vec![0];
    starts.extend(
        bytes
            .iter()
            .enumerate()
            .filter(|(_, b)| **b == b'\n')
            .map(|(i, _)| i + 1),
    );
    starts
}

/// Runs the campaign of one reader over its fixtures.
pub fn run_campaign(
    reader: &str,
    fixtures: &[Fixture],
    s: &Settings,
    run: &dyn Fn(&Fixture, &[u8]) -> Verdict,
) -> Tally {
    quiet_panics();
    // A heap blow-up past the allocator's hard cap aborts the process (std prints "memory
    // allocation of N bytes failed"); CAMPAIGN_TRACE=1 names each mutant first, to find it.
    let trace = std::env::var_os("CAMPAIGN_TRACE").is_some();
    let start = Instant::now();
    let mut t = Tally {
        reader: reader.into(),
        ..Tally::default()
    };
    for fx in fixtures {
        for (family, label, bytes) in mutants(fx, s) {
            t.mutants += 1;
            *t.families.entry(family).or_default() += 1;
            if trace {
                eprintln!("campaign: {reader}: {} {label}", fx.name);
            }
            let cap = s.mem_factor * bytes.len() + s.mem_extra;
            PANIC.with(|p| *p.borrow_mut() = Some(String::new()));
            let t0 = Instant::now();
            let (r, peak) = measure(|| catch_unwind(AssertUnwindSafe(|| run(fx, &bytes))));
            let took = t0.elapsed();
            let panic = PANIC.with(|p| p.borrow_mut().take());
            let what = format!("{} {label}", fx.name);
            t.slowest = t.slowest.max(took);
            t.worst_peak = t.worst_peak.max(peak as f64 / cap as f64);
            if peak > cap {
                t.failures
                    .push(format!("{what}: heap peak {peak} bytes over the cap {cap}"));
            }
            if took > s.slow {
                t.failures.push(format!("{what}: took {took:?}"));
            }
            let verdict = match r {
                Ok(v) => v,
                Err(_) => {
                    t.failures
                        .push(format!("{what}: panic: {}", panic.unwrap_or_default()));
                    *t.outcomes.entry("PANIC".into()).or_default() += 1;
                    continue;
                }
            };
            let outcome = match &verdict {
                Verdict::Ok { .. } => "ok".to_string(),
                Verdict::Located(kind) => format!("error: {kind}"),
                Verdict::Broken(_) => "BROKEN".to_string(),
            };
            *t.outcomes.entry(outcome).or_default() += 1;
            if let Verdict::Broken(why) = &verdict {
                t.failures.push(format!("{what}: {why}"));
            }
            // A cut must not read back as a clean, shorter file where the format would tell.
            if family.starts_with("cut")
                && let Verdict::Ok { frames } = verdict
            {
                let cut = bytes.len();
                let silent = match &fx.cuts {
                    Cuts::Declared => true,
                    Cuts::FrameEnds(ends) => {
                        let before = ends.iter().filter(|&&e| e > 0 && e <= cut).count();
                        !ends.contains(&cut) || frames != before
                    }
                    Cuts::Unchecked => frames > fx.frames,
                };
                if silent {
                    t.failures
                        .push(format!("{what}: read as a clean file of {frames} frames"));
                }
            }
        }
    }
    t.elapsed = start.elapsed();
    t
}
