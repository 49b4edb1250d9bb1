//! The demo's materials section: a crystal drawn as materials scientists draw it in VESTA and
//! OVITO, from built-in data (no download), through the same plan, sphere method and mesh
//! drawing as `texmap render` (`--rep 'element Ti=polyhedra' --rep 'element O=ball-stick'
//! --replicate 3,3,4`).
//!
//! The crystal is rutile TiO₂ (space group P4₂/mnm, a = 4.594 Å, c = 2.959 Å, O at
//! u = 0.3048; Baur 1956), written here as its six atoms of the unit cell. The section states
//! what the drawing holds and checks it: one TiO₆ octahedron per Ti, each of 8 faces, and their
//! volume, which for this u is 9.908 Å³ (the value scipy's `ConvexHull` gives the same six O
//! atoms; md-io's tests/data/gen_vasp.py and the CLI's test compare the two).

use std::fmt;
use std::path::Path;

use texmap_core::shade::Lighting;
use texmap_impostor::{Method, Options, SphereScene};
use texmap_md_io::{Element, Frame, Label, Selection, UnitCell};
use texmap_md_scene::{
    DrawStyle, MolOptions, MolPlan, RepColor, Representation, SceneBuilder, StyleOptions, ViewAxis,
    fit_camera,
};

/// Why the materials section could not be made.
#[derive(Debug)]
pub struct MaterialsError(String);

impl fmt::Display for MaterialsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "materials demo: {}", self.0)
    }
}

impl std::error::Error for MaterialsError {}

fn fail(e: impl fmt::Display) -> MaterialsError {
    MaterialsError(e.to_string())
}

/// Rutile's unit cell: two Ti and four O atoms (see the module docs).
pub fn rutile() -> Frame {
    let (a, c, u) = (4.594f64, 2.959f64, 0.3048f64);
    let sites = [
        ("Ti", [0.0, 0.0, 0.0]),
        ("Ti", [0.5, 0.5, 0.5]),
        ("O", [u, u, 0.0]),
        ("O", [1.0 - u, 1.0 - u, 0.0]),
        ("O", [0.5 + u, 0.5 - u, 0.5]),
        ("O", [0.5 - u, 0.5 + u, 0.5]),
    ];
    let mut f = Frame::new();
    let cell = UnitCell::orthorhombic(a, a, c).expect("rutile's cell");
    for (k, (el, frac)) in sites.iter().enumerate() {
        f.positions.push(cell.to_cartesian(*frac).map(|x| x as f32));
        f.elements
            .push(Element::from_symbol(el).expect("an element"));
        f.names.push(Label::new(el).expect("a short label"));
        f.ids.push(k as i64 + 1);
    }
    f.cell = Some(cell);
    f.comment = "rutile TiO2".into();
    f
}

