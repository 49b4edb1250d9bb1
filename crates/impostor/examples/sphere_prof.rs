//! Profiling driver: `cargo run --release -p texmap-impostor --example sphere_prof -- S2 raycast 20`
//! renders a named scene repeatedly and prints the mean time per frame and the covered fraction.

use std::time::Instant;
use texmap_core::camera::Camera;
use texmap_core::frame::Frame;
use texmap_core::glam::Vec3;
use texmap_core::shade::{Lighting, Material};
use texmap_impostor::{Method, Options, Renderer, SphereScene};

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

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("S2");
    let method = Method::from_name(args.get(2).map(String::as_str).unwrap_or("raycast")).unwrap();
    let iters: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(10);
    let fov: f32 = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(69.0);
    let (n, side, r, w, h) = match name {
        "S1" => (1115, 24.0, 1.0, 500, 500),
        "S2" => (100_000, 100.0, 0.5, 1920, 1080),
        _ => (1_000_000, 200.0, 0.3, 1920, 1080),
    };
    let mut rng = Lcg(1);
    let mut s = SphereScene::new(vec![Material::plastic(Vec3::new(0.8, 0.3, 0.2)); 6]);
    for i in 0..n {
        let c = (Vec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * side;
        s.push(c, r, (i % 6) as u16);
    }
    let eye = Vec3::new(0.55, 0.35, 0.76).normalize() * (2.4 * side);
    let cam = Camera::perspective_look_at(eye, Vec3::ZERO, Vec3::Y, fov, w, h).unwrap();
    let opts = Options::new(method, Lighting::default_for(&cam));
    let mut rend = Renderer::new();
    let mut frame = Frame::new(w, h, [0, 0, 0, 255]);
    let st = rend.render_into(&s, &cam, &opts, &mut frame);
    let cpu0 = cpu_ms();
    let t = Instant::now();
    for _ in 0..iters {
        rend.render_into(&s, &cam, &opts, &mut frame);
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / iters as f64;
    let cpu = (cpu_ms() - cpu0) / iters as f64;
    println!(
        "{name} {} {ms:.2} ms/frame wall, {cpu:.2} ms/frame CPU (all threads), coverage {:.3}, {st:?}",
        method.name(),
        frame.coverage_count() as f64 / frame.len() as f64
    );
}

/// User + system CPU time of this process in ms (Linux `/proc/self/stat`, 10 ms ticks).
fn cpu_ms() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let rest = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11).and_then(|v| v.parse().ok()).unwrap_or(0.0)
        + f.get(12).and_then(|v| v.parse().ok()).unwrap_or(0.0);
    ticks * 10.0
}
