//! Options that do not apply: one given on the command line that does nothing with the
//! technique, the scene or the other settings asked for is refused in one line naming it and
//! what it needs (docs/usage.md, "Options that do not apply"); defaults never are. With
//! `--technique auto`, an option that applies to one of the techniques auto may pick is taken,
//! and a warning says so where the pick on this device does not use it: the same command line
//! works on every device.

use crate::{auto, SceneArgs};
use anyhow::Result;
use clap::parser::ValueSource;
use clap::ArgMatches;
use ml_cpu::environment::Environment;
use ml_cpu::scene_request::{BuiltScene, SceneSource, SceneWarning};
use ml_render::error::or_list;
use ml_render::{DebugView, OmniShadowMode, RenderSettings, ShadingModel, SunShadowMode, Technique, ViewNeed};

/// The options of a command given on the command line, by clap's id (the field's name): the
/// others keep their defaults, which never make an option refused as not applying.
#[derive(Clone, Debug, Default)]
pub(crate) struct Given(Vec<String>);

impl Given {
    pub(crate) fn of(matches: &ArgMatches) -> Given {
        Given(
            matches
                .ids()
                .filter(|id| matches.value_source(id.as_str()) == Some(ValueSource::CommandLine))
                .map(|id| id.to_string())
                .collect(),
        )
    }

    pub(crate) fn has(&self, id: &str) -> bool {
        self.0.iter().any(|given| given == id)
    }
}

/// An option given on the command line that does nothing with the technique, the scene or the
/// other settings asked for: refused in one line naming it, what it does not apply to and
/// what it needs (docs/usage.md, "Options that do not apply"). Defaults never are.
#[derive(Debug)]
pub(crate) struct NotApplying {
    option: String,
    to: String,
    needs: String,
}

impl std::fmt::Display for NotApplying {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} does not apply to {}: it needs {}", self.option, self.to, self.needs)
    }
}

impl std::error::Error for NotApplying {}

/// An option that applies only with some techniques, settings or scenes.
pub(crate) struct Rule {
    /// clap's id of the option (its field's name): the rule holds where it was given.
    id: &'static str,
    /// The option as the user wrote it: `--culling`, `--debug-view cluster-heat`.
    option: String,
    need: Need,
}

pub(crate) enum Need {
    /// One of the techniques `applies` accepts; `what` says what they have in common.
    Technique { what: &'static str, applies: fn(Technique) -> bool },
    /// A setting or scene: whether the ones asked for are it (None: not known yet: a scene
    /// file's shading model and lights before it is loaded), what they are instead, and what
    /// the option needs.
    Setting { holds: Option<bool>, instead: String, needs: String },
}

impl Rule {
    pub(crate) fn technique(id: &'static str, what: &'static str, applies: fn(Technique) -> bool) -> Rule {
        Rule { id, option: flag(id), need: Need::Technique { what, applies } }
    }

    pub(crate) fn setting(id: &'static str, holds: Option<bool>, instead: impl Into<String>, needs: impl Into<String>) -> Rule {
        Rule { id, option: flag(id), need: Need::Setting { holds, instead: instead.into(), needs: needs.into() } }
    }

    /// The rule of one value of the option (`--debug-view shadow-cube`).
    fn of_value(self, value: &str) -> Rule {
        Rule { option: format!("{} {value}", self.option), ..self }
    }
}

/// `--raster-split` for the id `raster_split`.
fn flag(id: &str) -> String {
    format!("--{}", id.replace('_', "-"))
}

/// What the techniques that have a cluster grid (the clustered ones) have in common.
pub(crate) const CLUSTER_GRID: &str = "the techniques with a cluster grid";
/// … and the technique whose visibility buffer the rasterisers draw.
pub(crate) const VISIBILITY_BUFFER: &str = "the technique with a visibility buffer";

/// The techniques a command renders with, as far as they are known: those named and, with
/// auto, its pick on this device; before the probe, any technique auto may pick.
pub(crate) struct Techniques {
    /// `--technique` or `--techniques`.
    pub(crate) flag: &'static str,
    pub(crate) named: Vec<Technique>,
    pub(crate) auto: Auto,
}

#[derive(Clone, Copy, PartialEq)]
pub(crate) enum Auto {
    /// Not asked for.
    No,
    /// Asked for, not probed yet.
    Pending,
    Picked(Technique),
}

impl Techniques {
    /// `--technique`'s choice (None: auto, not yet probed).
    pub(crate) fn chosen(choice: Option<Technique>) -> Techniques {
        match choice {
            Some(t) => Techniques { flag: "--technique", named: vec![t], auto: Auto::No },
            None => Techniques { flag: "--technique", named: Vec::new(), auto: Auto::Pending },
        }
    }

