//! Molecular surfaces (`md_scene::surface`, `texmap render --style surface`): wwPDB 3E8M chain A
//! (2,646 atoms, md-io's test data) with van der Waals radii, and 27 copies of it on a 3x3x3
//! lattice 70 Å apart (71,442 atoms): the surface built at 0.5 Å (density, surface nets, Newton
//! projection) and drawn over a cleared 1920x1080 frame; the chain alone also coloured by
//! element (`3e8m_by_element`: the colour boundaries cut into the triangles they cross); the
//! chain's cartoon (DSSP, spline, sweep). A movie pays them per frame. Volumetric data: the
//! chain's Gaussian density on a 0.5 Å grid (as a cube file would hold it), its isosurface and
//! that surface cut into 64 colour bands (`texmap render --isosurface`, `--isosurface-color-by`).
//! Aspherical particles (`--style ellipsoids`): 8,000 ellipsoids drawn as impostors, and as the
//! meshes tessellated for the view that the reference traces, drawn by the rasteriser.
//!
//! `cargo bench --bench md_surface -- --warm-up-time 2 --measurement-time 10`
//! (test mode, `cargo test --bench md_surface`, builds the one chain at 1.0 Å and 320x180.)

use criterion::{Criterion, criterion_group};
use glam::Vec3;
use texmap::core::camera::Camera;
use texmap::core::frame::Frame as Image;
use texmap::core::shade::{Lighting, Material};
use texmap::md_io::volume::Volume;
use texmap::md_io::{AtomStyle, Frame, Trajectory};
use texmap::md_scene::cartoon::append_cartoon;
use texmap::md_scene::ellipsoids::{Ellipsoid, TOLERANCE_PX, draw, tessellate};
use texmap::md_scene::isosurface::{Side, bands, isosurface};
use texmap::md_scene::surface::{MolMesh, SurfaceAtoms, SurfaceOptions, draw_mesh};

