//! Topology parsing (sections, particles, bonds, bodies and their surface checks).
#![no_main]

use libfuzzer_sys::fuzz_target;

mod common;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    if let Err(e) = cellmd::topology::parse_topology(&cellmd::input::SourceFile::new("fuzz.top", text)) {
        common::check_error(e);
    }
});
