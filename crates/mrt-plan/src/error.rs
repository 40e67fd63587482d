//! The error type of `mrt-plan`.

/// What can go wrong when building a model or feeding it readings.
///
/// Messages are lower-case and name the parameter or the reading at fault.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A model parameter is out of its range (non-positive radius, NaN speed, ...).
    #[error("invalid parameter `{name}` = {value}: expected {expected}")]
    InvalidParameter {
        /// The parameter's name, as in the constructor.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What the value must be, e.g. "a finite value > 0".
        expected: &'static str,
    },
    /// Two omni wheels share a mounting angle: the three wheel speeds no longer determine the
    /// twist (the kinematic matrix is singular).
    #[error(
        "omni wheel angles {angles:?} (rad) give a singular kinematic matrix: two wheels coincide"
    )]
    SingularWheelLayout {
        /// The mounting angles given, radians.
        angles: [f64; 3],
    },
    /// An input reading is NaN or infinite.
    #[error("non-finite input `{name}`")]
    NonFiniteInput {
        /// Which input.
        name: &'static str,
    },
    /// SPIKE found no path (`mrt_plan::spike`).
    #[error("no path: {reason}")]
    NoPath {
        /// Why: the start or the goal shut in, or nothing joining them.
        reason: &'static str,
    },
    /// SPIKE would need more cells than it may make (`mrt_plan::spike::MAX_CELLS`): the map is
    /// too large for its accuracy.
    #[error("the plan needs more than {cells} cells: use a coarser accuracy or a smaller map")]
    TooManyCells {
        /// The limit.
        cells: usize,
    },
    /// "Behind the ball" needs a line from the goal through the ball.
    #[error("ball and goal coincide at ({x}, {y}): no line to stand behind")]
    BallOnGoal {
        /// x of the ball (and goal).
        x: f64,
        /// y of the ball (and goal).
        y: f64,
    },
}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(PlanError::InvalidParameter { name, value, expected: "a finite value > 0" })
    }
}
