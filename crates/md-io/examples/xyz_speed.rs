//! Reads an in-memory XYZ text K times (K from argv) so `perf stat` can count the cycles of
//! reading alone (run with K = 0 to get the cost of building the text).
use std::fmt::Write;
use std::io::Cursor;
use texmap_md_io::{Format, Frame, Trajectory};

fn main() {
    let k: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let fmt = std::env::args().nth(2).unwrap_or_else(|| "xyz".into());
    let mut s = 1u64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 100.0 - 50.0
    };
    let mut t = String::new();
    let names = ["C", "O", "N", "H"];
    let format = if fmt == "lammps" {
        Format::LammpsDump
    } else {
        Format::Xyz
    };
    for f in 0..4 {
        if format == Format::Xyz {
            writeln!(t, "100000\nframe {f}").unwrap();
        } else {
            write!(t, "ITEM: TIMESTEP\n{f}\nITEM: NUMBER OF ATOMS\n100000\nITEM: BOX BOUNDS pp pp pp\n-50 50\n-50 50\n-50 50\nITEM: ATOMS id type x y z\n").unwrap();
        }
        for i in 0..100_000 {
            if format == Format::Xyz {
                writeln!(t, "{} {:.6} {:.6} {:.6}", names[i % 4], r(), r(), r()).unwrap();
            } else {
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
    }
    let bytes = t.into_bytes();
    let mut frame = Frame::new();
    let mut n = 0;
    for _ in 0..k {
        let mut tr = Trajectory::from_reader(Cursor::new(&bytes[..]), format, "x").unwrap();
        while tr.read_next(&mut frame).unwrap() {
            n += frame.n_atoms();
        }
    }
    eprintln!("{} bytes, {n} atoms read", bytes.len());
}
