//! Trajectory read throughput per format, one core: a 100,000-atom x 100-frame trajectory
//! (water-like triples in a 100 Å box, drifting per frame) written once per run into a temp dir
//! with our writers (XYZ, DCD, XTC via molly's compressor) and small TRR and AMBER mdcrd
//! (`10F8.3` with box lines, read with the atom count a topology would give) generators here,
//! then read frame by frame through `Trajectory::read_next` into one reused `Frame`.
//!
//! Groups: `md_io_read` reports bytes/s (criterion `Throughput::Bytes` = file size);
//! `md_io_xtc_atoms` reports atoms/s for XTC, our decoder beside molly 0.7 alone (its
//! `read_frame_with_scratch` into one reused frame and buffer), the baseline of the XTC target.
//!
//! Test mode (`cargo test --bench md_io`) uses 2,000 atoms x 3 frames so it stays quick.
//!
//! `CARGO_TARGET_DIR=/work/target-mdbin cargo bench --bench md_io -- --warm-up-time 1 --measurement-time 3`

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use criterion::{BatchSize, Criterion, Throughput, criterion_group};
use std::sync::atomic::{AtomicUsize, Ordering};
use texmap::md_io::{Format, Frame, Label, ReadOptions, Trajectory, UnitCell, Writer};

/// The run's atom count, for [`read_all`]'s options.
static N_ATOMS: AtomicUsize = AtomicUsize::new(0);

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// Frame `k` of the synthetic trajectory: triples of atoms within 1 Å (like water), 100 Å box.
fn synthetic(n_atoms: usize, k: usize, base: &[[f32; 3]], out: &mut Frame) {
    out.clear();
    let mut rng = Lcg(0x1234_5678 + k as u64);
    let drift = 0.05 * k as f32;
    out.positions.extend(base.iter().take(n_atoms).map(|p| {
        [
            p[0] + drift + 0.02 * rng.next(),
            p[1] - drift + 0.02 * rng.next(),
            p[2] + 0.02 * rng.next(),
        ]
    }));
    out.names
        .extend((0..n_atoms).map(|i| Label::new(if i % 3 == 0 { "O" } else { "H" }).unwrap()));
    out.cell = Some(UnitCell::orthorhombic(100.0, 100.0, 100.0).unwrap());
    out.step = Some(100 * k as i64);
    out.time = Some(0.2 * k as f64);
}

fn base_positions(n_atoms: usize) -> Vec<[f32; 3]> {
    let mut rng = Lcg(42);
    let mut out = Vec::with_capacity(n_atoms);
    while out.len() < n_atoms {
        let c = [rng.next() * 100.0, rng.next() * 100.0, rng.next() * 100.0];
        out.push(c);
        for _ in 0..2 {
            out.push([
                c[0] + rng.next() - 0.5,
                c[1] + rng.next() - 0.5,
                c[2] + rng.next() - 0.5,
            ]);
        }
    }
    out.truncate(n_atoms);
    out
}

/// A single-precision TRR with box and positions, written byte by byte (XDR, big-endian).
fn write_trr(path: &Path, n_atoms: usize, n_frames: usize, base: &[[f32; 3]]) {
    let mut w = BufWriter::new(File::create(path).unwrap());
    let mut frame = Frame::new();
    let i32be = |w: &mut BufWriter<File>, v: i32| w.write_all(&v.to_be_bytes()).unwrap();
    for k in 0..n_frames {
        synthetic(n_atoms, k, base, &mut frame);
        i32be(&mut w, 1993);
        i32be(&mut w, 13);
        i32be(&mut w, 12);
        w.write_all(b"GMX_trn_file").unwrap();
        let x_size = (n_atoms * 12) as i32;
        for s in [0, 0, 36, 0, 0, 0, 0, x_size, 0, 0] {
            i32be(&mut w, s);
        }
        i32be(&mut w, n_atoms as i32);
        i32be(&mut w, 100 * k as i32);
        i32be(&mut w, 0);
        for v in [0.2 * k as f32, 0.0] {
            w.write_all(&v.to_be_bytes()).unwrap();
        }
        for v in [10.0f32, 0.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 10.0] {
            w.write_all(&v.to_be_bytes()).unwrap();
        }
        for p in &frame.positions {
            for v in p {
                w.write_all(&(v / 10.0).to_be_bytes()).unwrap();
            }
        }
    }
    w.flush().unwrap();
}

