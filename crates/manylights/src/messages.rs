//! The error line a user sees. The libraries' errors name what is wrong with a setting ("width
//! 0 is out of range"); on the command line the user gave it as a flag, so the line names the
//! flag instead ("--width 0 is out of range").

use ml_cpu::limits::{MAX_BENCH_OBJECTS, MAX_CLUSTERS, MAX_LIGHTS};
use ml_cpu::scene_request::SceneRequestError;
use ml_cpu::SceneError;
use ml_render::error::{Named, Setting, SettingsError};
use ml_render::RenderError;
use ml_vk::VkError;
use std::error::Error;

/// clap's message about the arguments in one line, after `error: `: what is missing or wrong,
/// the tip and the usage, each of its lines trimmed and the blank ones dropped, a line that
/// ends in a colon continued by the next (`not provided: --out <OUT>`), the others joined by
/// "; ".
pub fn argument_error(text: &str) -> String {
    let mut line = String::new();
    for part in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        let part = part.strip_prefix("error: ").unwrap_or(part);
        if !line.is_empty() {
            line += if line.ends_with(':') { " " } else { "; " };
        }
        line += part;
    }
    line
}

/// The error and its causes in one line, as anyhow's `{:#}` writes it, each cause that is
/// about a flag's value said with that flag.
pub fn describe(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = with_flags(cause).unwrap_or_else(|| cause.to_string());
        // An error whose message already ends with its source's ("cannot write 'x':
        // Permission denied (os error 13)") says it once.
        if line.ends_with(&text) {
            continue;
        }
        if !line.is_empty() {
            line += ": ";
        }
        line += &text;
    }
    line
}

/// `cause` in the command line's words, where they differ from the library's.
fn with_flags(cause: &(dyn Error + 'static)) -> Option<String> {
    if let Some(e) = cause.downcast_ref::<RenderError>() {
        return match e {
            RenderError::Scene(e) => scene(e),
            RenderError::Settings(e) => Some(settings(e)),
            RenderError::Vulkan(e) => vulkan(e),
            RenderError::ListsTooLong(e) => Some(format!(
                "{e}: use a smaller --light-radius, fewer --lights or a coarser --clusters grid (without --light-radius, a scene file's or glTF file's lights of any --light-layout, and the bench scene's, get a radius that shrinks as their count grows)"
            )),
            RenderError::UnknownName { kind: Named::OmniShadowMode, name, expected } => {
                Some(format!("unknown --omni-shadow mode '{name}': expected one of {expected}"))
            }
            RenderError::UnknownName { kind: Named::SunShadowMode, name, expected } => {
                Some(format!("unknown --sun-shadow mode '{name}': expected one of {expected}"))
            }
            RenderError::UnknownName { kind: Named::Raster, name, expected } => {
                Some(format!("unknown rasteriser '{name}' in --raster: expected one of {expected}"))
            }
            _ => None,
        };
    }
    if let Some(SceneRequestError::Scene(e)) = cause.downcast_ref::<SceneRequestError>() {
        return scene(e);
    }
    if let Some(e) = cause.downcast_ref::<SettingsError>() {
        return Some(settings(e));
    }
    if let Some(e) = cause.downcast_ref::<VkError>() {
        return vulkan(e);
    }
    cause.downcast_ref::<SceneError>().and_then(scene)
}

fn vulkan(e: &VkError) -> Option<String> {
    match e {
        VkError::DeviceIndex { index, count } => {
            Some(format!("--device {index} does not exist: {count} Vulkan device(s) found (see `manylights info`)"))
        }
        _ => None,
    }
}

fn scene(e: &SceneError) -> Option<String> {
    match e {
        SceneError::LightCount(n) => Some(format!("--lights {n} is out of range: use 1 to {MAX_LIGHTS}")),
        SceneError::ObjectCount(n) => Some(format!("--objects {n} is out of range: use 0 to {MAX_BENCH_OBJECTS}")),
        SceneError::Clusters(text) => {
            Some(format!("--clusters {text} is invalid: use XxYxZ with each at least 1 and at most {MAX_CLUSTERS} clusters in all"))
        }
        SceneError::TooManyMarkers(_) => Some(format!("--show-lights: {e}")),
        SceneError::NoSurface => Some(format!("--light-layout surface: {e}")),
        _ => None,
    }
}

fn flag(s: Setting) -> &'static str {
    match s {
        Setting::Width => "--width",
        Setting::Height => "--height",
        Setting::CubeSize => "--cube-size",
        Setting::RasterSplit => "--raster-split",
        Setting::TransparencyBudget => "--transparency-budget",
    }
}

