//! Computed properties (`texmap_md_io::expr`) against OVITO 3.17's Compute property modifier
//! (muparser) on a LAMMPS dump OVITO wrote (tests/data/expr, gen_expr.py): 600 atoms with
//! velocities, a `c_pe` column and ids in shuffled order; eleven formulas covering every
//! operator level, the ternary, the logical operators, functions of one, two and many
//! arguments, `pi`, `N`, `index` and `id`, the unary minus against `^` and `^`'s associativity,
//! each written in texmap's names and in OVITO's. Every atom's value must be OVITO's within
//! f32 precision.

use texmap_md_io::Frame;
use texmap_md_io::expr::Expression;

use crate::support;
use support::ovito::*;

const DATA: Fixtures = Fixtures("expr");

#[test]
fn every_formula_is_ovitos() {
    let cases = DATA.json("expr_reference.json");
    let frame = DATA.frame("atoms.lammpstrj");
    assert_eq!(frame.n_atoms(), 600);
    for case in cases.as_array().unwrap() {
        let formula = case["formula"].as_str().unwrap();
        let want = numbers(&case["values"]);
        let got = Expression::parse(formula)
            .unwrap()
            .evaluate(&frame)
            .unwrap();
        let (worst, at) = got
            .iter()
            .zip(&want)
            .enumerate()
            .map(|(i, (&a, &b))| ((a as f64 - b).abs() / b.abs().max(1.0), i))
            .fold((0.0, 0), |m, x| if x.0 > m.0 { x } else { m });
        println!("{formula}: worst relative difference {worst:.1e} at atom {at}");
        // f32 inputs (7 digits) through a few operations; boolean results exactly.
        assert!(
            worst < 2e-5,
            "{formula} (OVITO: {}): atom {at}: {} vs {}",
            case["ovito"],
            got[at],
            want[at]
        );
    }
}

#[test]
fn errors_name_the_column_and_the_missing_names() {
    let e = Expression::parse("sqrt(x) + foo(2)").unwrap_err();
    assert_eq!(e.column, 11);
    assert!(e.message.contains("'foo' is not a function"), "{e}");
    let e = Expression::parse("atan2(x)").unwrap_err();
    assert!(
        e.message.contains("atan2 takes 2 argument(s), not 1"),
        "{e}"
    );
    let e = Expression::parse("x $ 2").unwrap_err();
    assert_eq!(
        (e.column, e.message.as_str()),
        (3, "unexpected character '$'")
    );
    let e = Expression::parse("x ? 1").unwrap_err();
    assert!(e.to_string().starts_with("column 6: expected ':'"), "{e}");
    let e = Expression::parse("(x) (y)").unwrap_err();
    assert_eq!(e.column, 5);
    let deep = format!("{}x{}", "(".repeat(200), ")".repeat(200));
    assert!(
        Expression::parse(&deep)
            .unwrap_err()
            .message
            .contains("deeper than")
    );
    let minus = format!("{}x", "-".repeat(500));
    assert!(Expression::parse(&minus).is_err());
    let mut frame = Frame::new();
    frame.positions = vec![[0.0; 3]; 2];
    let e = Expression::parse("vx + c_pe")
        .unwrap()
        .evaluate(&frame)
        .unwrap_err();
    assert!(
        e.message
            .starts_with("the frame has no 'vx' (it has: x, y, z, index"),
        "{e}"
    );
}

#[test]
fn functions_ovito_lacks_follow_their_definitions() {
    let mut frame = Frame::new();
    frame.positions = vec![[-1.5, 2.5, 0.0], [2.5, -0.5, 3.0]];
    let eval = |f: &str| Expression::parse(f).unwrap().evaluate(&frame).unwrap();
    assert_eq!(eval("floor(x)"), [-2.0, 2.0]);
    assert_eq!(eval("ceil(y)"), [3.0, -0.0]);
    assert_eq!(eval("rint(x)"), [-2.0, 2.0]); // ties to even
    assert_eq!(eval("!z + sign(y)"), [2.0, -1.0]);
    assert_eq!(eval("-2^2"), [-4.0, -4.0]);
    assert_eq!(eval("2^-1"), [0.5, 0.5]);
    assert_eq!(eval("1 < 2 == 1"), [1.0, 1.0]);
    assert_eq!(eval("z ? 10 : x ? 20 : 30"), [20.0, 10.0]);
}

/// Formulas typed wrong in every way (random strings over the language's characters, and
/// random cuts of valid formulas) are refused or evaluated, never a panic; the values of what
/// parses have one per atom.
#[test]
fn random_formulas_never_panic() {
    let pieces = [
        "x", "vx", "c_pe", "index", "N", "pi", "1", "2.5", "1e3", ".5", "+", "-", "*", "/", "^",
        "<", "<=", "==", "!=", "&&", "||", "!", "?", ":", "(", ")", ",", "sqrt(", "min(", "atan2(",
        "fmod(", " ", "v_s[1]", "[", "]", "$", "é",
    ];
    let valid = "atan2(y - 15, x - 15) * 180 / pi + (c_pe < -3.5 ? 2 : -x^2) && !vx";
    let mut frame = Frame::new();
    frame.positions = vec![[1.0, 2.0, 3.0], [0.0, -1.0, 0.5]];
    frame.velocities = vec![[0.5, 0.0, 0.0]; 2];
    let mut seed = 11u64;
    let mut next = |n: usize| {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 33) as usize % n
    };
    let (mut parsed, mut refused) = (0, 0);
    for case in 0..20_000 {
        let text: String = if case % 2 == 0 {
            (0..1 + next(12))
                .map(|_| pieces[next(pieces.len())])
                .collect()
        } else {
            let (a, b) = (next(valid.len()), next(valid.len()));
            valid[a.min(b)..a.max(b)].to_string()
        };
        match Expression::parse(&text) {
            Ok(e) => {
                parsed += 1;
                if let Ok(v) = e.evaluate(&frame) {
                    assert_eq!(v.len(), 2, "{text}");
                }
            }
            Err(e) => {
                refused += 1;
                assert!(e.column <= text.chars().count() + 1, "{text}: {e}");
            }
        }
    }
    assert!(
        parsed > 1000 && refused > 1000,
        "{parsed} parsed, {refused} refused"
    );
}
