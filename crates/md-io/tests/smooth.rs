//! Trajectory smoothing (`texmap_md_io::smooth`) against analytic answers: steady motion is
//! left where it is, wrapped atoms are averaged at their nearest image (the unwrapped path is
//! known), Gaussian jitter falls as 1/sqrt(window), and the smoother reading a trajectory
//! written to a file gives the brute-force window mean whatever order frames are asked in.

use std::io::Cursor;

use texmap_md_io::smooth::{Smoother, mean_positions, window};
use texmap_md_io::{Format, Frame, Trajectory, UnitCell, Writer};

/// A seeded stream of standard normal numbers (xorshift64* and Box-Muller).
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// One frame's exact positions.
type Exact = Vec<[f64; 3]>;

/// Frame `f` of `frames` (in `cell`, if any) smoothed over its window of half-width `half`.
fn smoothed(frames: &[Vec<[f32; 3]>], f: usize, half: usize, cell: Option<UnitCell>) -> Frame {
    let mut frame = Frame::new();
    frame.positions = frames[f].clone();
    frame.cell = cell;
    let others: Vec<&[[f32; 3]]> = window(f, frames.len(), half)
        .filter(|&g| g != f)
        .map(|g| frames[g].as_slice())
        .collect();
    mean_positions(&mut frame, &others);
    frame
}

/// `n` frames of `atoms` atoms: start points on a grid, velocity per atom, Gaussian jitter
/// of `sigma` Å per coordinate; the exact (jitter-free) positions too.
fn frames(n: usize, atoms: usize, sigma: f64) -> (Vec<Vec<[f32; 3]>>, Vec<Exact>) {
    let mut rng = Normal(0x9e37_79b9_7f4a_7c15);
    let start: Vec<[f64; 3]> = (0..atoms)
        .map(|i| {
            [
                (i % 10) as f64 * 3.0,
                (i / 10 % 10) as f64 * 3.0,
                (i / 100) as f64 * 3.0,
            ]
        })
        .collect();
    let velocity: Vec<[f64; 3]> = (0..atoms)
        .map(|_| [rng.next() * 0.3, rng.next() * 0.3, rng.next() * 0.3])
        .collect();
    let mut read = Vec::new();
    let mut exact = Vec::new();
    for f in 0..n {
        let e: Vec<[f64; 3]> = start
            .iter()
            .zip(&velocity)
            .map(|(s, v)| [0, 1, 2].map(|k| s[k] + v[k] * f as f64))
            .collect();
        read.push(
            e.iter()
                .map(|p| p.map(|x| (x + sigma * rng.next()) as f32))
                .collect(),
        );
        exact.push(e);
    }
    (read, exact)
}

#[test]
fn windows_shrink_symmetrically_at_the_ends() {
    assert_eq!(window(0, 5, 3), 0..=0);
    assert_eq!(window(1, 5, 3), 0..=2);
    assert_eq!(window(2, 5, 3), 0..=4);
    assert_eq!(window(4, 5, 3), 4..=4);
    assert_eq!(window(7, 20, 0), 7..=7);
    assert_eq!(window(0, 1, 2), 0..=0);
}

#[test]
fn steady_motion_stays_and_jitter_falls_as_one_over_root_window() {
    let (n, atoms, sigma, half) = (11, 4000, 0.5, 2usize);
    // Steady motion alone: every frame, ends included, stays where it is.
    let (read, exact) = frames(n, atoms, 0.0);
    for (f, exact) in exact.iter().enumerate() {
        let frame = smoothed(&read, f, half, None);
        for (p, e) in frame.positions.iter().zip(exact) {
            for k in 0..3 {
                assert!(
                    (p[k] as f64 - e[k]).abs() < 1e-4,
                    "frame {f}: {p:?} vs {e:?}"
                );
            }
        }
    }
    // With jitter: the interior frames' error is sigma / sqrt(2 half + 1).
    let (read, exact) = frames(n, atoms, sigma);
    let f = n / 2;
    let frame = smoothed(&read, f, half, None);
    let rms = |p: &[[f32; 3]]| {
        let s: f64 = p
            .iter()
            .zip(&exact[f])
            .map(|(p, e)| (0..3).map(|k| (p[k] as f64 - e[k]).powi(2)).sum::<f64>())
            .sum();
        (s / (3 * atoms) as f64).sqrt()
    };
    let (before, after) = (rms(&read[f]), rms(&frame.positions));
    let want = sigma / ((2 * half + 1) as f64).sqrt();
    assert!((before / sigma - 1.0).abs() < 0.03, "jitter {before}");
    assert!(
        (after / want - 1.0).abs() < 0.05,
        "smoothed {after}, expected {want}"
    );
}