/// An AMBER ASCII trajectory: a title, then per frame `10F8.3` positions and a box line.
fn write_mdcrd(path: &Path, n_atoms: usize, n_frames: usize, base: &[[f32; 3]]) {
    let mut w = BufWriter::new(File::create(path).unwrap());
    let mut frame = Frame::new();
    writeln!(w, "bench").unwrap();
    for k in 0..n_frames {
        synthetic(n_atoms, k, base, &mut frame);
        for (i, v) in frame.positions.iter().flatten().enumerate() {
            write!(w, "{v:8.3}").unwrap();
            if i % 10 == 9 {
                writeln!(w).unwrap();
            }
        }
        if !(3 * n_atoms).is_multiple_of(10) {
            writeln!(w).unwrap();
        }
        writeln!(w, "{:8.3}{:8.3}{:8.3}", 100.0, 100.0, 100.0).unwrap();
    }
    w.flush().unwrap();
}

/// Writes the trajectory in every format; returns (format, path, bytes).
fn write_all(dir: &Path, n_atoms: usize, n_frames: usize) -> Vec<(Format, PathBuf, u64)> {
    let base = base_positions(n_atoms);
    let mut frame = Frame::new();
    let mut out = Vec::new();
    for format in [Format::Xyz, Format::Dcd, Format::Xtc] {
        let path = dir.join(format!("bench.{}", format.name()));
        let mut w = Writer::create(&path, format).unwrap();
        for k in 0..n_frames {
            synthetic(n_atoms, k, &base, &mut frame);
            w.write_frame(&frame).unwrap();
        }
        w.finish().unwrap();
        out.push((format, path, 0));
    }
    let trr = dir.join("bench.trr");
    write_trr(&trr, n_atoms, n_frames, &base);
    out.push((Format::Trr, trr, 0));
    let mdcrd = dir.join("bench.mdcrd");
    write_mdcrd(&mdcrd, n_atoms, n_frames, &base);
    out.push((Format::AmberTrj, mdcrd, 0));
    for e in &mut out {
        e.2 = std::fs::metadata(&e.1).unwrap().len();
    }
    out
}

/// Reads every frame; returns a checksum so nothing is optimised away.
fn read_all(path: &Path, frame: &mut Frame) -> f64 {
    // The atom count an AMBER ASCII trajectory's topology gives (other formats ignore it).
    let opts = ReadOptions::new().atoms(N_ATOMS.load(Ordering::Relaxed));
    let mut t = Trajectory::open_with(path, opts).unwrap();
    let mut sum = 0.0;
    while t.read_next(frame).unwrap() {
        sum += f64::from(frame.positions[frame.n_atoms() / 2][0]);
    }
    sum
}

fn bench(c: &mut Criterion) {
    let full = std::env::args().any(|a| a == "--bench");
    let (n_atoms, n_frames) = if full { (100_000, 100) } else { (2_000, 3) };
    N_ATOMS.store(n_atoms, Ordering::Relaxed);
    let dir = tempfile::tempdir().unwrap();
    let files = write_all(dir.path(), n_atoms, n_frames);

    // Read throughput per format, in bytes of file per second.
    let mut g = c.benchmark_group("md_io_read");
    g.sample_size(10);
    let mut frame = Frame::new();
    for (format, path, bytes) in &files {
        g.throughput(Throughput::Bytes(*bytes));
        g.bench_function(format!("{}_{}x{}", format.name(), n_atoms, n_frames), |b| {
            b.iter(|| read_all(path, &mut frame))
        });
    }
    g.finish();

    // XTC in atoms per second: our decoder beside molly alone.
    let xtc = &files.iter().find(|f| f.0 == Format::Xtc).unwrap().1;
    let mut g = c.benchmark_group("md_io_xtc_atoms");
    g.sample_size(10);
    g.throughput(Throughput::Elements((n_atoms * n_frames) as u64));
    g.bench_function("texmap_md_io", |b| b.iter(|| read_all(xtc, &mut frame)));
    g.bench_function("molly_0.7", |b| {
        b.iter_batched(
            || texmap::md_io::molly::XTCReader::open(xtc).unwrap(),
            |mut r| {
                // molly's fastest path: one frame and one scratch buffer reused.
                let mut f = texmap::md_io::molly::Frame::default();
                let mut scratch = Vec::new();
                let all = texmap::md_io::molly::selection::AtomSelection::All;
                let mut sum = 0.0;
                while r
                    .read_frame_with_scratch(&mut f, &mut scratch, &all)
                    .is_ok()
                {
                    sum += f64::from(f.positions[3 * (n_atoms / 2)]);
                }
                sum
            },
            BatchSize::PerIteration,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
