//! VASP volumetric files (CHGCAR, CHG, PARCHG, LOCPOT, ELFCAR, AECCAR0/1/2): a POSCAR block,
//! then grids (see [`crate::volume`] for the layout, units and names). The grid walk here
//! serves both [`crate::volume::read_volumes`] (values kept) and the VASP trajectory reader,
//! which reads such a file as one frame, the structure, and walks its grids so that damage
//! there is an error for that frame.

use crate::error::Error;
use crate::frame::Frame;
use crate::parse::{fields, parse_f64, parse_usize, trim};
use crate::text::{Ctx, LineReader, Pos};
use crate::volume::{Budget, MAX_POINTS, Values, VaspQuantity, walk_values};
use std::io::Read;

/// One grid as read: steps (lattice vectors / N, Å), dims and values (x fastest).
pub(crate) struct Grid {
    pub steps: [[f64; 3]; 3],
    pub dims: [usize; 3],
    pub data: Vec<f32>,
}

/// The dimensions on a grid line: exactly three positive integers.
pub(crate) fn grid_dims(line: &[u8]) -> Option<[usize; 3]> {
    let mut f = fields(line);
    let mut d = [0usize; 3];
    for x in &mut d {
        *x = parse_usize(f.next()?).filter(|n| *n > 0)?;
    }
    f.next().is_none().then_some(d)
}

/// Checks a grid line's dimensions: at most [`MAX_POINTS`] points, and what the file holds.
pub(crate) fn check_dims(
    ctx: &Ctx,
    pos: Pos,
    line: &[u8],
    dims: [usize; 3],
    budget: &Budget,
) -> Result<usize, Error> {
    dims.iter()
        .try_fold(1usize, |a, &d| a.checked_mul(d))
        .filter(|n| *n <= MAX_POINTS && *n <= budget.max_values())
        .ok_or_else(|| {
            ctx.parse(
                pos,
                line,
                trim(line),
                "grid dimensions the file can hold: at most 2^30 points, each of ≥ 2 bytes",
            )
        })
}

/// Reads a VASP volumetric file: the structure into `frame`, then every grid, its values
/// divided by the cell volume for a density.
pub(crate) fn read<R: Read>(
    lines: &mut LineReader<R>,
    ctx: &Ctx,
    frame: &mut Frame,
    quantity: VaspQuantity,
    budget: &Budget,
) -> Result<Vec<Grid>, Error> {
    let start = lines.pos();
    if !crate::vasp::read_structure(lines, ctx, frame)? {
        return Err(ctx.truncated(
            start,
            "a POSCAR block (comment, scaling factor, lattice, species, coordinates)".into(),
        ));
    }
    let Some(cell) = frame.cell else {
        return Err(ctx.truncated(start, "a POSCAR block with its lattice".into()));
    };
    let lattice = cell.matrix();
    const DIMS: &str = "a blank line, then the grid dimensions NGX NGY NGZ";
    let dims = loop {
        let (pos, line) = crate::text::need_line(lines, ctx, DIMS)?;
        if trim(line).is_empty() {
            continue;
        }
        match grid_dims(line) {
            Some(d) => {
                check_dims(ctx, pos, line, d, budget)?;
                break d;
            }
            None => return Err(ctx.parse(pos, line, trim(line), DIMS)),
        }
    };
    let scale = match quantity {
        VaspQuantity::Density => 1.0 / cell.volume(),
        _ => 1.0,
    };
    let mut data = Vec::new();
    let walk = Walk {
        dims,
        n_atoms: frame.n_atoms(),
        scale,
        parse: true,
    };
    walk.grids(lines, ctx, budget, Some(&mut data))?;
    let steps: [[f64; 3]; 3] = std::array::from_fn(|a| lattice[a].map(|x| x / dims[a] as f64));
    Ok(data
        .into_iter()
        .map(|data| Grid { steps, dims, data })
        .collect())
}

/// A walk over a file's grids, from the values after the first grid line.
pub(crate) struct Walk {
    /// The first grid's dimensions, which every later grid repeats.
    pub dims: [usize; 3],
    /// Atoms of the structure: the count of per-atom moments between grids.
    pub n_atoms: usize,
    /// Factor applied to kept values.
    pub scale: f64,
    /// Parse every value (else count them: a scan).
    pub parse: bool,
}

impl Walk {
    /// Walks the grids (the first grid line was read) to the end of the file; with
    /// `keep`, every grid's values are pushed there. Between grids come augmentation
    /// occupancies (`augmentation occupancies <atom> <count>` and that many numbers), blank
    /// lines and a line of per-atom moments (one number per atom, over one or more lines).
    pub fn grids<R: Read>(
        &self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        budget: &Budget,
        mut keep: Option<&mut Vec<Vec<f32>>>,
    ) -> Result<(), Error> {
        let [nx, ny, nz] = self.dims;
        let n = nx * ny * nz;
        let scan = || {
            if self.parse {
                Values::Check
            } else {
                Values::Count
            }
        };
        for set in 1.. {
            let what = format!("data set {set} ({nx}x{ny}x{nz} points)");
            match keep.as_deref_mut() {
                Some(sets) => {
                    let mut v = Vec::with_capacity(n.min(budget.reserve_values()));
                    walk_values(lines, ctx, n, self.scale, &mut Values::Keep(&mut v), &what)?;
                    sets.push(v);
                }
                None => walk_values(lines, ctx, n, self.scale, &mut scan(), &what)?,
            }
            if !self.between(lines, ctx, set, budget, scan)? {
                break;
            }
        }
        Ok(())
    }

    /// Reads what follows grid `set` up to the next grid's dimensions line (true) or the end
    /// of the file (false).
    fn between<R: Read>(
        &self,
        lines: &mut LineReader<R>,
        ctx: &Ctx,
        set: usize,
        budget: &Budget,
        scan: impl Fn() -> Values<'static>,
    ) -> Result<bool, Error> {
        const BETWEEN: &str = "augmentation occupancies, one moment per atom or the grid \
                               dimensions of the next data set (as the first's)";
        const AUGMENTATION: &str = "augmentation occupancies <atom> <count of values>";
        let mut moments = 0usize;
        loop {
            let p = lines.pos();
            let Some((pos, line)) = lines.next_line().map_err(|e| ctx.io(p, e))? else {
                if moments > 0 {
                    let [nx, ny, nz] = self.dims;
                    return Err(ctx.truncated(
                        p,
                        format!("the grid dimensions {nx} {ny} {nz} of data set {}", set + 1),
                    ));
                }
                return Ok(false);
            };
            let t = trim(line);
            if t.is_empty() {
                continue;
            }
            if let Some(d) = grid_dims(line) {
                if d != self.dims || (moments != 0 && moments != self.n_atoms) {
                    return Err(ctx.parse(pos, line, t, BETWEEN));
                }
                return Ok(true);
            }
            if t.len() >= 12 && t[..12].eq_ignore_ascii_case(b"augmentation") {
                let count = fields(line)
                    .last()
                    .and_then(parse_usize)
                    .filter(|c| *c <= budget.max_values())
                    .ok_or_else(|| ctx.parse(pos, line, t, AUGMENTATION))?;
                walk_values(
                    lines,
                    ctx,
                    count,
                    1.0,
                    &mut scan(),
                    "augmentation occupancies",
                )?;
                continue;
            }
            for f in fields(line) {
                moments += 1;
                if parse_f64(f).is_none() || moments > self.n_atoms {
                    return Err(ctx.parse(pos, line, f, BETWEEN));
                }
            }
        }
    }
}