/// A polycrystal of about `atoms` FCC aluminium atoms (a = 4.05 Å) in a periodic cube of
/// `grains` Voronoi grains, seeded by `seed`: each grain a crystal turned by a random rotation
/// (returned, `[x, y, z, w]`, in grain order); of two atoms closer than 2 Å at a boundary the
/// later is dropped; thermal noise `noise` Å. The grain analysis of the demo and the
/// md_analysis bench are run on it.
pub fn polycrystal(atoms: usize, grains: usize, noise: f64, seed: u64) -> (Frame, Vec<[f64; 4]>) {
    use texmap_core::glam::{DQuat, DVec3};
    let a = 4.05f64;
    let l = (atoms as f64 * a * a * a / 4.0).cbrt();
    let mut rng = crate::rng::SplitMix64::new(seed);
    let seeds: Vec<[f64; 3]> = (0..grains)
        .map(|_| [0, 1, 2].map(|_| rng.range(0.0, l)))
        .collect();
    // The squared distance between two points at their nearest periodic images.
    let d2 = |p: &[f64; 3], q: &[f64; 3]| {
        (0..3)
            .map(|k| {
                let d = p[k] - q[k];
                let d = d - l * (d / l).round();
                d * d
            })
            .sum::<f64>()
    };
    let nearest = |p: [f64; 3]| {
        (0..grains)
            .min_by(|&x, &y| d2(&p, &seeds[x]).total_cmp(&d2(&p, &seeds[y])))
            .expect("at least one grain")
    };
    let base = [
        [0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0],
        [0.5, 0.0, 0.5],
        [0.0, 0.5, 0.5],
    ];
    let reach = (l * 0.87 / a).ceil() as i64 + 1;
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut turns = Vec::with_capacity(grains);
    for (g, seed) in seeds.iter().enumerate() {
        let q =
            DQuat::from_xyzw(rng.normal(), rng.normal(), rng.normal(), rng.normal()).normalize();
        turns.push([q.x, q.y, q.z, q.w]);
        for i in -reach..reach {
            for j in -reach..reach {
                for k in -reach..reach {
                    for b in base {
                        let v = DVec3::new(i as f64 + b[0], j as f64 + b[1], k as f64 + b[2]);
                        let p = q * (v * a);
                        // One copy of each site: the cube of side l around the seed.
                        if (0..3).any(|c| p[c] < -l / 2.0 || p[c] >= l / 2.0) {
                            continue;
                        }
                        let p = [0, 1, 2].map(|c| (p[c] + seed[c]).rem_euclid(l));
                        if nearest(p) == g {
                            points.push(p);
                        }
                    }
                }
            }
        }
    }
    // Thin the boundaries on a grid of cells 2 Å wide or wider.
    let cells = ((l / 2.0).floor() as usize).max(1);
    let cell_of = |p: &[f64; 3]| p.map(|v| ((v / l * cells as f64) as usize).min(cells - 1));
    let mut grid: std::collections::HashMap<[usize; 3], Vec<usize>> = Default::default();
    let mut frame = Frame::new();
    'atom: for (i, p) in points.iter().enumerate() {
        let c = cell_of(p);
        for d in 0..27 {
            let o = [d % 3, d / 3 % 3, d / 9].map(|v| v as i64 - 1);
            let n = [0, 1, 2].map(|k| (c[k] as i64 + o[k]).rem_euclid(cells as i64) as usize);
            if let Some(near) = grid.get(&n)
                && near.iter().any(|&j| d2(&points[j], p) < 4.0)
            {
                continue 'atom;
            }
        }
        grid.entry(c).or_default().push(i);
        frame
            .positions
            .push(p.map(|v| (v + noise * rng.normal()).rem_euclid(l) as f32));
    }
    frame.cell = Some(UnitCell::orthorhombic(l, l, l).expect("a positive side"));
    frame.names = vec![Label::new("Al").expect("a short name"); frame.positions.len()];
    (frame, turns)
}

