//! `--model`, `--tree` and `--trees` of `texmap terrain render|fly`: parse the flags, load and
//! place the models and trees once, draw them after each terrain frame. Glue only: the drawing
//! is `texmap_terrain::models`.

use anyhow::{Context, Result};
use clap::Args;
use texmap_core::camera::Camera;
use texmap_core::sample::Sampler;
use texmap_raster::Framebuffer;
use texmap_terrain::dem::Grid;
use texmap_terrain::models::{
    self, Model, ModelError, ModelStats, Placed, PlacedTree, Placement, Tree, TreeBillboard,
};

use crate::args::{UsageError, usage};

/// Models and trees on the terrain (shared by `terrain render` and `terrain fly`).
#[derive(Args, Debug, Default)]
pub struct ModelArgs {
    /// A model on the terrain: FILE@X,Y[,HEADING[,SCALE]]. FILE is an OBJ (textured by its
    /// material's map_Kd image) or a glTF/GLB (drawn flat grey); X,Y in the grid's
    /// georeference; its lowest vertex stands on the ground there; HEADING degrees clockwise
    /// from north (default 0: the model's -z points north); SCALE metres per model unit
    /// (default 1). Repeatable.
    #[arg(
        long = "model",
        value_name = "FILE@X,Y[,HEADING[,SCALE]]",
        allow_hyphen_values = true
    )]
    pub models: Vec<String>,
    /// A tree billboard standing at X,Y (grid georeference), HEIGHT metres tall (default 12).
    /// Repeatable.
    #[arg(long = "tree", value_name = "X,Y[,HEIGHT]", allow_hyphen_values = true)]
    pub trees: Vec<String>,
    /// N tree billboards scattered over the grid's data (deterministic), besides any --tree.
    #[arg(long = "trees", value_name = "N")]
    pub forest: Option<usize>,
}

/// The placed models and trees of a run.
pub struct Objects {
    placed: Vec<Placed>,
    trees: Vec<PlacedTree>,
    billboard: TreeBillboard,
}

fn numbers(s: &str, flag: &str, what: &str, min: usize, max: usize) -> Result<Vec<f64>> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .or_else(|_| usage(format!("{flag} {s}: expected {what}")))?;
    if v.len() < min || v.len() > max {
        return usage(format!("{flag} {s}: expected {what}"));
    }
    Ok(v)
}

/// Placement and value errors are the user's (exit 2); unreadable files are not.
fn model_error(e: ModelError) -> anyhow::Error {
    match e {
        ModelError::BadValue { .. }
        | ModelError::Outside { .. }
        | ModelError::NoGround { .. }
        | ModelError::UnknownFormat { .. } => UsageError(e.to_string()).into(),
        other => anyhow::Error::new(other),
    }
}

impl ModelArgs {
    /// Whether any tree was asked for.
    pub fn any_trees(&self) -> bool {
        !self.trees.is_empty() || self.forest.is_some_and(|n| n > 0)
    }

    /// Load and place everything on `grid`.
    pub fn load(&self, grid: &Grid) -> Result<Objects> {
        let mut placed = Vec::with_capacity(self.models.len());
        for spec in &self.models {
            let Some((file, at)) = spec.rsplit_once('@') else {
                return usage(format!(
                    "--model {spec}: expected FILE@X,Y[,HEADING[,SCALE]]"
                ));
            };
            let v = numbers(at, "--model", "FILE@X,Y[,HEADING[,SCALE]]", 2, 4)?;
            let model = Model::load(file).map_err(model_error)?;
            let p = Placement {
                x: v[0],
                y: v[1],
                heading_deg: v.get(2).copied().unwrap_or(0.0),
                scale: v.get(3).copied().unwrap_or(1.0),
                ..Placement::default()
            };
            placed.push(
                Placed::new(&model, grid, &p)
                    .map_err(model_error)
                    .with_context(|| format!("--model {spec}"))?,
            );
        }
        let mut trees = Vec::new();
        for spec in &self.trees {
            let v = numbers(spec, "--tree", "X,Y[,HEIGHT]", 2, 3)?;
            trees.push(Tree {
                x: v[0],
                y: v[1],
                height: v.get(2).copied().unwrap_or(12.0),
            });
        }
        if let Some(n) = self.forest {
            trees.extend(models::forest(grid, n, 0x7e55));
        }
        let trees = models::place_trees(grid, &trees).map_err(model_error)?;
        Ok(Objects {
            placed,
            trees,
            billboard: TreeBillboard::new(),
        })
    }
}

impl Objects {
    /// The placed models (for the ray-traced reference).
    pub fn placed(&self) -> &[Placed] {
        &self.placed
    }

    /// Draw the models, then the trees, into a frame that holds the terrain.
    pub fn draw(
        &self,
        camera: &Camera,
        sampler: Sampler,
        fb: &mut Framebuffer,
    ) -> Result<ModelStats> {
        let m = models::draw_models(camera, &self.placed, sampler, fb)?;
        let t = models::draw_trees(camera, &self.trees, &self.billboard, sampler, fb)?;
        Ok(m.add(&t))
    }
}
