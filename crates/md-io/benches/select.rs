//! Selection speed on a million atoms: `cargo bench -p texmap-md-io --bench select`.
//!
//! A synthetic system of 1,000,000 atoms: 25,000 alanines (10 atoms each, 250k atoms), 249,900
//! waters (OW HW1 HW2), and 100 ligand atoms (resname LIG), at seeded positions in a 200 Å cube;
//! then `within`/`around` again with that cube as the periodic box.

use criterion::{Criterion, criterion_group, criterion_main};
use texmap_md_io::{Element, Frame, Label, Selection};

fn system() -> Frame {
    let mut f = Frame::new();
    let mut state = 0x5e1ec7u64;
    let mut r = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32 * 200.0
    };
    let push = |f: &mut Frame, name: &str, res: &str, resid: i64, el: &str, p: [f32; 3]| {
        f.positions.push(p);
        f.names.push(Label::new(name).unwrap());
        f.res_names.push(Label::new(res).unwrap());
        f.res_ids.push(resid);
        f.elements.push(Element::from_symbol(el).unwrap());
    };
    let ala = ["N", "H", "CA", "HA", "CB", "HB1", "HB2", "HB3", "C", "O"];
    for k in 0..25_000 {
        for a in ala {
            push(&mut f, a, "ALA", k + 1, &a[..1], [r(), r(), r()]);
        }
    }
    for k in 0..249_966 {
        for (a, e) in [("OW", "O"), ("HW1", "H"), ("HW2", "H")] {
            push(&mut f, a, "SOL", 25_001 + k, e, [r(), r(), r()]);
        }
    }
    for _ in 0..102 {
        push(
            &mut f,
            "C1",
            "LIG",
            300_000,
            "C",
            [r() / 10.0 + 90.0, r() / 10.0 + 90.0, r() / 10.0 + 90.0],
        );
    }
    assert_eq!(f.n_atoms(), 1_000_000);
    f
}

fn bench(c: &mut Criterion) {
    let frame = system();
    let mut g = c.benchmark_group("select_1M");
    g.sample_size(20);
    for text in [
        "not resname SOL",
        "name CA and resid 1:5000",
        "protein and not name H*",
        "element O and not water",
        "within 5 of resname LIG",
        "water and around 3.5 protein",
    ] {
        let sel = Selection::parse(text).unwrap();
        g.bench_function(text, |b| b.iter(|| sel.evaluate(&frame).unwrap()));
    }
    // The same system in a periodic 200 Å box: within/around through its faces.
    let mut boxed = frame.clone();
    boxed.cell = Some(texmap_md_io::UnitCell::orthorhombic(200.0, 200.0, 200.0).unwrap());
    for text in ["within 5 of resname LIG", "water and around 3.5 protein"] {
        let sel = Selection::parse(text).unwrap();
        g.bench_function(format!("{text} (periodic box)"), |b| {
            b.iter(|| sel.evaluate(&boxed).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
