//! The expression language (deck `variable … equal`, expression parameters,
//! `custom` force fields): parsing, evaluation, symbolic derivatives and the
//! WGSL emitter give a value or a message with a span inside the text, never
//! a crash or a hang.
#![no_main]

use cellmd::expr::{parse, Ref};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let in_text = |e: &cellmd::expr::ExprError| {
        assert!(!e.message.is_empty() && e.span.start <= e.span.end && e.span.end <= text.len(), "{e:?} in {text:?}");
    };
    match parse(text) {
        Ok(expr) => {
            // Every name is a variable worth 1.5; thermo columns are unknown.
            let mut lookup = |r: Ref| match r {
                Ref::Name(_) => Ok(1.5),
                Ref::Thermo(c) => Err(format!("no thermo column `{c}`")),
            };
            if let Err(e) = expr.eval(&mut lookup) {
                in_text(&e);
            }
            for var in ["x", "t"] {
                let derivative = expr.derivative(var);
                let _ = derivative.eval(&mut lookup);
            }
            if let Err(e) = cellmd::expr::wgsl::wgsl(&expr, &|name| Some(format!("v_{name}"))) {
                in_text(&e);
            }
        }
        Err(e) => in_text(&e),
    }
});
