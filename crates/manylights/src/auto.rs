//! `--technique auto` (render, view, bench): the lighting path this device runs fastest, from
//! the compute-vs-fragment probe (ml_render::stage_probe) measured on it.

use anyhow::{bail, Result};
use ml_render::settings::missing_meshlet_feature;
use ml_render::stage_probe::{pick_lighting_path, quick_probe, StageTimes};
use ml_render::Technique;
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;

pub const AUTO: &str = "auto";

/// `name` as a technique, None for `auto` (checked before any GPU work).
pub fn technique_choice(name: &str) -> Result<Option<Technique>> {
    if name == AUTO {
        return Ok(None);
    }
    Technique::from_name(name).map(Some).map_err(|e| anyhow::anyhow!("{e}, or auto"))
}

/// Probe `ctx`'s device and say which technique `auto` is there, why, and what the probe
/// measured.
pub fn pick(ctx: &Context) -> Result<(Technique, String, StageTimes)> {
    let times = quick_probe(ctx)?;
    let (technique, why) = pick_lighting_path(&times, missing_meshlet_feature(&ctx.info.features).is_none());
    Ok((technique, why, times))
}

/// The line that tells what `auto` picked and why.
pub fn announce(technique: Technique, why: &str) {
    println!("auto: {}: {why}", technique.name());
}

/// `name`'s technique; for `auto`, probed on a context of its own (the viewer makes its own
/// for the window), which must leave the validation layer silent.
pub fn resolve_alone(name: &str, validation: bool, device_index: Option<usize>) -> Result<Technique> {
    if let Some(t) = technique_choice(name)? {
        return Ok(t);
    }
    let ctx = Context::new(&ContextDesc { validation, device_index, window: None })?;
    let messages = ctx.validation_counter();
    let picked = pick(&ctx);
    drop(ctx);
    let count = messages.load(Ordering::SeqCst);
    if count > 0 {
        bail!("the validation layer reported {count} message(s) while probing for --technique auto (printed above)");
    }
    let (technique, why, _) = picked?;
    announce(technique, &why);
    Ok(technique)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn auto_is_a_choice_and_unknown_names_say_so() {
        assert_eq!(technique_choice("auto").unwrap(), None);
        assert_eq!(technique_choice("deferred-compute").unwrap(), Some(Technique::DeferredCompute));
        let e = technique_choice("raytracing").unwrap_err().to_string();
        assert!(e.contains("raytracing") && e.ends_with("or auto"), "{e}");
    }
}
