//! Debug views: what the image shows instead of the shaded scene, as data. Each feature
//! declares its own views in its module (`ViewSpec`: the name users type, the code its
//! shaders read, what the view needs, how it is drawn, its legend) and lists them in its
//! `VIEWS`; the assembly's `FEATURES` gathers the lists, one line a feature. The settings check
//! and the command line's "does not apply" rules read a view's needs (`ViewNeed`, checked in
//! settings.rs), the plan how it is drawn, the report its legend: none of them names a view.
//! This module names no feature: the features use it.

use crate::report::FrameStats;
use crate::technique::Technique;
use ml_cpu::shading_model::ShadingModel;

/// One debug view, or none: a handle on what its feature declares. Views are equal when their
/// names are (the registry's test keeps names and codes unique).
#[derive(Clone, Copy)]
pub struct DebugView {
    pub(crate) spec: &'static ViewSpec,
}

/// What a feature declares of one of its views.
pub(crate) struct ViewSpec {
    /// What users type after `--debug-view`.
    pub(crate) name: &'static str,
    /// `DEBUG_VIEW_*` of common/common.glsl, which the shaders that draw it read.
    pub(crate) code: u32,
    /// What must hold for the view to be drawn, checked in this order.
    pub(crate) needs: &'static [ViewNeed],
    pub(crate) drawn: Drawn,
    /// The table's legend row, where the view's colours need one.
    pub(crate) legend: Legend,
}

impl ViewSpec {
    /// A view without a legend: what most views are.
    pub(crate) const fn plain(name: &'static str, code: u32, needs: &'static [ViewNeed], drawn: Drawn) -> ViewSpec {
        ViewSpec { name, code, needs, drawn, legend: Legend::None }
    }
}

/// How a view is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Drawn {
    /// By the lighting shaders in place of the shaded colour: through the tone curve as the
    /// shaded image is (`toned`) or with its values as they are; with the transparent layers
    /// blended over it (`layers`) or showing the opaque surfaces alone.
    InShading { toned: bool, layers: bool },
    /// By the shadow-map view pass, which paints one shadow store over the whole image.
    Store(ShownStore),
}

/// Which shadow store the shadow-map view pass paints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShownStore {
    SunMap,
    Cube,
    Atlas,
}

/// The legend a view's colours need in the report's table.
pub(crate) enum Legend {
    None,
    Text(&'static str),
    /// Made from what the frame counted (the cluster heat map's top).
    Counted(fn(&FrameStats) -> String),
}

/// What a view needs of the technique, the settings or the scene.
#[derive(Clone, Copy)]
pub enum ViewNeed {
    /// A technique `holds` accepts; `what` says what those have in common.
    Technique { what: &'static str, holds: fn(Technique) -> bool },
    /// Point-light shadows by one of `modes` (`--omni-shadow`'s names); `what` names what
    /// those modes make.
    OmniShadow { what: &'static str, modes: &'static [&'static str] },
    /// A shading model; `what` names its feature the view shows.
    Shading { model: ShadingModel, what: &'static str },
    /// The sun's shadow drawn into a map (not traced).
    SunMap,
    /// Transparent objects in the scene.
    TransparentObjects,
    /// The 64-bit depth-and-id buffer the compute raster fills (`--raster compute` or hybrid,
    /// or any raster with anti-aliasing).
    SampleBuffer,
}

impl DebugView {
    /// The shaded image itself.
    pub const NONE: DebugView =
        DebugView { spec: &ViewSpec::plain("none", ml_shaders::debug_view::NONE, &[], Drawn::InShading { toned: true, layers: true }) };

    pub fn name(self) -> &'static str {
        self.spec.name
    }

    /// The value shaders see: `DEBUG_VIEW_*` in common/common.glsl, generated from there.
    pub fn code(self) -> u32 {
        self.spec.code
    }

    /// What the view needs, checked in this order.
    pub fn needs(self) -> &'static [ViewNeed] {
        self.spec.needs
    }

    /// Whether the image is the shaded one, no view.
    pub fn is_none(self) -> bool {
        self == DebugView::NONE
    }

    /// Whether the image goes through the tone curve the shaded image does (the others show
    /// their values as they are).
    pub fn toned(self) -> bool {
        matches!(self.spec.drawn, Drawn::InShading { toned: true, .. })
    }

    /// Whether the transparent layers are blended over it (surface views show the opaque
    /// surfaces alone).
    pub fn shows_layers(self) -> bool {
        matches!(self.spec.drawn, Drawn::InShading { layers: true, .. })
    }

    /// The shadow store the shadow-map view pass paints, for the views that pass draws.
    pub(crate) fn shown_store(self) -> Option<ShownStore> {
        match self.spec.drawn {
            Drawn::Store(store) => Some(store),
            Drawn::InShading { .. } => None,
        }
    }

    /// The legend row its colours need, from what the frame counted.
    pub fn legend(self, stats: &FrameStats) -> Option<String> {
        match self.spec.legend {
            Legend::None => None,
            Legend::Text(text) => Some(text.to_owned()),
            Legend::Counted(made) => Some(made(stats)),
        }
    }
}

impl PartialEq for DebugView {
    fn eq(&self, other: &DebugView) -> bool {
        self.name() == other.name()
    }
}

impl Eq for DebugView {}

impl std::hash::Hash for DebugView {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.name().hash(state);
    }
}

impl std::fmt::Debug for DebugView {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "DebugView({})", self.name())
    }
}