/// Draws the section's picture into `out_dir/materials/rutile.png` and returns its HTML.
pub fn demo_section(out_dir: &Path) -> Result<String, MaterialsError> {
    let dir = out_dir.join("materials");
    std::fs::create_dir_all(&dir).map_err(fail)?;
    let rep = |sel: &str, draw, color| Representation {
        select: Some(Selection::parse(sel).expect("a fixed selection")),
        draw,
        color,
    };
    let mut plan = MolPlan::new(MolOptions {
        reps: vec![
            rep(
                "element Ti",
                DrawStyle::Polyhedra,
                Some(RepColor::Fixed([0.435, 0.659, 0.863])),
            ),
            rep("element O", DrawStyle::BallStick, None),
        ],
        replicate: Some([3, 3, 4]),
        ..MolOptions::default()
    })
    .map_err(fail)?;
    let mut builder = SceneBuilder::new(&StyleOptions::default()).map_err(fail)?;
    let mut frame = rutile();
    let mut scene = SphereScene::default();
    plan.build(&mut builder, &mut frame, &mut scene)
        .map_err(fail)?;
    let mesh = plan.polyhedra_mesh().clone();
    // The camera frames the polyhedra too.
    let mut framed = scene.clone();
    texmap_md_scene::push_framed_points(&mut framed, &mesh.positions);
    let (cam, _) = fit_camera(&frame, &framed, ViewAxis::Auto, None, 480, 360).map_err(fail)?;
    let lighting = Lighting::default_for(&cam);
    let mut options = Options::new(Method::Raycast, lighting);
    options.draw_bonds = plan.draws_bonds();
    draw_and_save(&scene, &mesh, &cam, &options, 0.85, &dir.join("rutile.png"))?;
    // What the picture holds: 3 x 3 x 4 cells of two Ti, each an octahedron of 8 faces.
    let titanium = 2 * 3 * 3 * 4;
    let faces = mesh.triangles.len();
    let volume = mesh.volume() / titanium as f64;
    if faces != 8 * titanium || (volume - 9.908).abs() > 0.01 {
        return Err(fail(format!(
            "expected {titanium} octahedra of 8 faces and 9.908 Å³, drew {faces} faces of {volume:.3} Å³ each"
        )));
    }
    let orbital = orbital_section(&dir)?;
    let grains = grains_section(&dir)?;
    let rdf = rdf_section(&dir)?;
    Ok(format!(
        "<p>Rutile TiO<sub>2</sub> (built in: its six atoms of the unit cell), 3 x 3 x 4 cells, \
         drawn as VESTA draws a crystal: the TiO<sub>6</sub> coordination polyhedra \
         (<code>--rep 'element Ti=polyhedra'</code>) and the O atoms as balls and sticks \
         (<code>--rep 'element O=ball-stick' --replicate 3,3,4</code>). {titanium} octahedra of \
         8 faces each, {volume:.3} Å<sup>3</sup> each (scipy's ConvexHull of the same six O \
         atoms: 9.908 Å<sup>3</sup>). The same pipeline reads VASP POSCAR/XDATCAR, \
         crystallographic CIF (expanded by its symmetry operations) and LAMMPS data files, and \
         draws arrows (<code>--rep 'all=arrows'</code>), trails and measurements.</p>\n\
         <img src=\"materials/rutile.png\" alt=\"rutile's TiO6 octahedra\" width=\"480\">\n\
         {orbital}{grains}{rdf}"
    ))
}

/// The spheres of `scene` ray-cast, `mesh` drawn over them at `opacity`, saved as a PNG.
fn draw_and_save(
    scene: &SphereScene,
    mesh: &texmap_md_scene::surface::MolMesh,
    cam: &texmap_core::camera::Camera,
    options: &Options,
    opacity: f32,
    png: &Path,
) -> Result<(), MaterialsError> {
    let mut render = texmap_impostor::render(scene, cam, options);
    let lighting = options.lighting;
    texmap_md_scene::surface::draw_mesh(
        mesh,
        &scene.materials,
        cam,
        &lighting,
        opacity,
        &mut render.frame,
    )
    .map_err(fail)?;
    let (w, h) = (render.frame.width(), render.frame.height());
    let raw: Vec<u8> = render.frame.color.iter().flatten().copied().collect();
    image::RgbaImage::from_raw(w, h, raw)
        .ok_or_else(|| fail("a frame of its own size"))?
        .save(png)
        .map_err(fail)
}

