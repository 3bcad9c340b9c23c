//! Why lights or their settings were refused.

/// Why a light set was refused.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum LightError {
    #[error("light {index}: {field} is {value}, which is not finite")]
    NonFinite {
        index: usize,
        field: &'static str,
        value: String,
    },
    #[error("light {index}: {field} is {value}; it must be {expected}")]
    OutOfRange {
        index: usize,
        field: &'static str,
        value: f32,
        expected: &'static str,
    },
    #[error("light settings: {0}")]
    Settings(String),
}
