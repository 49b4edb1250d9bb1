//! Wigner–Seitz defect analysis (`texmap_md_io::wigner_seitz`) against OVITO 3.17's
//! Wigner-Seitz analysis modifier on damaged iron OVITO wrote (tests/data/wigner_seitz,
//! gen_ws.py): six Frenkel pairs, a split dumbbell, a replacement sequence, two sputtered atoms,
//! the box expanded by 1 % and every atom wrapped. Every site's occupancy, every atom's site and
//! both counts must be OVITO's exactly.

use texmap_md_io::Frame;
use texmap_md_io::wigner_seitz::wigner_seitz;

use crate::support;
use support::ovito::*;

const DATA: Fixtures = Fixtures("wigner_seitz");

#[test]
fn every_site_and_atom_is_ovitos() {
    let want = DATA.json("ws_reference.json");
    let (reference, current) = (DATA.frame("ref.xyz"), DATA.frame("cur.xyz"));
    assert_eq!((reference.n_atoms(), current.n_atoms()), (2000, 1998));
    let ws = wigner_seitz(&reference, &current).unwrap();
    let occupancy: Vec<i64> = ws.occupancy.iter().map(|&o| o as i64).collect();
    assert_eq!(occupancy, integers(&want["occupancy"]));
    let sites: Vec<i64> = ws.site.iter().map(|s| s.unwrap() as i64).collect();
    assert_eq!(sites, integers(&want["site"]));
    // Atom mode's occupancy: that of the atom's site.
    let per_atom: Vec<i64> = sites.iter().map(|&s| occupancy[s as usize]).collect();
    assert_eq!(per_atom, integers(&want["atom_occupancy"]));
    assert_eq!(ws.vacancies as i64, want["vacancies"].as_i64().unwrap());
    assert_eq!(
        ws.interstitials as i64,
        want["interstitials"].as_i64().unwrap()
    );
    // Six Frenkel pairs, the dumbbell and the replacement sequence (one each), two sputtered.
    assert_eq!((ws.vacancies, ws.interstitials), (10, 8));
}

#[test]
fn the_perfect_crystal_has_no_defects_and_an_empty_reference_is_refused() {
    let reference = DATA.frame("ref.xyz");
    let ws = wigner_seitz(&reference, &reference).unwrap();
    assert_eq!((ws.vacancies, ws.interstitials), (0, 0));
    assert!(
        ws.site
            .iter()
            .enumerate()
            .all(|(i, s)| *s == Some(i as u32))
    );
    let e = wigner_seitz(&Frame::new(), &reference).unwrap_err();
    assert!(e.to_string().contains("no atoms to serve as sites"));
}
