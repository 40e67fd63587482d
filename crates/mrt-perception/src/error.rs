//! The error type of `mrt-perception`.

/// What can go wrong when building a sensor model or feeding it readings.
///
/// Messages are lower-case and name the parameter or the reading at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PerceptionError {
    /// A model parameter is out of its range (non-positive distance, NaN tolerance, ...).
    #[error("invalid parameter `{name}` = {value}: expected {expected}")]
    InvalidParameter {
        /// The parameter's name, as in the constructor.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What the value must be, e.g. "a finite value > 0".
        expected: &'static str,
    },
    /// An input reading is NaN or infinite.
    #[error("non-finite input `{name}`")]
    NonFiniteInput {
        /// Which input.
        name: &'static str,
    },
    /// The two mice disagree along the line that joins them (MRT manual §4.1: `x̄_r = x̄_l`).
    /// At least one of the four readings is wrong (§4.2).
    #[error(
        "mice readings inconsistent: x_left = {x_left}, x_right = {x_right} differ by more than {tolerance}"
    )]
    MiceInconsistent {
        /// `x̄_l`, metres.
        x_left: f64,
        /// `x̄_r`, metres.
        x_right: f64,
        /// The tolerance of the check, metres.
        tolerance: f64,
    },
    /// The error reduction of §4.2 cannot restore the constraint: the two lateral readings
    /// have opposite signs, or the short one is zero (its direction is lost).
    #[error("mice readings cannot be reduced: x_left = {x_left}, x_right = {x_right}")]
    MiceIrreducible {
        /// `x̄_l`, metres.
        x_left: f64,
        /// `x̄_r`, metres.
        x_right: f64,
    },
}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, PerceptionError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PerceptionError::InvalidParameter { name, value, expected: "a finite value > 0" })
    }
}

/// Checks that `value` is finite and `>= 0`.
pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<f64, PerceptionError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(PerceptionError::InvalidParameter { name, value, expected: "a finite value >= 0" })
    }
}
