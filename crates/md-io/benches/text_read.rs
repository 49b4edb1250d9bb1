//! Reading speed of the text formats from memory (no disk): MB/s of file text parsed into a
//! reused Frame. XYZ target: >= 500 MB/s on one core (chemfiles: 92 MB/s on this machine kind).
//!
//! `cargo bench -p texmap-md-io --bench text_read -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::fmt::Write;
use std::hint::black_box;
use std::io::Cursor;
use texmap_md_io::{Format, Frame, Trajectory};

const ATOMS: usize = 100_000;
const FRAMES: usize = 4;

/// Deterministic pseudo-random coordinates in [-50, 50) Å.
fn coords(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 100.0 - 50.0
    }
}

fn xyz_text() -> String {
    let mut r = coords(1);
    let mut t = String::new();
    let names = ["C", "O", "N", "H"];
    for f in 0..FRAMES {
        writeln!(t, "{ATOMS}\nframe {f}").unwrap();
        for i in 0..ATOMS {
            // The layout chemfiles and VMD write: %f-style, 6 decimals (ASE writes 8).
            writeln!(t, "{} {:.6} {:.6} {:.6}", names[i % 4], r(), r(), r()).unwrap();
        }
    }
    t
}

fn lammps_text() -> String {
    let mut r = coords(2);
    let mut t = String::new();
    for f in 0..FRAMES {
        write!(t, "ITEM: TIMESTEP\n{f}\nITEM: NUMBER OF ATOMS\n{ATOMS}\n").unwrap();
        t.push_str(
            "ITEM: BOX BOUNDS pp pp pp\n-50 50\n-50 50\n-50 50\nITEM: ATOMS id type x y z\n",
        );
        for i in 0..ATOMS {
            writeln!(
                t,
                "{} {} {:.6} {:.6} {:.6}",
                i + 1,
                1 + i % 2,
                r(),
                r(),
                r()
            )
            .unwrap();
        }
    }
    t
}

fn gro_text() -> String {
    let mut r = coords(3);
    let mut t = String::new();
    for f in 0..FRAMES {
        write!(t, "bench t= {f}.0 step= {f}\n{ATOMS:5}\n").unwrap();
        for i in 0..ATOMS {
            let (a, b, c) = (r() / 20.0 + 3.0, r() / 20.0 + 3.0, r() / 20.0 + 3.0);
            writeln!(
                t,
                "{:5}{:<5}{:>5}{:5}{a:8.3}{b:8.3}{c:8.3}",
                (i / 3 + 1) % 100_000,
                "SOL",
                "OW",
                (i + 1) % 100_000
            )
            .unwrap();
        }
        t.push_str("   6.00000   6.00000   6.00000\n");
    }
    t
}

fn pdb_text() -> String {
    let mut r = coords(4);
    let mut t = String::new();
    for f in 0..FRAMES {
        writeln!(t, "MODEL     {:>4}", f + 1).unwrap();
        for i in 0..ATOMS {
            let (a, b, c) = (r(), r(), r());
            writeln!(
                t,
                "ATOM  {:5}  CA  ALA A{:4}    {a:8.3}{b:8.3}{c:8.3}  1.00  0.00           C",
                (i + 1) % 100_000,
                (i / 10) % 10_000
            )
            .unwrap();
        }
        t.push_str("ENDMDL\n");
    }
    t
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("text_read");
    g.sample_size(10);
    for (name, format, text) in [
        ("xyz", Format::Xyz, xyz_text()),
        ("lammps", Format::LammpsDump, lammps_text()),
        ("gro", Format::Gro, gro_text()),
        ("pdb", Format::Pdb, pdb_text()),
    ] {
        let bytes = text.into_bytes();
        g.throughput(Throughput::Bytes(bytes.len() as u64));
        let mut frame = Frame::new();
        g.bench_function(format!("{name}_100k_atoms_x{FRAMES}"), |b| {
            b.iter(|| {
                let mut t = Trajectory::from_reader(Cursor::new(&bytes[..]), format, name).unwrap();
                let mut n = 0;
                while t.read_next(&mut frame).unwrap() {
                    n += frame.n_atoms();
                }
                black_box(n)
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
