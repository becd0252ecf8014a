//! The features with a section of the scene (`section_kind`), a line each, in the order their
//! tables are read and their asks applied.

use crate::section_kind::SectionKind;

pub const SECTIONS: &[SectionKind] = &[crate::environment::SECTION];
