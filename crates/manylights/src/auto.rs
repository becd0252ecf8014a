//! `--technique auto` (render, view, bench): the lighting path this device runs fastest, from
//! the compute-vs-fragment probe (ml_render::stage_probe) measured on it.

use anyhow::{bail, Result};
use ml_cpu::scene::Scene;
use ml_render::settings::{missing_meshlet_feature, missing_raster_feature};
use ml_render::stage_probe::{pick_lighting_path, quick_probe, StageTimes};
use ml_render::{Antialiasing, Geometry, Raster, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;

pub const AUTO: &str = "auto";

/// Every technique auto may pick (`pick_lighting_path`): an option that applies to none of
/// them is refused before the probe.
pub const CANDIDATES: [Technique; 3] = [Technique::Visibility, Technique::DeferredCompute, Technique::DeferredClustered];

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

/// Frames each rasteriser renders in `--raster auto`'s probe.
pub const RASTER_PROBE_FRAMES: u32 = 4;

/// The rasteriser for `settings` on `ctx`'s device and, where `auto` (`choice` None) chose it,
/// why. Techniques without a visibility buffer keep the hardware (an explicit compute raster
/// is refused by the settings check); a device without what the asked-for raster needs draws
/// with the hardware, and says so; auto renders `scene` with each rasteriser the device can
/// run (hardware, hybrid and compute, those with `split`) and keeps the fastest.
pub fn resolve_raster(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    (choice, split): (Option<Raster>, u32),
) -> Result<(Raster, Option<String>)> {
    if settings.technique.geometry() != Geometry::Meshlets {
        return Ok((choice.unwrap_or(Raster::Hardware), None));
    }
    let device = &ctx.info.name;
    let features = &ctx.info.features;
    if choice.is_none() && settings.antialiasing != Antialiasing::Off {
        // With samples, the compute raster: every raster keeps them, but the hybrid's and the
        // hardware's multisampled draws run on the fragment units (on the H200 at 8 samples:
        // 1.26 ms a frame against 3.08 and 6.79).
        let raster = Raster::compute(split);
        let samples = settings.antialiasing.name();
        return Ok(match missing_raster_feature(raster, features) {
            Some(feature) => {
                (Raster::Hardware, Some(format!("--aa {samples}: the compute raster needs {feature}, which '{device}' lacks")))
            }
            None => (raster, Some(format!("--aa {samples}: the compute raster draws samples fastest"))),
        });
    }
    if let Some(raster) = choice {
        return Ok(match missing_raster_feature(raster, features) {
            Some(feature) => {
                eprintln!("warning: the {} raster needs {feature}, which '{device}' lacks: drawing with the hardware", raster.name());
                (Raster::Hardware, None)
            }
            None => (raster, None),
        });
    }
    let candidates: Vec<Raster> = [Raster::Hardware, Raster::hybrid(split), Raster::compute(split)]
        .into_iter()
        .filter(|&r| missing_raster_feature(r, features).is_none())
        .collect();
    if candidates.len() == 1 {
        let feature = missing_raster_feature(Raster::compute(split), features).unwrap_or("what the compute rasters need");
        return Ok((Raster::Hardware, Some(format!("'{device}' lacks {feature}, which the compute raster needs"))));
    }
    let (raster, why) = pick_raster(ctx, scene, settings, &candidates)?;
    Ok((raster, Some(why)))
}

/// `resolve_raster` on a context of its own (the viewer makes its own for the window), which
/// must leave the validation layer silent; auto's pick is announced.
pub fn resolve_raster_alone(
    scene: &Scene,
    settings: &RenderSettings,
    choice: (Option<Raster>, u32),
    (validation, device_index): (bool, Option<usize>),
) -> Result<Raster> {
    if settings.technique.geometry() != Geometry::Meshlets {
        return Ok(choice.0.unwrap_or(Raster::Hardware));
    }
    let ctx = Context::new(&ContextDesc { validation, device_index, window: None })?;
    let messages = ctx.validation_counter();
    let resolved = resolve_raster(&ctx, scene, settings, choice);
    drop(ctx);
    let count = messages.load(Ordering::SeqCst);
    if count > 0 {
        bail!("the validation layer reported {count} message(s) while timing the rasterisers for --raster auto (printed above)");
    }
    let (raster, why) = resolved?;
    if let Some(why) = why {
        println!("auto raster: {}: {why}", raster.name());
    }
    Ok(raster)
}

/// Render `scene` with `settings` and each of `candidates` for RASTER_PROBE_FRAMES frames; the
/// one whose frames took least GPU time (wall time where the device has no timestamps), and
/// the line that says so.
pub fn pick_raster(ctx: &Context, scene: &Scene, settings: &RenderSettings, candidates: &[Raster]) -> Result<(Raster, String)> {
    let time = |raster| -> Result<f64> {
        let s = RenderSettings { raster, frames: RASTER_PROBE_FRAMES, ..*settings };
        let out = Renderer::new(ctx, scene.clone(), s)?.render()?;
        Ok(match out.stats.gpu_ms() {
            Some(passes) => passes.iter().map(|(_, ms)| ms).sum(),
            None => out.stats.wall_ms_per_frame(),
        })
    };
    let timed = candidates.iter().map(|&r| Ok((r, time(r)?))).collect::<Result<Vec<(Raster, f64)>>>()?;
    let &(picked, best) = timed.iter().min_by(|a, b| a.1.total_cmp(&b.1)).expect("at least one rasteriser");
    let each: Vec<String> = timed.iter().map(|(r, ms)| format!("{ms:.3} ms {}", r.name())).collect();
    let runner_up = timed.iter().filter(|(r, _)| *r != picked).map(|t| t.1).fold(f64::INFINITY, f64::min);
    let why = format!(
        "a frame of this scene took {} ({:.2}× faster than the next; mean of {RASTER_PROBE_FRAMES} frames each)",
        each.join(", "),
        runner_up / best
    );
    Ok((picked, why))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Compute faster or not, with and without the meshlet features.
    #[test]
    fn auto_picks_only_its_candidates() {
        use ml_render::report::Spread;
        let ms = |median| Spread { median, p95: median, mean: median };
        for (fragment, compute) in [(1.0, 10.0), (10.0, 1.0), (1.0, 1.0)] {
            let times = StageTimes { lights: 16, pixels: 64, fragment: ms(fragment), compute: ms(compute), timestamps: true };
            for meshlets in [true, false] {
                let (t, _) = pick_lighting_path(&times, meshlets);
                assert!(CANDIDATES.contains(&t), "{t:?}");
            }
        }
    }

    #[test]
    fn auto_is_a_choice_and_unknown_names_say_so() {
        assert_eq!(technique_choice("auto").unwrap(), None);
        assert_eq!(technique_choice("deferred-compute").unwrap(), Some(Technique::DeferredCompute));
        let e = technique_choice("raytracing").unwrap_err().to_string();
        assert!(e.contains("raytracing") && e.ends_with("or auto"), "{e}");
    }
}
