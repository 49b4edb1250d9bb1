//! The per-frame analyses a plan runs before styling (`MolOptions::coordination` after
//! `MolOptions::replicate`), against OVITO 3.17: the atoms `prop coordination < 12` keeps of a
//! jiggled FCC crystal with a vacancy cluster are exactly those OVITO's Coordination analysis
//! counts fewer than 12 neighbours for (md-io's cna fixture and reference), and replicating the
//! periodic crystal first changes no atom's count: every copy of an atom has its count. The
//! slice, clusters, atomic strain and centrosymmetry in a plan, each against OVITO too.

use std::path::Path;

use texmap_md_io::{Frame, Selection, Trajectory};
use texmap_md_scene::{COORDINATION, MolOptions, MolPlan, SceneBuilder, SphereScene, StyleOptions};

fn cna(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../md-io/tests/data/cna")
        .join(name)
}

fn fcc() -> Frame {
    let mut t = Trajectory::open(cna("crystals.xyz.gz")).unwrap();
    let mut f = Frame::new();
    assert!(t.read_next(&mut f).unwrap());
    f
}

/// The frame after the plan's steps, and the scene drawn from it.
fn build(options: MolOptions) -> (Frame, SphereScene) {
    let mut plan = MolPlan::new(options).unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let (mut frame, mut scene) = (fcc(), SphereScene::default());
    plan.build(&mut builder, &mut frame, &mut scene).unwrap();
    (frame, scene)
}

