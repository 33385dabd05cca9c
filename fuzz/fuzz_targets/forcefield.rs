//! Force-field parsing (the reader takes a path: the input is written to a
//! scratch file).
#![no_main]

use cellmd::forcefield::{check_pair_types, load_forcefield, ForceField};
use cellmd::units::UnitSystem;
use libfuzzer_sys::fuzz_target;

mod common;

fuzz_target!(|data: &[u8]| {
    let path = std::env::temp_dir().join(format!("cellmd-fuzz-{}.ff", std::process::id()));
    std::fs::write(&path, data).expect("scratch file");
    let mut ff = ForceField::default();
    let parsed = load_forcefield(&path, None, UnitSystem::Cell, &mut ff, &mut Vec::new()).and_then(|()| check_pair_types(&ff));
    if let Err(e) = parsed {
        common::check_error(e);
    }
});
