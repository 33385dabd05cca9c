//! `variable NAME equal EXPRESSION` arithmetic: a finite value or a message, never a crash.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match cellmd::input::evaluate_expression(text) {
        Ok(v) => assert!(v.is_finite()),
        Err(message) => assert!(!message.is_empty()),
    }
});
