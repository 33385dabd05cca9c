//! What every target checks of an error: `file:line:col: message` with a
//! positive line and column, rendered as the CLI renders it without a panic.

use cellmd::input::InputError;

pub fn check_error(error: InputError) {
    assert!(error.line >= 1 && error.col >= 1 && !error.message.is_empty(), "{error}");
    assert!(error.to_string().starts_with(&format!("{}:{}:{}: ", error.path, error.line, error.col)));
    let mut out = String::new();
    miette::GraphicalReportHandler::new().render_report(&mut out, &error).expect("rendered");
}
