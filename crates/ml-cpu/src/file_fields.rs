//! The checks of a file's numbers, each naming the field as the file spells it (`what`): the
//! scene file's own fields and the sections its features read (`scene_section`) share them.

use crate::error::Number;
use crate::limits::MAX_INTENSITY;
use std::ops::RangeInclusive;
use thiserror::Error;

/// A number a file gives that its field does not take.
#[derive(Debug, Error)]
pub enum FieldProblem {
    #[error("{what} {value} is not a finite number")]
    NotFinite { what: &'static str, value: f32 },
    #[error("{what} {value} must be greater than 0")]
    NotPositive { what: &'static str, value: f32 },
    #[error("{what} {value} must not be negative")]
    Negative { what: &'static str, value: f32 },
    #[error("{what} {value} must lie in [0, 1]")]
    NotUnit { what: &'static str, value: f32 },
    #[error("{what} {} is out of range: use {} to {}", Number(*value), Number(*range.start()), Number(*range.end()))]
    OutOfRange { what: &'static str, value: f32, range: RangeInclusive<f32> },
}

pub fn finite(what: &'static str, value: f32) -> Result<f32, FieldProblem> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(FieldProblem::NotFinite { what, value })
    }
}

/// `value`, refused outside `range` (finite already).
pub fn within(what: &'static str, value: f32, range: RangeInclusive<f32>) -> Result<f32, FieldProblem> {
    if range.contains(&value) {
        Ok(value)
    } else {
        Err(FieldProblem::OutOfRange { what, value, range })
    }
}

/// A light's colour or the ambient term: not negative, at most MAX_INTENSITY.
pub fn intensity(what: &'static str, value: f32) -> Result<f32, FieldProblem> {
    within(what, non_negative(what, value)?, 0.0..=MAX_INTENSITY)
}

pub fn positive(what: &'static str, value: f32) -> Result<f32, FieldProblem> {
    if finite(what, value)? > 0.0 {
        Ok(value)
    } else {
        Err(FieldProblem::NotPositive { what, value })
    }
}

pub fn non_negative(what: &'static str, value: f32) -> Result<f32, FieldProblem> {
    if finite(what, value)? >= 0.0 {
        Ok(value)
    } else {
        Err(FieldProblem::Negative { what, value })
    }
}

pub fn unit(what: &'static str, value: f32) -> Result<f32, FieldProblem> {
    if (0.0..=1.0).contains(&finite(what, value)?) {
        Ok(value)
    } else {
        Err(FieldProblem::NotUnit { what, value })
    }
}
