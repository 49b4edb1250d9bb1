//! Texture sampling speed on a tilted ground plane at 1024x768 (Seed 000's flight-simulator view):
//! nearest, bilinear, trilinear (Eq. 4) and the span sampler (Eq. 8–10, K = 3 and 4), one core,
//! over a 4096² procedural RGBA8 pyramid. Throughput is in samples (pixels) per second.
//!
//! Run: `cargo bench --bench sampling -- --warm-up-time 1 --measurement-time 3`
//! Map coordinates and derivatives are precomputed per pixel (Seed 000 Eq. 1–2), so only the
//! sampling is timed.
//!
//! Cases: `nearest`, `bilinear`, `trilinear` through `sample_pixels` (trilinear runs eight pixels
//! per step in AVX2 lanes, four in the SSE2 baseline); `trilinear_quads`, `span_k3`, `span_k4`
//! through `sample_quads` (the span sampler runs eight spans per step in AVX2 lanes, four in
//! SSE2); `*_quad_api` one `sample_quad` call per quad, as the rasteriser calls it
//! (`quadratic3_quad_api`: the quadratic 3x3 sampler on trilinear's levels).
//! The target of issue #2 compares `span_k3` / `span_k4` with `trilinear` (the best of each).
//! Instruction counts of the same scene: `crates/texmap-core/examples/sampling_prof.rs`.
//!
//! Two groups: `sampling_*` measures wall-clock time (criterion's default); `sampling_cpu_*`
//! measures the benchmark thread's CPU time (`CLOCK_THREAD_CPUTIME_ID`, Linux), which stays
//! meaningful when other processes share the cores (time spent waiting for a core is not
//! counted; cache and memory-bandwidth contention still are).

use std::hint::black_box;

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use texmap_core::camera::Camera;
use texmap_core::glam::{Vec2, Vec3, Vec4};
use texmap_core::mip::{MipTexture, Reduction, Wrap};
use texmap_core::sample::{Banks, Sampler};
use texmap_core::transform::TexturedFace;

const W: u32 = 1024;
const H: u32 = 768;
const TEX: u32 = 4096;

/// A 4096² sRGB8 pattern: coloured checkers of several sizes with a gradient (no flat areas).
fn texture() -> MipTexture {
    let mut data = vec![0u8; (TEX * TEX * 4) as usize];
    for y in 0..TEX {
        for x in 0..TEX {
            let i = ((y * TEX + x) * 4) as usize;
            let c8 = ((x >> 3) ^ (y >> 3)) & 1;
            let c64 = ((x >> 6) ^ (y >> 6)) & 1;
            data[i] = (40 + 180 * c8 + (x & 31)) as u8;
            data[i + 1] = (30 + 150 * c64 + (y & 63)) as u8;
            data[i + 2] = ((x ^ y) & 255) as u8;
            data[i + 3] = 255;
        }
    }
    MipTexture::from_srgb8(TEX, TEX, &data, Reduction::GammaCorrect, Wrap::Repeat).unwrap()
}

/// The tilted plane: eye 2 units above the ground looking 30° down, 60° FOV; the whole image sees
/// the ground. One map width = 8 world units.
fn scene() -> (Vec<Vec2>, Vec<Vec2>, Vec<Vec2>, Vec<[Vec2; 4]>) {
    let eye = Vec3::new(0.0, 2.0, 0.0);
    let fwd = Vec3::new(
        0.0,
        -(30f32.to_radians().sin()),
        -(30f32.to_radians().cos()),
    );
    let cam = Camera::perspective_look_at(eye, eye + fwd, Vec3::Y, 60.0, W, H).unwrap();
    let face = TexturedFace::new(Vec3::ZERO, Vec3::X, Vec3::Z, 8.0, &cam).unwrap();
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

/// The calling thread's CPU time in nanoseconds.
#[cfg(target_os = "linux")]
fn thread_cpu_ns() -> u64 {
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
    // SAFETY: clock_gettime writes one timespec (two C longs on 64-bit Linux) to a valid pointer.
    let rc = unsafe { clock_gettime(CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    ts.sec as u64 * 1_000_000_000 + ts.nsec as u64
}

/// Elsewhere: wall-clock time since the first call.
#[cfg(not(target_os = "linux"))]
fn thread_cpu_ns() -> u64 {
    use std::sync::OnceLock;
    use std::time::Instant;
    static T0: OnceLock<Instant> = OnceLock::new();
    T0.get_or_init(Instant::now).elapsed().as_nanos() as u64
}

/// Criterion measurement: thread CPU time.
struct ThreadCpu;

struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, _typical: f64, values: &mut [f64]) -> &'static str {
        for v in values {
            *v *= 1e-6;
        }
        "ms (cpu)"
    }
    fn scale_throughputs(&self, _typical: f64, t: &Throughput, values: &mut [f64]) -> &'static str {
        let per = match *t {
            Throughput::Elements(e) | Throughput::ElementsAndBytes { elements: e, .. } => e as f64,
            Throughput::Bytes(b) | Throughput::BytesDecimal(b) => b as f64,
            Throughput::Bits(b) => b as f64,
        };
        for v in values {
            *v = per * 1e3 / v.max(1.0);
        }
        "Melem/s (cpu)"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

impl Measurement for ThreadCpu {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, i: u64) -> u64 {
        thread_cpu_ns().saturating_sub(i)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

fn sampling(c: &mut Criterion) {
    run(c, "sampling_1024x768_tex4096");
}

fn sampling_cpu(c: &mut Criterion<ThreadCpu>) {
    run(c, "sampling_cpu_1024x768_tex4096");
}

fn run<M: Measurement>(c: &mut Criterion<M>, group: &str) {
    let tex = texture();
    let (uv, dx, dy, quads) = scene();
    let n = uv.len();
    let mut out = vec![Vec4::ZERO; n];
    let mut qout = vec![[Vec4::ZERO; 4]; quads.len()];
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(n as u64));
    for (name, s) in [
        ("nearest", Sampler::Nearest),
        ("bilinear", Sampler::Bilinear),
        ("trilinear", Sampler::Trilinear),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                s.sample_pixels(&tex, black_box(&uv), &dx, &dy, &mut out)
                    .unwrap();
                black_box(&out);
            })
        });
    }
    for (name, s) in [
        ("trilinear_quads", Sampler::Trilinear),
        ("span_k3", Sampler::Span(Banks::K3)),
        ("span_k4", Sampler::Span(Banks::K4)),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                s.sample_quads(&tex, black_box(&quads), &mut qout).unwrap();
                black_box(&qout);
            })
        });
    }
    // The per-quad API the rasteriser calls (one 2x2 quad per call).
    for (name, s) in [
        ("trilinear_quad_api", Sampler::Trilinear),
        ("span_k3_quad_api", Sampler::Span(Banks::K3)),
        ("span_k4_quad_api", Sampler::Span(Banks::K4)),
        ("quadratic3_quad_api", Sampler::Quadratic3),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                for (o, q) in qout.iter_mut().zip(black_box(&quads)) {
                    *o = s.sample_quad(&tex, *q);
                }
                black_box(&qout);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, sampling);
criterion_group! {
    name = benches_cpu;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = sampling_cpu
}
criterion_main!(benches, benches_cpu);
