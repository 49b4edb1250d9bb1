//! `texmap` — render molecular-dynamics trajectories and compare sphere-drawing methods.
//!
//! The binary is the definition of the command line plus glue: every computation lives in a
//! library crate (md-io reads, impostor draws, reftrace is the reference, study compares).
//! Exit codes: 0 success, 1 runtime failure (bad file, unwritable output…), 2 bad usage.

mod args;
mod commands;
mod convert;
mod envmap;
mod envmap_bake;
mod movie;
mod output;
mod plot;
mod scene;
mod tables;
mod terrain;
mod terrain_contour;
mod terrain_dem;
mod terrain_fly;
mod terrain_grid;
mod terrain_models;
mod terrain_view;
mod terrain_viewshed;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    let cli = match args::Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            // clap prints help/version to stdout (exit 0) and usage errors to stderr (exit 2).
            let _ = e.print();
            return if e.use_stderr() {
                ExitCode::from(2)
            } else {
                ExitCode::SUCCESS
            };
        }
    };
    if let Some(n) = cli.threads {
        if n == 0 {
            eprintln!("texmap: error: --threads must be at least 1");
            return ExitCode::from(2);
        }
        if let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
        {
            eprintln!("texmap: error: cannot start {n} threads: {e}");
            return ExitCode::from(1);
        }
    }
    match commands::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if let Some(u) = e.downcast_ref::<args::UsageError>() {
                eprintln!("texmap: error: {u}");
                return ExitCode::from(2);
            }
            eprintln!("texmap: error: {e:#}");
            ExitCode::from(1)
        }
    }
}