    /// Refused unless one of the techniques named or auto may pick is one that `applies`
    /// accepts; the technique auto picked where the option is taken but goes unused (none of
    /// the named ones uses it, nor the pick).
    fn check(&self, option: &str, what: &str, applies: fn(Technique) -> bool) -> Result<Option<Technique>, NotApplying> {
        let auto: &[Technique] = if self.auto == Auto::No { &[] } else { &auto::CANDIDATES };
        if self.named.iter().any(|&t| applies(t)) {
            return Ok(None);
        }
        if auto.iter().any(|&t| applies(t)) {
            return Ok(match self.auto {
                Auto::Picked(t) if !applies(t) => Some(t),
                _ => None,
            });
        }
        let mut to: Vec<String> = self.named.iter().map(|t| t.name().to_owned()).collect();
        if self.auto != Auto::No {
            to.push(format!("auto (which picks {})", or_list(auto.iter().map(|t| t.name()))));
        }
        let which = or_list(Technique::ALL.into_iter().filter(|&t| applies(t)).map(Technique::name));
        let mut needs = format!("{} {which} ({what})", self.flag);
        if self.auto != Auto::No {
            needs += &format!(", named with {} rather than auto", self.flag);
        }
        Err(NotApplying { option: option.to_owned(), to: to.join(" and "), needs })
    }
}

/// Refuse the first of `rules` whose option was given and does not apply to `techniques` (as
/// far as they are known) or to the settings and scene asked for (as far as they are known).
pub(crate) fn check_rules(rules: &[Rule], given: &Given, techniques: &Techniques) -> Result<Unused, NotApplying> {
    let mut unused = Unused::default();
    for rule in rules.iter().filter(|r| given.has(r.id)) {
        match &rule.need {
            Need::Technique { what, applies } => {
                if let Some(picked) = techniques.check(&rule.option, what, *applies)? {
                    unused.0.push((
                        rule.id,
                        format!("{} is not used: auto picked {} on this device, and it applies to {what}", rule.option, picked.name()),
                    ));
                }
            }
            Need::Setting { holds: Some(false), instead, needs } => {
                return Err(NotApplying { option: rule.option.clone(), to: instead.clone(), needs: needs.clone() });
            }
            Need::Setting { .. } => {}
        }
    }
    Ok(unused)
}

/// The options given that auto's pick does not use (by clap's id), each with its warning.
#[derive(Debug, Default)]
pub(crate) struct Unused(Vec<(&'static str, String)>);

impl Unused {
    /// Print each one's warning.
    pub(crate) fn warn(&self) {
        for (_, warning) in &self.0 {
            eprintln!("warning: {warning}");
        }
    }

    /// Warn, and leave out of `settings` what the pick cannot take: a debug view it does not
    /// have gives the shaded image, as the warning says (the other options are inert there).
    pub(crate) fn take_effect(&self, settings: &mut RenderSettings) {
        self.warn();
        if self.has("debug_view") {
            settings.debug_view = DebugView::NONE;
        }
    }

    fn has(&self, id: &str) -> bool {
        self.0.iter().any(|(unused, _)| *unused == id)
    }
}

/// `--objects`, of `render`, `view` and `bench`.
pub(crate) fn objects_rule(scene: &str) -> Rule {
    Rule::setting("objects", Some(scene == "bench"), format!("--scene {scene}"), "the bench scene (--scene bench)")
}

/// The options of `render` and `view` that apply only with some techniques, settings or
/// scenes: `source` is the scene asked for, `built` the scene once it is (which tells a scene
/// file's shading model and whether it keeps its own lights).
fn scene_rules(args: &SceneArgs, source: &SceneSource, built: Option<&BuiltScene>) -> Vec<Rule> {
    let scene = format!("--scene {}", args.scene);
    let (seed, room, bench, file) = (
        matches!(source, SceneSource::Seed { .. }),
        matches!(source, SceneSource::Room),
        matches!(source, SceneSource::Bench { .. }),
        matches!(source, SceneSource::File(_)),
    );
    let gltf = matches!(source, SceneSource::File(path) if !path.to_string_lossy().to_lowercase().ends_with(".toml"));
    let placed =
        "lights placed by layout (--scene seed or a scene or glTF file; the bench scene's are random, the room keeps its one light)";
    let random = args.light_layout != "grid" || args.light_radius.as_deref().is_some_and(|r| r.contains(".."));
    let random_lights = "random lights (--light-layout random or surface, a --light-radius range MIN..MAX, or --scene bench)";
    // A file that has lights keeps them unless --lights replaces them.
    let own_lights =
        built.map(|b| file && args.lights.is_none() && !b.warnings.iter().any(|w| matches!(w, SceneWarning::DefaultRig { .. })));
    let own = |id| {
        Rule::setting(id, own_lights.map(|own| !own), format!("the lights of '{}'", args.scene), "--lights N, whose lights replace them")
    };
    let omni = args.omni_shadow.as_str();
    // The debug view asked for (an unknown name is refused where the settings are made).
    let asked_view = DebugView::from_name(&args.debug_view).ok();
    let map_modes = OmniShadowMode::ALL.into_iter().filter(|m| *m != OmniShadowMode::Rays).map(OmniShadowMode::name);
    let shadow_maps = format!("point-light shadow maps (--omni-shadow {})", or_list(map_modes));
    let shadows = format!("point-light shadows (--omni-shadow {})", or_list(OmniShadowMode::ALL.into_iter().map(OmniShadowMode::name)));
    let atlas = "the shadow atlas (--omni-shadow atlas)";
    let model = built.map(|b| b.shading);
    // Options of one shading model's feature.
    let of_model = |id, wanted: ShadingModel, feature: &'static str| {
        Rule::setting(id, model.map(|m| m == wanted), format!("the {} shading model", model.map_or("", ShadingModel::name)), feature)
    };
    let sun = |id| of_model(id, ShadingModel::BlinnPhong, "the blinn-phong model's sun (--shading blinn-phong)");
    let pbr = |id| of_model(id, ShadingModel::Pbr, "the pbr model's environment light (--shading pbr)");
    let lit = |id| {
        Rule::setting(
            id,
            built.map(|b| b.scene.sections.get::<Environment>().is_some()),
            "a scene without an environment",
            "an environment (--environment FILE or sky)",
        )
    };
    let mut rules = vec![
        objects_rule(&args.scene),
        pbr("environment"),
        pbr("environment_intensity"),
        pbr("environment_rotation"),
        lit("environment_intensity"),
        lit("environment_rotation"),
        Rule::setting("variant", Some(gltf), &scene, "a glTF file (--scene FILE.gltf or FILE.glb)"),
        Rule::setting("object", Some(seed), &scene, "the seed scene (--scene seed)"),
        Rule::setting("material", Some(seed), &scene, "the seed scene (--scene seed)"),
        Rule::setting(
            "lights",
            Some(!room),
            &scene,
            "a scene whose lights are placed (--scene seed, bench or a file; the room keeps its one light)",
        ),
        Rule::setting("light_layout", Some(seed || file), &scene, placed),
        Rule::setting("light_radius", Some(seed || file), &scene, placed),
        Rule::setting("light_colors", Some(seed || file), &scene, placed),
        Rule::setting("light_seed", Some(!room), &scene, random_lights),
        Rule::setting("light_seed", Some(bench || random), "--light-layout grid of one --light-radius", random_lights),
        own("light_layout"),
        own("light_radius"),
        own("light_colors"),
        own("light_seed"),
        Rule::setting("shadowed_lights", Some(omni != "off"), "--omni-shadow off", &shadows),
        Rule::setting("cube_size", Some(omni != "off" && omni != "rays"), format!("--omni-shadow {omni}"), &shadow_maps),
        Rule::setting("shadow_budget", Some(omni == "atlas"), format!("--omni-shadow {omni}"), atlas),
        Rule::setting("shadow_cache", Some(omni == "atlas"), format!("--omni-shadow {omni}"), atlas),
        sun("sun_shadow"),
        Rule::setting(
            "exposure",
            Some(args.debug_view == "none"),
            format!("--debug-view {}", args.debug_view),
            "the shaded image (--debug-view none; debug views show their values as they are)",
        ),
        Rule::technique("clusters", CLUSTER_GRID, Technique::has_cluster_grid),
        Rule::technique("culling", "the technique that culls meshlets on the GPU", Technique::draws_meshlets),
        Rule::technique("light_grid_marks", "the techniques that know their surfaces before their lighting", Technique::marks_light_grid),
        Rule::technique("raster", VISIBILITY_BUFFER, Technique::draws_meshlets),
        Rule::technique("raster_split", VISIBILITY_BUFFER, Technique::draws_meshlets),
        Rule::setting(
            "raster_split",
            Some(args.raster != "hardware"),
            "--raster hardware",
            "a rasteriser in compute (--raster compute, hybrid or auto)",
        ),
    ];
    // Transparency needs transparent objects (a file's, or made by the two options), and
    // the shaded image or the layers' own view.
    let transparent = built.map(|b| b.scene.has_transparent_objects());
    let needs_transparent = "transparent objects (alphaMode BLEND in a glTF file, --transparent-objects or --glass-layers)";
    rules.push(Rule::setting(
        "transparency_budget",
        transparent,
        format!("'{}', which has no transparent objects", args.scene),
        needs_transparent,
    ));
    rules.push(Rule::setting(
        "transparency_budget",
        Some(asked_view.is_some_and(DebugView::shows_layers)),
        format!("--debug-view {}", args.debug_view),
        "the shaded image or --debug-view transparency-layers (surface views show the opaque surfaces only)",
    ));
    // The colour background applies anywhere.
    if let Some(shown @ "environment") = args.background.as_deref() {
        rules.extend([pbr("background").of_value(shown), lit("background").of_value(shown)]);
    }
    // The debug view's needs, as its feature declares them.
    let view = asked_view.unwrap_or(DebugView::NONE);
    for need in view.needs() {
        let rule = |holds, instead| Rule::setting("debug_view", holds, instead, need.needs());
        rules.extend(
            match *need {
                ViewNeed::Technique { what, holds } => Some(Rule::technique("debug_view", what, holds)),
                ViewNeed::OmniShadow { modes, .. } => Some(rule(Some(modes.contains(&omni)), format!("--omni-shadow {omni}"))),
                ViewNeed::Shading { model: wanted, .. } => {
                    Some(rule(model.map(|m| m == wanted), format!("the {} shading model", model.map_or("", ShadingModel::name))))
                }
                ViewNeed::SunMap => {
                    let drawn = SunShadowMode::from_name(&args.sun_shadow).ok().map(ViewNeed::sun_map);
                    Some(rule(drawn, format!("--sun-shadow {}", args.sun_shadow)))
                }
                ViewNeed::TransparentObjects => Some(rule(transparent, format!("'{}', which has no transparent objects", args.scene))),
                // Known once the raster and samples are: the settings' check says.
                ViewNeed::SampleBuffer => None,
            }
            .map(|rule| rule.of_value(view.name())),
        );
    }
    rules
}

/// Refuse an option of `render` or `view` given on the command line that does not apply to
/// `techniques`, the scene or the other settings, as far as they are known.
pub(crate) fn check_options_apply(
    args: &SceneArgs,
    source: &SceneSource,
    built: Option<&BuiltScene>,
    techniques: &Techniques,
) -> Result<Unused> {
    Ok(check_rules(&scene_rules(args, source, built), &args.given, techniques)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Cli, Command};
    use clap::{CommandFactory as _, Parser as _};
    use ml_render::DebugView;

    /// The ids of `command`'s options.
    fn ids(command: &str) -> Vec<String> {
        let cli = Cli::command();
        let sub = cli.find_subcommand(command).expect("the command");
        sub.get_arguments().map(|a| a.get_id().to_string()).collect()
    }

    /// A rule whose id names no option would never hold.
    #[test]
    fn every_rule_names_an_option() {
        for view in DebugView::all() {
            let Command::Render(args) = Cli::parse_from(["manylights", "render", "--debug-view", view.name(), "--out", "a.png"]).command
            else {
                unreachable!()
            };
            for rule in scene_rules(&args.scene, &SceneSource::Room, None) {
                assert!(ids("render").contains(&rule.id.to_owned()) && ids("view").contains(&rule.id.to_owned()), "{}", rule.id);
            }
        }
        let Command::Bench(args) = Cli::parse_from(["manylights", "bench"]).command else { unreachable!() };
        for rule in args.rules(&[]) {
            assert!(ids("bench").contains(&rule.id.to_owned()), "{}", rule.id);
        }
    }

    #[test]
    fn lists_read_as_prose() {
        assert_eq!([&["a"][..], &["a", "b"], &["a", "b", "c"]].map(|l| or_list(l.iter().copied())), ["a", "a or b", "a, b or c"]);
    }
}