/// A polycrystal drawn as `texmap render --color-by ipf` draws it, and its grains found as
/// `--grains` finds them; the section checks each grain's mean orientation against the
/// rotation it was built with.
fn grains_section(dir: &Path) -> Result<String, MaterialsError> {
    use texmap_md_io::grains::{GrainOptions, segment};
    use texmap_md_io::orientation::{Symmetry, disorientation, orientations};
    let built = 6;
    let (mut frame, turns) = polycrystal(12_000, built, 0.05, 2026);
    let atoms = frame.n_atoms();
    let types = texmap_md_io::cna::classify(&frame);
    let fits = orientations(&frame, &types);
    let found = segment(&frame, &types, &fits, &GrainOptions::default());
    // Each grain found is one built: its mean orientation that grain's rotation.
    let mut worst = 0f64;
    for g in &found.grains {
        let nearest = turns
            .iter()
            .map(|t| disorientation(g.orientation, *t, Symmetry::Cubic))
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(nearest);
    }
    let worst = worst.to_degrees();
    if found.grains.len() != built || worst > 0.5 {
        return Err(fail(format!(
            "{built} grains built, {} found, mean orientations up to {worst:.2}° from the built ones",
            found.grains.len()
        )));
    }
    let crystalline = fits.iter().filter(|f| f.is_some()).count();
    let style = StyleOptions {
        color_by: texmap_md_scene::ColorBy::Ipf(texmap_md_scene::IpfAxis::Z),
        ..StyleOptions::default()
    };
    let mut plan = MolPlan::new(MolOptions::default()).map_err(fail)?;
    let mut builder = SceneBuilder::new(&style).map_err(fail)?;
    let mut scene = SphereScene::default();
    plan.build(&mut builder, &mut frame, &mut scene)
        .map_err(fail)?;
    let (cam, _) = fit_camera(&frame, &scene, ViewAxis::Auto, None, 480, 360).map_err(fail)?;
    let options = Options::new(Method::Raycast, Lighting::default_for(&cam));
    let empty = texmap_md_scene::surface::MolMesh::default();
    draw_and_save(&scene, &empty, &cam, &options, 1.0, &dir.join("grains.png"))?;
    Ok(format!(
        "<p>A polycrystal as <code>texmap render dump --color-by ipf --grains</code> draws \
         and segments one, as OVITO's polyhedral template matching and grain segmentation do: \
         {atoms} aluminium atoms in {built} Voronoi grains of random orientation (built in), \
         each FCC atom ({crystalline} of them) coloured by the crystal direction along z (an \
         EBSD inverse pole figure: [001] red, [101] green, [111] blue; boundaries white). \
         {} grains found; each grain's mean orientation is within {worst:.2}° of the rotation \
         it was built with.</p>\n\
         <img src=\"materials/grains.png\" alt=\"a polycrystal in inverse pole figure colours\" width=\"480\">\n",
        found.grains.len()
    ))
}