#[test]
fn wrapped_atoms_are_averaged_at_their_nearest_image() {
    // A triclinic box; atoms move steadily (0.6 Å per frame and coordinate, rms; under half a
    // box length over a window, as the module docs require) and are wrapped into the box every
    // frame, so many cross a face within the window.
    let cell = UnitCell::from_lengths_angles([20.0, 18.0, 16.0], [80.0, 95.0, 100.0]).unwrap();
    let (n, half) = (9, 3usize);
    let (read, exact) = frames(n, 2000, 0.0);
    let wrapped: Vec<Vec<[f32; 3]>> = read
        .iter()
        .map(|p| {
            let mut f = Frame::new();
            f.positions = p.iter().map(|q| q.map(|x| x * 2.0)).collect();
            f.cell = Some(cell);
            texmap_md_io::pbc::wrap(&mut f);
            f.positions
        })
        .collect();
    let mut naive_far = 0;
    for (f, exact) in exact.iter().enumerate().take(n - 1).skip(1) {
        let frame = smoothed(&wrapped, f, half, Some(cell));
        let range = window(f, n, half);
        let count = (range.end() - range.start() + 1) as f64;
        for (i, p) in frame.positions.iter().enumerate() {
            // The truth is the unwrapped position (2x the steady path) up to whole cell
            // vectors.
            let truth = exact[i].map(|x| x * 2.0);
            let d = [0, 1, 2].map(|k| p[k] as f64 - truth[k]);
            let d = texmap_md_io::pbc::minimum_image(&cell, d);
            assert!(
                d.iter().all(|v| v.abs() < 1e-3),
                "frame {f} atom {i}: {d:?}"
            );
            // The plain mean of the wrapped positions is far off for atoms that crossed.
            let naive: Vec<f64> = (0..3)
                .map(|k| range.clone().map(|g| wrapped[g][i][k] as f64).sum::<f64>() / count)
                .collect();
            let nd = [0, 1, 2].map(|k| naive[k] - truth[k]);
            let nd = texmap_md_io::pbc::minimum_image(&cell, nd);
            naive_far += nd.iter().any(|v| v.abs() > 1.0) as usize;
        }
    }
    assert!(naive_far > 200, "only {naive_far} atoms crossed a face");
}

/// `read` written as an XYZ trajectory (carbon atoms) in memory.
fn xyz(read: &[Vec<[f32; 3]>]) -> Vec<u8> {
    let mut w = Writer::new(Cursor::new(Vec::new()), Format::Xyz, "mem.xyz").unwrap();
    for p in read {
        let mut f = Frame::new();
        f.positions = p.clone();
        f.names = vec![texmap_md_io::Label::new("C").unwrap(); p.len()];
        w.write_frame(&f).unwrap();
    }
    w.finish().unwrap().into_inner()
}

#[test]
fn the_smoother_reads_each_window_from_the_trajectory() {
    let (n, half) = (10, 2usize);
    let (read, _) = frames(n, 300, 0.4);
    let bytes = xyz(&read);
    let mut traj = Trajectory::from_reader(Cursor::new(bytes), Format::Xyz, "mem.xyz").unwrap();
    // Asked in order, backwards, and jumping: always the brute-force window mean of what the
    // file holds.
    let orders: [Vec<usize>; 3] = [
        (0..n).collect(),
        (0..n).rev().collect(),
        vec![5, 0, 9, 4, 4, 6, 1],
    ];
    let mut file = Vec::new();
    for f in 0..n {
        let mut frame = Frame::new();
        traj.read_frame(f, &mut frame).unwrap();
        file.push(frame.positions);
    }
    for order in orders {
        let mut smoother = Smoother::new(half);
        for &f in &order {
            let mut frame = Frame::new();
            traj.read_frame(f, &mut frame).unwrap();
            smoother.smooth(&mut traj, n, f, &mut frame).unwrap();
            let range = window(f, n, half);
            let count = (range.end() - range.start() + 1) as f64;
            for (i, p) in frame.positions.iter().enumerate() {
                for k in 0..3 {
                    let want: f64 =
                        range.clone().map(|g| file[g][i][k] as f64).sum::<f64>() / count;
                    assert!((p[k] as f64 - want).abs() < 1e-4, "{order:?} frame {f}");
                }
            }
        }
    }
}

#[test]
fn a_window_over_frames_of_other_atom_counts_names_both_frames() {
    let mut read = frames(6, 40, 0.1).0;
    read[4].truncate(39);
    let mut traj =
        Trajectory::from_reader(Cursor::new(xyz(&read)), Format::Xyz, "mem.xyz").unwrap();
    let mut smoother = Smoother::new(1);
    let mut frame = Frame::new();
    for f in 0..3 {
        traj.read_frame(f, &mut frame).unwrap();
        smoother.smooth(&mut traj, 6, f, &mut frame).unwrap();
    }
    traj.read_frame(3, &mut frame).unwrap();
    let e = smoother
        .smooth(&mut traj, 6, 3, &mut frame)
        .unwrap_err()
        .to_string();
    assert!(e.contains("mem.xyz") && e.contains("frame 4"), "{e}");
    assert!(e.contains("39 atoms, but frame 3 has 40"), "{e}");
}
