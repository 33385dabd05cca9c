//! Deck validation (`cellmd check`) of arbitrary text, in the bad-deck
//! directory so that `topology base.top` and friends resolve.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

mod common;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let file = cellmd::input::SourceFile::new("fuzz.in", text);
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/decks/bad"));
    if let Err(e) = cellmd::deck::validate(&file, dir, &[]) {
        common::check_error(e);
    }
});