/// The radial distribution function of a polycrystal beside the perfect crystal's, as
/// `texmap convert --rdf 8 --rdf-table` writes it; the section checks that each first peak
/// holds the neighbours it should (12 in the perfect crystal).
fn rdf_section(dir: &Path) -> Result<String, MaterialsError> {
    let (poly, _) = polycrystal(12_000, 6, 0.05, 2026);
    // A perfect FCC aluminium crystal of 10³ cells, no noise.
    let a = 4.05f32;
    let mut perfect = Frame::new();
    for (i, j, k) in (0..1000).map(|c| (c / 100, (c / 10) % 10, c % 10)) {
        for b in [
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [0.5, 0.0, 0.5],
            [0.0, 0.5, 0.5],
        ] {
            perfect.positions.push([
                (i as f32 + b[0]) * a,
                (j as f32 + b[1]) * a,
                (k as f32 + b[2]) * a,
            ]);
        }
    }
    perfect.cell = Some(UnitCell::orthorhombic(40.5, 40.5, 40.5).map_err(fail)?);
    let (cutoff, bins) = (8.0f32, 160);
    let mut series = Vec::new();
    let mut first_shell = Vec::new();
    for (name, frame) in [("perfect crystal", &perfect), ("polycrystal", &poly)] {
        let g = texmap_md_io::rdf::rdf(frame, cutoff, bins, false).map_err(fail)?;
        // Neighbours within 3.4 Å (between the first shell at a/√2 = 2.86 Å and the second at
        // a = 4.05 Å): the pair count of those bins over the atoms.
        let n = frame.n_atoms() as f64;
        let volume = frame.cell.map_or(1.0, |c| c.volume());
        let dr = cutoff as f64 / bins as f64;
        let neighbours: f64 = (0..(3.4 / dr) as usize)
            .map(|k| {
                let (r0, r1) = (k as f64 * dr, (k + 1) as f64 * dr);
                let shell = 4.0 / 3.0 * std::f64::consts::PI * (r1.powi(3) - r0.powi(3));
                g.total[k] * shell * n / volume
            })
            .sum();
        first_shell.push(neighbours);
        series.push((name.to_string(), g.r.iter().copied().zip(g.total).collect()));
    }
    if (first_shell[0] - 12.0).abs() > 1e-9 || !(10.5..12.0).contains(&first_shell[1]) {
        return Err(fail(format!(
            "first-shell neighbours {:.4} (perfect, 12 expected) and {:.3} (polycrystal, 10.5 to 12 expected)",
            first_shell[0], first_shell[1]
        )));
    }
    let mut svg = String::new();
    crate::chart::scatter(
        "radial distribution function, FCC aluminium",
        "r (Å)",
        "g(r)",
        &series,
        crate::chart::Target::Svg(&mut svg),
    )
    .map_err(fail)?;
    std::fs::write(dir.join("rdf.svg"), svg).map_err(fail)?;
    Ok(format!(
        "<p>The radial distribution function of the same polycrystal beside a perfect crystal's, \
         as <code>texmap convert dump --rdf 8 --rdf-table gr.csv</code> writes it (OVITO's \
         Coordination analysis table): the perfect crystal's first shell holds {:.0} neighbours \
         per atom, the polycrystal's {:.2} (its grain boundaries and thermal noise broaden and \
         thin the peaks).</p>\n\
         <img src=\"materials/rdf.svg\" alt=\"g(r) of a perfect and a polycrystalline FCC crystal\" width=\"480\">\n",
        first_shell[0], first_shell[1]
    ))
}

/// The bohr radius in Å.
const BOHR: f64 = 0.529177210903;

/// The hydrogen atom's 3d_z² orbital (atomic units): `(3z² − r²) e^(−r/3) / (81 √(6π))`.
fn d_z2(p: [f64; 3]) -> f64 {
    let r2 = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
    (3.0 * p[2] * p[2] - r2) * (-r2.sqrt() / 3.0).exp()
        / (81.0 * (6.0 * std::f64::consts::PI).sqrt())
}