#[test]
fn the_under_coordinated_atoms_are_ovitos() {
    let text = std::fs::read_to_string(cna("coordination_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ovito: Vec<u64> = v["frames"][0]["2.9"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .collect();
    let (frame, scene) = build(MolOptions {
        coordination: Some(2.9),
        select: Some(Selection::parse("prop coordination < 12").unwrap()),
        ..MolOptions::default()
    });
    let want: Vec<[f32; 3]> = (0..ovito.len())
        .filter(|&i| ovito[i] < 12)
        .map(|i| frame.positions[i])
        .collect();
    assert_eq!(want.len(), 24);
    let got: Vec<[f32; 3]> = scene.centers.iter().map(|c| c.to_array()).collect();
    assert_eq!(got, want);
}

#[test]
fn replicating_first_keeps_every_count() {
    let (one, _) = build(MolOptions {
        coordination: Some(4.0),
        ..MolOptions::default()
    });
    let (many, _) = build(MolOptions {
        coordination: Some(4.0),
        replicate: Some([2, 1, 2]),
        ..MolOptions::default()
    });
    let counts = |f: &Frame| f.property(COORDINATION).unwrap().to_vec();
    assert_eq!(counts(&many), counts(&one).repeat(4));
}

/// `MolOptions::slice` draws exactly the atoms OVITO 3.17's Slice modifier keeps, in order, for
/// half-spaces and slabs, inverted or not, with normals of any length (tests/data/cna
/// slice_reference.json, by gen_slice.py). The frame itself keeps every atom, so analyses
/// colour the cut as the whole crystal: no atom of a slab through the perfect crystal far from
/// the vacancies is drawn as under-coordinated.
#[test]
fn the_slice_draws_ovitos_atoms() {
    use texmap_md_scene::Slice;
    let text = std::fs::read_to_string(cna("slice_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let all = fcc();
    for c in v["configs"].as_array().unwrap() {
        let f = |x: &serde_json::Value| x.as_f64().unwrap();
        let normal = c["normal"].as_array().unwrap();
        let slice = Slice {
            normal: [f(&normal[0]), f(&normal[1]), f(&normal[2])],
            distance: f(&c["distance"]),
            width: f(&c["width"]),
            invert: c["inverse"].as_bool().unwrap(),
        };
        let kept: Vec<usize> = c["kept"]
            .as_array()
            .unwrap()
            .iter()
            .map(|i| i.as_u64().unwrap() as usize)
            .collect();
        let (frame, scene) = build(MolOptions {
            slice: Some(slice),
            ..MolOptions::default()
        });
        assert_eq!(frame.n_atoms(), all.n_atoms());
        let want: Vec<[f32; 3]> = kept.iter().map(|&i| all.positions[i]).collect();
        let got: Vec<[f32; 3]> = scene.centers.iter().map(|c| c.to_array()).collect();
        assert_eq!(got, want, "{slice:?}");
    }
    // A thin (100) slab at the box's edge, away from the central vacancy cluster: with the
    // coordination counted on the whole crystal, every drawn atom has 12 neighbours.
    let slab = Slice {
        normal: [1.0, 0.0, 0.0],
        distance: 2.0,
        width: 3.0,
        invert: false,
    };
    let (_, drawn) = build(MolOptions {
        slice: Some(slab),
        ..MolOptions::default()
    });
    assert!(drawn.centers.len() >= 50, "{}", drawn.centers.len());
    let (frame, scene) = build(MolOptions {
        slice: Some(slab),
        coordination: Some(2.9),
        select: Some(Selection::parse("prop coordination < 12").unwrap()),
        ..MolOptions::default()
    });
    assert!(frame.n_atoms() > 1000);
    let under = scene.centers.len();
    assert_eq!(under, 0, "{under} under-coordinated");
}

/// `MolOptions::clusters` with a selection of the clustered atoms: the copper precipitate in
/// iron that `--clusters 2.9 --cluster-atoms 'element Cu' --select 'prop cluster == 0'` draws
/// is exactly OVITO 3.17's largest cluster (md-io's clusters fixture), and `ColorBy::Cluster`
/// gives each of the largest clusters its own palette colour, the iron the element colour.
#[test]
fn the_largest_copper_cluster_is_ovitos() {
    use texmap_md_scene::{CLUSTER, ClusterOptions, ColorBy, type_color};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/clusters");
    let text = std::fs::read_to_string(dir.join("clusters_reference.json")).unwrap();
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let ovito: Vec<i64> = v[2]["ids"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_i64().unwrap())
        .collect();
    let read = || {
        let mut f = Frame::new();
        assert!(
            Trajectory::open(dir.join("fecu.xyz"))
                .unwrap()
                .read_next(&mut f)
                .unwrap()
        );
        f
    };
    let options = |select: Option<&str>| MolOptions {
        clusters: Some(ClusterOptions {
            cutoff: 2.9,
            atoms: Some(Selection::parse("element Cu").unwrap()),
        }),
        select: select.map(|s| Selection::parse(s).unwrap()),
        ..MolOptions::default()
    };
    let mut plan = MolPlan::new(options(Some("prop cluster == 0"))).unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let (mut frame, mut scene) = (read(), SphereScene::default());
    plan.build(&mut builder, &mut frame, &mut scene).unwrap();
    let want: Vec<[f32; 3]> = (0..ovito.len())
        .filter(|&i| ovito[i] == 0)
        .map(|i| frame.positions[i])
        .collect();
    assert_eq!(want.len(), 81);
    let got: Vec<[f32; 3]> = scene.centers.iter().map(|c| c.to_array()).collect();
    assert_eq!(got, want);
    assert_eq!(frame.property(CLUSTER).unwrap().len(), frame.n_atoms());

    // Colours: cluster k has palette colour k; iron (cluster -1) its element colour.
    let mut plan = MolPlan::new(options(None)).unwrap();
    let style = StyleOptions {
        color_by: ColorBy::Cluster,
        ..StyleOptions::default()
    };
    let mut builder = SceneBuilder::new(&style).unwrap();
    let (mut frame, mut scene) = (read(), SphereScene::default());
    plan.build(&mut builder, &mut frame, &mut scene).unwrap();
    let ids = frame.property(CLUSTER).unwrap().to_vec();
    // The palette's material of an sRGB colour: quantised to 8 bits, made linear.
    let linear = |c: [f32; 3]| {
        c.map(|x| {
            let x = (x.clamp(0.0, 1.0) * 255.0).round() / 255.0;
            texmap_core::color::srgb_to_linear(x)
        })
    };
    let mut clustered = 0;
    for (i, &id) in ids.iter().enumerate() {
        let want = if id >= 0.0 {
            clustered += 1;
            type_color(id as usize)
        } else {
            texmap_md_io::atom_element(&frame, i).color()
        };
        let got = scene.materials[scene.kinds[i] as usize]
            .base_color
            .to_array();
        let want = linear(want);
        assert!(
            (0..3).all(|k| (got[k] - want[k]).abs() < 1e-6),
            "atom {i}, cluster {id}: {got:?} vs {want:?}"
        );
    }
    assert!(clustered > 200 && clustered < ids.len() / 5, "{clustered}");
}

/// `MolOptions::radius_from`: the atoms of a PQR file PDB2PQR wrote (AMBER radii, md-io's
/// fixture) are drawn at the file's radii, and those whose radius is 0 (hydroxyl and polar
/// hydrogens in AMBER's set) at their element's; a property the frame lacks is an error naming
/// those it has.
#[test]
fn pqr_radii_are_drawn() {
    use texmap_md_scene::MolError;
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/pdb2pqr_amber.pqr");
    let read = || {
        let mut f = Frame::new();
        assert!(Trajectory::open(&file).unwrap().read_next(&mut f).unwrap());
        f
    };
    let pqr = read();
    let radii = pqr.property("radius").unwrap().to_vec();
    let mut plan = MolPlan::new(MolOptions {
        radius_from: Some("radius".into()),
        ..MolOptions::default()
    })
    .unwrap();
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let (mut frame, mut scene) = (read(), SphereScene::default());
    plan.build(&mut builder, &mut frame, &mut scene).unwrap();
    let (mut from_file, mut from_element) = (0, 0);
    for (i, &r) in radii.iter().enumerate() {
        if r > 0.0 {
            from_file += 1;
            assert_eq!(scene.radii[i], r, "atom {i}");
        } else {
            from_element += 1;
            let e = texmap_md_io::atom_element(&frame, i);
            assert!((scene.radii[i] - e.vdw_radius()).abs() < 1e-6, "atom {i}");
        }
    }
    assert!(
        from_file > 100 && from_element > 0,
        "{from_file} {from_element}"
    );
    let mut plan = MolPlan::new(MolOptions {
        radius_from: Some("sigma".into()),
        ..MolOptions::default()
    })
    .unwrap();
    let err = plan
        .build(&mut builder, &mut read(), &mut SphereScene::default())
        .unwrap_err();
    assert!(matches!(&err, MolError::NoRadiusProperty { .. }));
    assert!(err.to_string().contains("it has charge, radius"), "{err}");
}

/// `MolOptions::strain` and `MolOptions::centrosymmetry` in a plan, on md-io's strain fixture
/// (a sheared, bulged copper slab OVITO wrote, and OVITO's values): the reference is the first
/// frame built, or the frame given to `set_displacement_reference`, and the second frame's
/// `shear_strain` is OVITO's either way; with `--align` on every atom the frames are
/// superposed, which changes no strain (it is invariant under the rigid motion); `prop
/// centrosymmetry > 4` keeps OVITO's defect atoms (the surfaces and the lone atoms).
#[test]
fn strain_and_centrosymmetry_in_a_plan_are_ovitos() {
    use texmap_md_io::centrosymmetry::CspMode;
    use texmap_md_scene::{Alignment, CENTROSYMMETRY, CentroOptions, SHEAR_STRAIN};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../md-io/tests/data/strain");
    let json = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(name)).unwrap()).unwrap()
    };
    let read = |name: &str| {
        let mut f = Frame::new();
        assert!(
            Trajectory::open(dir.join(name))
                .unwrap()
                .read_next(&mut f)
                .unwrap()
        );
        f
    };
    let ovito: Vec<f64> = json("strain_reference.json")["shear"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let check = |frame: &Frame, what: &str| {
        let got = frame.property(SHEAR_STRAIN).unwrap();
        let worst = got
            .iter()
            .zip(&ovito)
            .map(|(a, b)| (*a as f64 - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 5e-6, "{what}: worst {worst}");
    };
    let options = |align: bool| MolOptions {
        strain: Some(3.0),
        align: align.then(|| Alignment::on_first_frame(Selection::parse("all").unwrap())),
        ..MolOptions::default()
    };
    let mut builder = SceneBuilder::new(&StyleOptions::default()).unwrap();
    let mut scene = SphereScene::default();
    // The first frame built is the reference: zero strain there, OVITO's in the second.
    let mut plan = MolPlan::new(options(false)).unwrap();
    let mut first = read("ref.xyz");
    plan.build(&mut builder, &mut first, &mut scene).unwrap();
    assert!(
        first
            .property(SHEAR_STRAIN)
            .unwrap()
            .iter()
            .all(|v| v.abs() < 1e-6)
    );
    let mut second = read("cur.xyz");
    plan.build(&mut builder, &mut second, &mut scene).unwrap();
    check(&second, "first frame as reference");
    // The reference given, the frames aligned on it.
    let mut plan = MolPlan::new(options(true)).unwrap();
    plan.set_displacement_reference(&mut read("ref.xyz"))
        .unwrap();
    let mut only = read("cur.xyz");
    plan.build(&mut builder, &mut only, &mut scene).unwrap();
    check(&only, "reference given, aligned");
    // A frame of other atoms than the reference is the build's error.
    let mut short = read("cur.xyz");
    short.positions.pop();
    let e = plan
        .build(&mut builder, &mut short, &mut scene)
        .unwrap_err();
    assert!(e.to_string().starts_with("atomic strain: "), "{e}");

    // Centrosymmetry: the atoms above 4 Å² are OVITO's.
    let csp = &json("centro_reference.json")[3];
    assert_eq!(csp["file"], "cur.xyz");
    let want: Vec<f64> = csp["csp"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    let mut plan = MolPlan::new(MolOptions {
        centrosymmetry: Some(CentroOptions {
            neighbours: 12,
            mode: CspMode::Conventional,
        }),
        select: Some(Selection::parse("prop centrosymmetry > 4").unwrap()),
        ..MolOptions::default()
    })
    .unwrap();
    let mut frame = read("cur.xyz");
    plan.build(&mut builder, &mut frame, &mut scene).unwrap();
    let kept: Vec<[f32; 3]> = (0..want.len())
        .filter(|&i| want[i] > 4.0)
        .map(|i| frame.positions[i])
        .collect();
    // Two (001) surface layers of 8 x 8 x 2 atoms, and the five atoms in the vacuum.
    assert_eq!(kept.len(), 261);
    let got: Vec<[f32; 3]> = scene.centers.iter().map(|c| c.to_array()).collect();
    assert_eq!(got, kept);
    assert_eq!(frame.property(CENTROSYMMETRY).unwrap().len(), want.len());
}
