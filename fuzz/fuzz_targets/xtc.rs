//! libFuzzer target: the XTC reader on arbitrary bytes (see common.rs for what is checked).
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;
use texmap_md_io::Format;

fuzz_target!(|data: &[u8]| common::run(data, Format::Xtc));
