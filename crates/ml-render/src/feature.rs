//! What a feature plugs into the renderer besides its passes (a pass is a `PassKind` placed by
//! the plan and made in the assembly): its debug views, its part of the scene's GPU state, the
//! constants it compiles into the lighting pipelines and what it refuses of a scene. A feature
//! declares them in its module as one `Feature`, and the assembly's `FEATURES` lists it: one
//! line. Every hook has a default (none), so a feature fills in only what it has.
//!
//! The hooks see the whole settings and scene. The features the settings themselves are made
//! of (shadows, shading, transparency: their types are fields of `RenderSettings`) cannot name
//! the settings from their modules without an import circle; the assembly builds their
//! entries from their modules' functions instead, still one entry each.

use crate::debug_view::DebugView;
use crate::error::SettingsError;
use crate::scene_part::MakePart;
use crate::settings::RenderSettings;
use crate::specialization::Constants;
use ml_cpu::scene::Scene;

/// One feature's hooks.
#[derive(Clone, Copy)]
pub struct Feature {
    /// Its debug views, in the order lists and menus show them.
    pub views: &'static [DebugView],
    /// Its part of the scene's GPU state, made with each scene (`scene_part`).
    pub part: Option<MakePart>,
    /// Its constants of the lighting pipelines, for a scene under the settings.
    pub lighting: fn(&RenderSettings, &Scene) -> Constants,
    /// What it refuses of a scene under the settings (checked before anything is made).
    pub check_scene: fn(&RenderSettings, &Scene) -> Result<(), SettingsError>,
}

impl Feature {
    /// A feature with no hooks: the start of every declaration (`..Feature::NONE`).
    pub const NONE: Feature = Feature { views: &[], part: None, lighting: no_constants, check_scene: accepts_any };

    /// A feature with debug views and nothing else.
    pub const fn views(views: &'static [DebugView]) -> Feature {
        Feature { views, ..Feature::NONE }
    }
}

fn no_constants(_: &RenderSettings, _: &Scene) -> Constants {
    Constants::of(&[])
}

fn accepts_any(_: &RenderSettings, _: &Scene) -> Result<(), SettingsError> {
    Ok(())
}
