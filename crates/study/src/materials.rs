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
    for p in &mesh.positions {
        framed.push(*p, 0.0, 0);
    }
    let (cam, _) = fit_camera(&frame, &framed, ViewAxis::Auto, None, 480, 360).map_err(fail)?;
    let lighting = Lighting::default_for(&cam);
    let mut options = Options::new(Method::Raycast, lighting);
    options.draw_bonds = plan.draws_bonds();
    let mut render = texmap_impostor::render(&scene, &cam, &options);
    texmap_md_scene::surface::draw_mesh(
        &mesh,
        &scene.materials,
        &cam,
        &lighting,
        0.85,
        &mut render.frame,
    )
    .map_err(fail)?;
    let (w, h) = (render.frame.width(), render.frame.height());
    let raw: Vec<u8> = render.frame.color.iter().flatten().copied().collect();
    let png = dir.join("rutile.png");
    image::RgbaImage::from_raw(w, h, raw)
        .ok_or_else(|| fail("a frame of its own size"))?
        .save(&png)
        .map_err(fail)?;
    // What the picture holds: 3 x 3 x 4 cells of two Ti, each an octahedron of 8 faces.
    let titanium = 2 * 3 * 3 * 4;
    let faces = mesh.triangles.len();
    let volume = mesh.volume() / titanium as f64;
    if faces != 8 * titanium || (volume - 9.908).abs() > 0.01 {
        return Err(fail(format!(
            "expected {titanium} octahedra of 8 faces and 9.908 Å³, drew {faces} faces of {volume:.3} Å³ each"
        )));
    }
    Ok(format!(
        "<p>Rutile TiO<sub>2</sub> (built in: its six atoms of the unit cell), 3 x 3 x 4 cells, \
         drawn as VESTA draws a crystal: the TiO<sub>6</sub> coordination polyhedra \
         (<code>--rep 'element Ti=polyhedra'</code>) and the O atoms as balls and sticks \
         (<code>--rep 'element O=ball-stick' --replicate 3,3,4</code>). {titanium} octahedra of \
         8 faces each, {volume:.3} Å<sup>3</sup> each (scipy's ConvexHull of the same six O \
         atoms: 9.908 Å<sup>3</sup>). The same pipeline reads VASP POSCAR/XDATCAR, \
         crystallographic CIF (expanded by its symmetry operations) and LAMMPS data files, and \
         draws arrows (<code>--rep 'all=arrows'</code>), trails and measurements.</p>\n\
         <img src=\"materials/rutile.png\" alt=\"rutile's TiO6 octahedra\" width=\"480\">\n"
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
    }
}