fn settings(e: &SettingsError) -> String {
    match e {
        SettingsError::OutOfRange { what, value, max } => format!("{} {value} is out of range: use 1 to {max}", flag(*what)),
        SettingsError::ViewNeeds { view, needs, instead } => format!("--debug-view {view} needs {needs}, not {instead}"),
        SettingsError::NoFrames => "--frames must be at least 1".into(),
        SettingsError::Time(t) => format!("--time {t} is not a finite number"),
        SettingsError::ShadowsWithoutLights => format!("{e} (--lights N adds some)"),
        SettingsError::ShadowedLights { value, lights } => {
            format!("--shadowed-lights {value} is out of range: the scene has {lights} lights (use 1 to {lights})")
        }
        SettingsError::TooManyCubes { value, max, device } => {
            format!("--shadowed-lights {value} is more than the {max} shadow cubes '{device}' holds in one array")
        }
        SettingsError::ShadowMemory { .. } => format!("{e}: use fewer --shadowed-lights or a smaller --cube-size"),
        SettingsError::ShadowBuffer { .. } => {
            format!("--omni-shadow compute: {e}: use fewer --shadowed-lights, a smaller --cube-size or --omni-shadow layered")
        }
        SettingsError::MissingFeature { mode, feature, device, instead } => {
            format!("--omni-shadow {mode} needs the {feature} feature, which '{device}' lacks: use {instead}")
        }
        SettingsError::SunShadowFeature { feature, device } => {
            format!("--sun-shadow compute needs {feature}, which '{device}' lacks: use --sun-shadow graphics")
        }
        SettingsError::BrokenMultiview { device, driver } => format!(
            "--omni-shadow multiview: '{device}' ({driver}) renders every view of a depth-only multiview pass into the first layer (measured on Mesa 22.3 lavapipe): use layered, direct or copy"
        ),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A write refused by the system names its reason once, though the error both says it and
    /// keeps it as its source.
    #[test]
    fn a_cause_already_said_is_not_said_again() {
        let denied = std::io::Error::from(std::io::ErrorKind::PermissionDenied);
        let e = anyhow::Error::new(ml_cpu::files::WriteError::Io { path: "out.png".into(), source: denied });
        let line = describe(&e.context("render"));
        assert_eq!(line.matches("ermission denied").count(), 1, "{line}");
        assert!(line.starts_with("render: cannot write 'out.png': "), "{line}");
    }

    #[test]
    fn argument_errors_keep_every_line() {
        let clap = "error: unexpected argument '--lihgts' found\n\n  tip: a similar argument exists: '--lights'\n\nUsage: manylights render --lights <LIGHTS> --out <OUT>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            argument_error(clap),
            "unexpected argument '--lihgts' found; tip: a similar argument exists: '--lights'; Usage: manylights render --lights <LIGHTS> --out <OUT>; For more information, try '--help'."
        );
        let missing = "error: the following required arguments were not provided:\n  --out <OUT>\n\nUsage: manylights render --out <OUT>\n";
        assert_eq!(
            argument_error(missing),
            "the following required arguments were not provided: --out <OUT>; Usage: manylights render --out <OUT>"
        );
    }

    #[test]
    fn setting_errors_name_their_flags_and_context_stays() {
        let e = anyhow::Error::from(RenderError::Settings(SettingsError::OutOfRange { what: Setting::Width, value: 0, max: 9 }));
        assert_eq!(describe(&e), "--width 0 is out of range: use 1 to 9");
        let e = anyhow::Error::from(SceneError::LightCount(0)).context("bench");
        assert_eq!(describe(&e), format!("bench: --lights 0 is out of range: use 1 to {MAX_LIGHTS}"));
        let e = anyhow::Error::from(ml_vk::VkError::DeviceIndex { index: 3, count: 1 });
        assert_eq!(describe(&e), "--device 3 does not exist: 1 Vulkan device(s) found (see `manylights info`)");
        let lists = ml_render::error::ListsTooLong {
            needed: 1 << 20,
            limit: 1 << 18,
            holder: "'gpu' binds as one storage buffer".into(),
            technique: Some(ml_render::Technique::DeferredCompute.name()),
        };
        let e = anyhow::Error::from(RenderError::ListsTooLong(lists));
        assert!(
            describe(&e).starts_with(
                "deferred-compute: the cluster light lists need at least 1048576 entries (4 MiB), more than the 1 MiB 'gpu' binds as one storage buffer: use a smaller --light-radius, fewer --lights or a coarser --clusters grid"
            ),
            "{}",
            describe(&e)
        );
        let e = anyhow::Error::from(SettingsError::ShadowsWithoutLights);
        assert_eq!(
            describe(&e),
            "point-light shadows need point lights (shadow rays: or directional lights), and the scene has none (--lights N adds some)"
        );
        let e = anyhow::Error::from(SettingsError::SunShadowFeature { feature: "shaderInt64", device: "gpu".into() });
        assert_eq!(describe(&e), "--sun-shadow compute needs shaderInt64, which 'gpu' lacks: use --sun-shadow graphics");
        // Errors about no flag read as the library wrote them.
        let e = anyhow::Error::from(SceneError::LightRadius("0".into()));
        assert_eq!(describe(&e), format!("{:#}", anyhow::Error::from(SceneError::LightRadius("0".into()))));
    }
}