/// Volumetric data drawn as `texmap render --isosurface` draws a cube file's orbital: the
/// hydrogen atom's 3d_z² orbital sampled on an 81³ grid (as a cube file would hold it), its
/// two lobes at +0.004 and the torus at −0.004 bohr^−3/2. The section checks the enclosed
/// volumes against a count of the exact function's points on a grid three times finer.
fn orbital_section(dir: &Path) -> Result<String, MaterialsError> {
    use texmap_md_io::volume::Volume;
    use texmap_md_scene::isosurface::{Side, isosurface};
    let (n, half) = (81usize, 22.0f64);
    let h = 2.0 * half / (n - 1) as f64;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = [i, j, k].map(|c| -half + h * c as f64);
                data.push(d_z2(p) as f32);
            }
        }
    }
    let step = h * BOHR;
    let steps = [[step, 0.0, 0.0], [0.0, step, 0.0], [0.0, 0.0, step]];
    let vol = Volume::new([-half * BOHR; 3], steps, [n; 3], data, false, "3d_z2").map_err(fail)?;
    let level = 0.004f32;
    let mut mesh = isosurface(&vol, level, Side::Above, 1).map_err(fail)?;
    let torus = isosurface(&vol, -level, Side::Below, 2).map_err(fail)?;
    let (v_pos, v_neg) = (mesh.volume(), torus.volume());
    mesh.append(&torus);
    // The exact volumes: points of a grid three times finer inside each region (bohr³ to Å³).
    let (m, (mut pos, mut neg)) = (3 * (n - 1), (0usize, 0usize));
    let f = h / 3.0;
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let v = d_z2([i, j, k].map(|c| -half + f * (c as f64 + 0.5)));
                pos += (v > level as f64) as usize;
                neg += (v < -level as f64) as usize;
            }
        }
    }
    let cell = (f * BOHR).powi(3);
    let (q_pos, q_neg) = (pos as f64 * cell, neg as f64 * cell);
    if (v_pos / q_pos - 1.0).abs() > 0.03 || (v_neg / q_neg - 1.0).abs() > 0.03 {
        return Err(fail(format!(
            "3d_z2 at ±{level}: the isosurfaces enclose {v_pos:.1} and {v_neg:.1} Å³, the exact function {q_pos:.1} and {q_neg:.1}"
        )));
    }
    // The atom at the centre, the lobes blue and the torus red, three-quarter view.
    let mut scene = SphereScene::new(vec![
        texmap_core::shade::Material::plastic(texmap_core::glam::Vec3::splat(0.9)),
        texmap_core::shade::Material::plastic(texmap_core::glam::Vec3::new(0.05, 0.17, 0.69)),
        texmap_core::shade::Material::plastic(texmap_core::glam::Vec3::new(0.69, 0.07, 0.05)),
    ]);
    scene.push(texmap_core::glam::Vec3::ZERO, 0.5, 0);
    let mut framed = scene.clone();
    texmap_md_scene::push_framed_points(&mut framed, &mesh.positions);
    let (cam, _) = fit_camera(&Frame::new(), &framed, ViewAxis::X, None, 480, 360).map_err(fail)?;
    let options = Options::new(Method::Raycast, Lighting::default_for(&cam));
    draw_and_save(&scene, &mesh, &cam, &options, 0.8, &dir.join("orbital.png"))?;
    Ok(format!(
        "<p>Volumetric data, as <code>texmap render orbital.cube --isosurface 0.004</code> \
         draws a Gaussian cube file (or a VASP CHGCAR): the hydrogen atom's 3d<sub>z²</sub> \
         orbital (built in, sampled on an {n}³ grid), its two lobes at +{level} and its torus at \
         −{level} bohr<sup>−3/2</sup> by surface nets on the grid, {} triangles. They enclose \
         {v_pos:.1} and {v_neg:.1} Å<sup>3</sup>; the exact function, counted on a grid three \
         times finer: {q_pos:.1} and {q_neg:.1} Å<sup>3</sup>.</p>\n\
         <img src=\"materials/orbital.png\" alt=\"the 3d_z2 orbital's lobes and torus\" width=\"480\">\n",
        mesh.triangles.len()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_section_draws_rutiles_octahedra() {
        let dir = tempfile::tempdir().unwrap();
        let html = demo_section(dir.path()).unwrap();
        assert!(html.contains("72 octahedra"), "{html}");
        let img = image::open(dir.path().join("materials/rutile.png"))
            .unwrap()
            .to_rgba8();
        assert_eq!(img.dimensions(), (480, 360));
        let lit = img.pixels().filter(|p| p.0[..3] != [0, 0, 0]).count();
        assert!(lit > 20_000, "{lit}");
        assert!(html.contains("3d<sub>z²</sub>"), "{html}");
        let img = image::open(dir.path().join("materials/orbital.png"))
            .unwrap()
            .to_rgba8();
        let blue = img
            .pixels()
            .filter(|p| p.0[2] as i32 > p.0[0] as i32 + 40)
            .count();
        let red = img
            .pixels()
            .filter(|p| p.0[0] as i32 > p.0[2] as i32 + 40)
            .count();
        assert!(blue > 5_000 && red > 5_000, "{blue} blue, {red} red");
        assert!(html.contains("6 grains found"), "{html}");
        assert!(dir.path().join("materials/grains.png").exists());
        assert!(html.contains("first shell holds 12 neighbours"), "{html}");
        let svg = std::fs::read_to_string(dir.path().join("materials/rdf.svg")).unwrap();
        assert!(
            svg.starts_with("<svg") && svg.contains("polycrystal"),
            "{svg:.200}"
        );
    }
}