fn bench(c: &mut Criterion) {
    // `cargo bench` passes --bench; `cargo test --benches` runs the small sizes.
    let test_mode = !std::env::args().any(|a| a == "--bench");
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/md-io/tests/data/dssp/3e8mA.pdb.gz"
    );
    let mut traj = Trajectory::open(path).unwrap();
    let mut md = Frame::new();
    traj.read_frame(0, &mut md).unwrap();
    let (mut radii, mut colors) = (Vec::new(), Vec::new());
    AtomStyle::new().apply(&md, &mut radii, &mut colors);
    let mut chain = SurfaceAtoms::default();
    for (p, r) in md.positions.iter().zip(&radii) {
        chain.push(Vec3::from(*p), *r, 0);
    }
    // The same chain with one material per element (C, N, O, S, ...).
    let mut by_element = SurfaceAtoms::default();
    for (i, (p, r)) in md.positions.iter().zip(&radii).enumerate() {
        let z = texmap::md_io::atom_element(&md, i).z();
        by_element.push(Vec3::from(*p), *r, z as u16);
    }
    let mut lattice = SurfaceAtoms::default();
    for k in 0..27 {
        let shift = Vec3::new((k % 3) as f32, ((k / 3) % 3) as f32, (k / 9) as f32) * 70.0;
        for ((c, r), kind) in chain.centers.iter().zip(&chain.radii).zip(&chain.kinds) {
            lattice.push(*c + shift, *r, *kind);
        }
    }
    let (spacing, w, h) = if test_mode {
        (1.0, 320, 180)
    } else {
        (0.5, 1920, 1080)
    };
    let options = SurfaceOptions {
        spacing,
        ..Default::default()
    };
    let mut g = c.benchmark_group("md_surface");
    g.sample_size(10);
    // The chain's cartoon (DSSP included, as every frame pays it).
    let centers: Vec<Vec3> = md.positions.iter().map(|p| Vec3::from(*p)).collect();
    let (kinds, selected) = (vec![0u16; md.n_atoms()], vec![true; md.n_atoms()]);
    g.bench_function("cartoon_3e8m", |b| {
        b.iter(|| {
            let mut mesh = MolMesh::default();
            append_cartoon(&md, &centers, &kinds, &selected, &mut mesh);
            mesh
        })
    });
    let mut cases = vec![("3e8m", &chain), ("3e8m_by_element", &by_element)];
    if !test_mode {
        cases.push(("3e8m_x27", &lattice));
    }
    for (name, atoms) in cases {
        g.bench_function(format!("build_{name}_{}atoms", atoms.len()), |b| {
            b.iter(|| MolMesh::surface(atoms, &options).unwrap())
        });
        let surface = MolMesh::surface(atoms, &options).unwrap();
        eprintln!(
            "{name}: {} vertices, {} triangles",
            surface.positions.len(),
            surface.triangles.len()
        );
        let (lo, hi) = atoms
            .centers
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), c| {
                (lo.min(*c), hi.max(*c))
            });
        let camera = Camera::fit_sphere(
            (lo + hi) * 0.5,
            (hi - lo).length() * 0.5 + 3.0,
            Vec3::new(-1.0, -0.6, -0.8).normalize(),
            Vec3::Y,
            Some(40.0),
            w,
            h,
            1.05,
        )
        .unwrap();
        let lighting = Lighting::default_for(&camera);
        let materials = [Material::plastic(Vec3::new(0.4, 0.6, 0.9))];
        let mut image = Image::new(w, h, [0, 0, 0, 255]);
        g.bench_function(
            format!("draw_{name}_{}triangles_{w}x{h}", surface.triangles.len()),
            |b| {
                b.iter(|| {
                    image.depth.fill(f32::INFINITY);
                    draw_mesh(&surface, &materials, &camera, &lighting, 1.0, &mut image).unwrap()
                })
            },
        );
    }
    // Volumetric data: the chain's density, a Gaussian per atom (σ = 0.6 r) summed on a grid
    // as a cube file holds it, then its isosurface (surface nets on the grid, normals from
    // the gradient) and that surface cut into 64 colour bands by x (an ESP map's step).
    let h = if test_mode { 1.0 } else { 0.5 };
    let vol = density_volume(&chain, h);
    let n_points = vol.data.len();
    g.bench_function(format!("isosurface_3e8m_{n_points}points"), |b| {
        b.iter(|| isosurface(&vol, 0.3, Side::Above, 0).unwrap())
    });
    let iso = isosurface(&vol, 0.3, Side::Above, 0).unwrap();
    eprintln!(
        "isosurface of {n_points} points: {} vertices, {} triangles",
        iso.positions.len(),
        iso.triangles.len()
    );
    let values: Vec<f64> = iso.positions.iter().map(|p| p.x as f64).collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    g.bench_function(
        format!("bands64_3e8m_{}triangles", iso.triangles.len()),
        |b| b.iter(|| bands(&iso, &values, (lo, hi), 64, 0, 64)),
    );
    // Aspherical particles (`--style ellipsoids`): a Gay-Berne-like liquid of 3:1:1
    // ellipsoids, 20^3 on a lattice 2.2 Å apart at orientations from a fixed generator, seen
    // whole: tessellated for the view (0.25 px), then drawn.
    let side = if test_mode { 6 } else { 20 };
    let (w, h) = if test_mode { (320, 180) } else { (1920, 1080) };
    let mut seed = 17u64;
    let mut next = move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 40) as f32 / (1u64 << 24) as f32
    };
    let particles: Vec<Ellipsoid> = (0..side * side * side)
        .map(|i| {
            let at = Vec3::new(
                (i % side) as f32,
                ((i / side) % side) as f32,
                (i / side / side) as f32,
            );
            let axis = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            Ellipsoid {
                center: at * 2.2,
                semi_axes: Vec3::new(1.5, 0.5, 0.5),
                rotation: glam::Quat::from_axis_angle(axis, next() * 6.0),
                kind: 0,
            }
        })
        .collect();
    let centre = Vec3::splat((side - 1) as f32 * 1.1);
    let radius = centre.length() + 1.5;
    let camera = Camera::perspective_look_at(
        centre + Vec3::new(1.0, 0.8, 1.6).normalize() * radius * 2.6,
        centre,
        Vec3::Y,
        45.0,
        w,
        h,
    )
    .unwrap();
    let n = particles.len();
    let lighting = Lighting::default_for(&camera);
    let materials = [Material::plastic(Vec3::new(0.8, 0.3, 0.3))];
    let mut image = Image::new(w, h, [0, 0, 0, 255]);
    g.bench_function(format!("ellipsoids_impostors_{n}_{w}x{h}"), |b| {
        b.iter(|| {
            image.depth.fill(f32::INFINITY);
            draw(&particles, &materials, &camera, &lighting, &mut image).unwrap()
        })
    });
    // The meshes the reference traces, as the rasteriser would draw them instead.
    g.bench_function(format!("ellipsoids_tessellate_{n}_{w}x{h}"), |b| {
        b.iter(|| tessellate(&particles, Some(&camera), TOLERANCE_PX))
    });
    let mesh = tessellate(&particles, Some(&camera), TOLERANCE_PX);
    eprintln!("{n} ellipsoids: {} triangles", mesh.triangles.len());
    g.bench_function(format!("ellipsoids_mesh_draw_{n}_{w}x{h}"), |b| {
        b.iter(|| {
            image.depth.fill(f32::INFINITY);
            draw_mesh(&mesh, &materials, &camera, &lighting, 1.0, &mut image).unwrap()
        })
    });
    g.finish();
}

/// The Gaussian density of `atoms` (σ = 0.6 r, cut at 3σ) on a grid `h` Å apart.
fn density_volume(atoms: &SurfaceAtoms, h: f32) -> Volume {
    let (lo, hi) = atoms
        .centers
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), c| {
            (lo.min(*c), hi.max(*c))
        });
    let (lo, hi) = (lo - Vec3::splat(5.0), hi + Vec3::splat(5.0));
    let dims = ((hi - lo) / h)
        .ceil()
        .as_uvec3()
        .to_array()
        .map(|d| d as usize + 1);
    let mut data = vec![0f32; dims[0] * dims[1] * dims[2]];
    for (c, r) in atoms.centers.iter().zip(&atoms.radii) {
        let sigma = 0.6 * r;
        let cut = 3.0 * sigma;
        let a = ((*c - lo - cut) / h).floor().max(Vec3::ZERO).as_uvec3();
        let b = ((*c - lo + cut) / h).ceil().as_uvec3();
        for k in a.z..=b.z.min(dims[2] as u32 - 1) {
            for j in a.y..=b.y.min(dims[1] as u32 - 1) {
                for i in a.x..=b.x.min(dims[0] as u32 - 1) {
                    let p = lo + Vec3::new(i as f32, j as f32, k as f32) * h;
                    let d2 = (p - *c).length_squared();
                    data[(k as usize * dims[1] + j as usize) * dims[0] + i as usize] +=
                        (-d2 / (2.0 * sigma * sigma)).exp();
                }
            }
        }
    }
    let steps = [
        [h as f64, 0.0, 0.0],
        [0.0, h as f64, 0.0],
        [0.0, 0.0, h as f64],
    ];
    let origin = lo.as_dvec3().to_array();
    Volume::new(origin, steps, dims, data, false, "density").unwrap()
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
}
