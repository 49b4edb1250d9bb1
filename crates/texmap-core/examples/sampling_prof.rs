//! Profiling driver for the samplers: the scene of `benches/sampling.rs` (tilted plane 1024x768,
//! 4096² procedural sRGB8 pyramid, Repeat), one case run `frames` times, for callgrind and
//! cachegrind (instruction counts are repeatable on a loaded machine, wall clock is not).
//!
//! ```text
//! cargo build --release -p texmap-core --example sampling_prof
//! valgrind --tool=callgrind --dump-instr=yes --toggle-collect='*run_case*' \
//!     target/release/examples/sampling_prof span_k3 1
//! ```
//!
//! Cases: `trilinear` (`sample_pixels`), `trilinear_quads`, `span_k3`, `span_k4`
//! (`sample_quads`), `trilinear_quad_api`, `span_k3_quad_api`, `span_k4_quad_api`,
//! `quadratic3_quad_api` (one `sample_quad` call per quad). An optional third argument sets the texture side (default 4096).
//! Prints the thread CPU time per sample of the best frame to stderr (for quick A/B runs on a
//! shared machine: time spent waiting for a core is not counted, cache contention is).

use std::hint::black_box;

use texmap_core::camera::Camera;
use texmap_core::glam::{Vec2, Vec3, Vec4};
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::{Banks, Sampler};
use texmap_core::transform::TexturedFace;

const W: u32 = 1024;
const H: u32 = 768;

/// The bench's pattern: coloured checkers of several sizes with a gradient.
fn texture(side: u32) -> MipTexture {
    let mut data = vec![0u8; (side * side * 4) as usize];
    for y in 0..side {
        for x in 0..side {
            let i = ((y * side + x) * 4) as usize;
            let c8 = ((x >> 3) ^ (y >> 3)) & 1;
            let c64 = ((x >> 6) ^ (y >> 6)) & 1;
            data[i] = (40 + 180 * c8 + (x & 31)) as u8;
            data[i + 1] = (30 + 150 * c64 + (y & 63)) as u8;
            data[i + 2] = ((x ^ y) & 255) as u8;
            data[i + 3] = 255;
        }
    }
    MipTexture::from_srgb8(side, side, &data, Reduction::GammaCorrect, Wrap::Repeat)
        .expect("valid texture")
}

type Scene = (Vec<Vec2>, Vec<Vec2>, Vec<Vec2>, Vec<[Vec2; 4]>);

/// The bench's tilted plane: eye 2 units up looking 30° down, 60° FOV, 8 world units per map.
fn scene() -> Scene {
    let eye = Vec3::new(0.0, 2.0, 0.0);
    let a = 30f32.to_radians();
    let fwd = Vec3::new(0.0, -a.sin(), -a.cos());
    let cam = Camera::perspective_look_at(eye, eye + fwd, Vec3::Y, 60.0, W, H).expect("camera");
    let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 8.0, &cam).expect("face");
    let (mut uv, mut dx, mut dy) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..H {
        for i in 0..W {
            let s = face
                .map(i as f32 + 0.5, j as f32 + 0.5)
                .expect("ground everywhere");
            uv.push(s.uv);
            dx.push(s.duv_dx);
            dy.push(s.duv_dy);
        }
    }
    let mut quads = Vec::new();
    for j in (0..H as usize).step_by(2) {
        for i in (0..W as usize).step_by(2) {
            let p = |x: usize, y: usize| uv[y * W as usize + x];
            quads.push([p(i, j), p(i + 1, j), p(i, j + 1), p(i + 1, j + 1)]);
        }
    }
    (uv, dx, dy, quads)
}

/// The calling thread's CPU time in seconds (Linux; elsewhere 0, and only callgrind counts).
fn thread_cpu_s() -> f64 {
    #[cfg(target_os = "linux")]
    {
        #[repr(C)]
        struct Timespec {
            sec: i64,
            nsec: i64,
        }
        unsafe extern "C" {
            fn clock_gettime(clock: i32, ts: *mut Timespec) -> i32;
        }
        const CLOCK_THREAD_CPUTIME_ID: i32 = 3;
        let mut ts = Timespec { sec: 0, nsec: 0 };
        // SAFETY: clock_gettime writes one timespec to a valid pointer.
        unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
        ts.sec as f64 + ts.nsec as f64 * 1e-9
    }
    #[cfg(not(target_os = "linux"))]
    {
        0.0
    }
}

/// One frame of `case` (the function callgrind's `--toggle-collect` selects).
#[inline(never)]
fn run_case(
    case: &str,
    tex: &MipTexture,
    s: &Scene,
    out: &mut [Vec4],
    qout: &mut [[Vec4; 4]],
) -> bool {
    let (uv, dx, dy, quads) = s;
    let per_pixel =
        |smp: Sampler, out: &mut [Vec4]| smp.sample_pixels(tex, black_box(uv), dx, dy, out).is_ok();
    let bulk = |smp: Sampler, qout: &mut [[Vec4; 4]]| {
        smp.sample_quads(tex, black_box(quads), qout).is_ok()
    };
    let api = |smp: Sampler, qout: &mut [[Vec4; 4]]| {
        for (o, q) in qout.iter_mut().zip(black_box(quads)) {
            *o = smp.sample_quad(tex, *q);
        }
        true
    };
    match case {
        "trilinear" => per_pixel(Sampler::Trilinear, out),
        "trilinear_quads" => bulk(Sampler::Trilinear, qout),
        "span_k3" => bulk(Sampler::Span(Banks::K3), qout),
        "span_k4" => bulk(Sampler::Span(Banks::K4), qout),
        "trilinear_quad_api" => api(Sampler::Trilinear, qout),
        "span_k3_quad_api" => api(Sampler::Span(Banks::K3), qout),
        "span_k4_quad_api" => api(Sampler::Span(Banks::K4), qout),
        "quadratic3_quad_api" => api(Sampler::Quadratic3, qout),
        _ => false,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map(String::as_str).unwrap_or("span_k3");
    let frames: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1);
    let side: u32 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(4096);
    let tex = texture(side);
    let s = scene();
    let mut out = vec![Vec4::ZERO; s.0.len()];
    let mut qout = vec![[Vec4::ZERO; 4]; s.3.len()];
    let mut best = f64::INFINITY;
    for _ in 0..frames {
        let t = thread_cpu_s();
        if !run_case(case, &tex, &s, &mut out, &mut qout) {
            eprintln!("unknown case {case}");
            std::process::exit(2);
        }
        best = best.min(thread_cpu_s() - t);
    }
    // A checksum so the work cannot be dropped, and the best frame's time per sample.
    let sum: f32 = out
        .iter()
        .chain(qout.as_flattened())
        .map(|c| c.x + c.y + c.z)
        .sum();
    eprintln!(
        "{case}: best {:.2} ns/sample of thread CPU ({:.1} M/s), checksum {sum}",
        best * 1e9 / s.0.len() as f64,
        s.0.len() as f64 / best / 1e6
    );
}
