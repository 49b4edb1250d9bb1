//! Topology + XTC to a 1080p image, per frame: a 100,002-atom water-like system (an O on a
//! 3.1 Å lattice and two H at 0.96 Å, residue SOL) written once per run with md-io's writers
//! (PDB topology, XTC of 5 frames), then per iteration: read one XTC frame, give it the
//! topology's names and elements (`Topology::apply`), style it (element radii and colours),
//! fill a `SphereScene` and ray-cast it at 1920x1080 with a camera fitted to the atoms. This is
//! what `texmap render run.xtc --topology top.pdb --size 1920x1080` does per frame, minus the
//! PNG encoding. Target: ≤ 60 ms per frame on 2 cores.
//!
//! `cargo bench --bench md_render -- --warm-up-time 2 --measurement-time 10`
//! (test mode, `cargo test --bench md_render`, uses 3,000 atoms at 320x180.)

use criterion::{Criterion, criterion_group};
use glam::Vec3;
use texmap::core::camera::Camera;
use texmap::core::color::srgb_to_linear;
use texmap::core::frame::Frame as Image;
use texmap::core::shade::{Lighting, Material};
use texmap::impostor::{Method, Options, Renderer, SphereScene};
use texmap::md_io::{AtomStyle, Format, Frame, Label, Topology, Trajectory, UnitCell, Writer};

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

fn system(n_mol: usize, k: usize) -> Frame {
    let side = (n_mol as f64).cbrt().ceil() as usize;
    let mut f = Frame::new();
    let mut rng = Lcg(7 + k as u64);
    let (o, h1, h2, sol) = (
        Label::new("OW").unwrap(),
        Label::new("HW1").unwrap(),
        Label::new("HW2").unwrap(),
        Label::new("SOL").unwrap(),
    );
    for m in 0..n_mol {
        let c = [
            (m % side) as f32 * 3.1 + 0.1 * rng.next(),
            ((m / side) % side) as f32 * 3.1,
            (m / (side * side)) as f32 * 3.1,
        ];
        f.positions.push(c);
        f.positions.push([c[0] + 0.96, c[1], c[2]]);
        f.positions.push([c[0] - 0.24, c[1] + 0.93, c[2]]);
        f.names.extend([o, h1, h2]);
        f.res_names.extend([sol; 3]);
        f.res_ids.extend([m as i64 % 9999 + 1; 3]);
    }
    let l = side as f64 * 3.1;
    f.cell = Some(UnitCell::orthorhombic(l, l, l).unwrap());
    f
}

fn bench(c: &mut Criterion) {
    // `cargo bench` passes --bench; `cargo test --benches` runs the small sizes.
    let test_mode = !std::env::args().any(|a| a == "--bench");
    let (n_mol, w, h) = if test_mode {
        (1_000, 320, 180)
    } else {
        (33_334, 1920, 1080)
    };
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path().join("top.pdb");
    let xtc = dir.path().join("run.xtc");
    {
        let mut wp = Writer::create(&top, Format::Pdb).unwrap();
        wp.write_frame(&system(n_mol, 0)).unwrap();
        wp.finish().unwrap();
        let mut wx = Writer::create(&xtc, Format::Xtc).unwrap();
        for k in 0..5 {
            let mut f = system(n_mol, k);
            f.names.clear();
            f.res_names.clear();
            f.res_ids.clear();
            wx.write_frame(&f).unwrap();
        }
        wx.finish().unwrap();
    }
    let topo = Topology::open(&top).unwrap();
    let mut traj = Trajectory::open(&xtc).unwrap();
    let n_frames = traj.n_frames().unwrap();
    let style = AtomStyle::new();
    let mut md = Frame::new();
    let mut scene = SphereScene::default();
    let (mut radii, mut colors) = (Vec::new(), Vec::new());
    let mut renderer = Renderer::new();
    // Materials: one per element colour met (O and H here).
    let mut palette: Vec<[u8; 3]> = Vec::new();
    let mut fill = |md: &mut Frame, scene: &mut SphereScene| {
        style.apply(md, &mut radii, &mut colors);
        scene.centers.clear();
        scene.radii.clear();
        scene.kinds.clear();
        for i in 0..md.n_atoms() {
            let key = colors[i].map(|v| (v * 255.0).round() as u8);
            let k = match palette.iter().position(|p| *p == key) {
                Some(k) => k,
                None => {
                    palette.push(key);
                    palette.len() - 1
                }
            };
            scene.push(Vec3::from(md.positions[i]), radii[i], k as u16);
        }
        scene.materials = palette
            .iter()
            .map(|p| Material::plastic(Vec3::from(p.map(|v| srgb_to_linear(v as f32 / 255.0)))))
            .collect();
    };
    traj.read_frame(0, &mut md).unwrap();
    topo.apply(&mut md, "run.xtc", 0).unwrap();
    fill(&mut md, &mut scene);
    let (lo, hi) = scene.bounds().unwrap();
    let camera = Camera::fit_sphere(
        (lo + hi) * 0.5,
        (hi - lo).length() * 0.5,
        Vec3::new(-1.0, -0.6, -0.8).normalize(),
        Vec3::Y,
        Some(40.0),
        w,
        h,
        1.05,
    )
    .unwrap();
    let opts = Options::new(Method::Raycast, Lighting::default_for(&camera));
    let mut image = Image::new(w, h, opts.background);
    let mut g = c.benchmark_group("md_render");
    g.sample_size(10);
    let mut k = 0;
    g.bench_function(format!("xtc_topology_{}atoms_{w}x{h}", 3 * n_mol), |b| {
        b.iter(|| {
            k = (k + 1) % n_frames;
            traj.read_frame(k, &mut md).unwrap();
            topo.apply(&mut md, "run.xtc", k).unwrap();
            fill(&mut md, &mut scene);
            renderer.render_into(&scene, &camera, &opts, &mut image)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
