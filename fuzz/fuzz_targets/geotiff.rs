//! libFuzzer target: the GeoTIFF elevation reader of texmap-terrain on arbitrary bytes. The
//! reader opens files by path (it checks the directory against the file's length before the
//! `tiff` decoder reads it), so each input is written to one scratch file first. Any outcome but
//! a grid or an error that names the file is a finding; so is a panic or an allocation beyond
//! libFuzzer's `-malloc_limit_mb`.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

fn scratch() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| std::env::temp_dir().join(format!("texmap-fuzz-{}.tif", std::process::id())))
}

fuzz_target!(|data: &[u8]| {
    let path = scratch();
    std::fs::write(path, data).expect("scratch file writable");
    match texmap_terrain::dem::geotiff::read_geotiff(path) {
        Ok(grid) => {
            assert_eq!(grid.heights().len(), grid.width() as usize * grid.height() as usize);
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains("texmap-fuzz-"), "an error that names no file: {msg}");
        }
    }
});
