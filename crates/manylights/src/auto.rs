//! `--technique auto` (render, view, bench): the lighting path this device runs fastest, from
//! the compute-vs-fragment probe (ml_render::stage_probe) measured on it.

use anyhow::{bail, Result};
use ml_cpu::scene::Scene;
use ml_render::settings::{missing_meshlet_feature, missing_raster_feature};
use ml_render::stage_probe::{pick_lighting_path, quick_probe, too_close_to_call, StageTimes};
use ml_render::{Antialiasing, Geometry, LargeTriangles, Raster, RenderSettings, Renderer, Technique};
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

/// What `auto`'s technique pick may render to decide: the scene, its settings and the
/// rasteriser asked for (`--raster`, None for auto).
pub type SceneProbe<'s> = (&'s Scene, &'s RenderSettings, Option<Raster>);

/// Probe `ctx`'s device and say which technique `auto` is there, why, and what the probe
/// measured. Where the light loop's probe cannot tell the kinds of pass apart
/// (`too_close_to_call`, or a CPU driver) and the device runs the meshlet techniques, `scene`
/// decides: rendered with visibility and with deferred-clustered, the first of them within
/// PICK_MARGIN of the faster is kept.
pub fn pick(ctx: &Context, scene: Option<SceneProbe>) -> Result<(Technique, String, StageTimes)> {
    let times = quick_probe(ctx)?;
    let meshlets = missing_meshlet_feature(&ctx.info.features).is_none();
    let (technique, why) = pick_lighting_path(&times, meshlets);
    // A CPU driver runs both kinds of pass on the same cores: what its probe measures is
    // noise (lavapipe: 0.74-1.17x on repeats).
    let undecided = if ctx.info.device_type == ml_vk::vk::PhysicalDeviceType::CPU {
        Some("a CPU driver runs both on the same cores")
    } else {
        too_close_to_call(&times).then_some("too close to call")
    };
    match (scene, undecided) {
        (Some(scene), Some(reason)) if meshlets => match pick_by_scene(ctx, scene)? {
            Some((technique, decided)) => Ok((technique, format!("{why}; {reason}, so {decided}"), times)),
            None => Ok((technique, why, times)),
        },
        _ => Ok((technique, why, times)),
    }
}

/// visibility and deferred-clustered timed on `scene` (visibility with the rasteriser asked
/// for, else the compute raster with samples and the hardware without: the raster probe comes
/// after), the first within the margin of the faster, and how; None where neither renders.
fn pick_by_scene(ctx: &Context, (scene, settings, raster): SceneProbe) -> Result<Option<(Technique, String)>> {
    let features = &ctx.info.features;
    let supported = |r: Raster| missing_raster_feature(r, features).is_none();
    let raster = match raster {
        Some(r) if supported(r) => r,
        _ if settings.antialiasing != Antialiasing::Off && supported(Raster::compute(Raster::DEFAULT_SPLIT)) => {
            Raster::compute(Raster::DEFAULT_SPLIT)
        }
        _ => Raster::Hardware,
    };
    let order = [Technique::Visibility, Technique::DeferredClustered];
    let mut timed: Vec<Timed<Technique>> = Vec::new();
    let mut refused = Vec::new();
    for technique in order {
        let s =
            RenderSettings { technique, raster: if technique == Technique::Visibility { raster } else { Raster::Hardware }, ..*settings };
        let best = timed.iter().map(|t| t.ms).fold(f64::INFINITY, f64::min);
        match time_renders(ctx, scene, s, best) {
            Ok(frames) => timed.push(frames.of(technique)),
            Err(e) => refused.push(format!("{} cannot render it: {e}", technique.name())),
        }
    }
    if timed.is_empty() {
        return Ok(None);
    }
    let picked = pick_within_margin(&timed, &order);
    let names: Vec<&str> = order.iter().map(|t| t.name()).collect();
    let mut how = format!("{}; {}", describe(&timed, |t| t.name()), margin_rule(&names));
    for r in refused {
        how.push_str("; ");
        how.push_str(&r);
    }
    Ok(Some((picked, how)))
}

/// The line that tells what `auto` picked and why.
pub fn announce(technique: Technique, why: &str) {
    println!("auto: {}: {why}", technique.name());
}

/// `decide` on a context of its own (the viewer makes its own for the window), which must
/// leave the validation layer silent (`what` it was doing names it in the error).
fn on_own_context<T>(
    (validation, device_index): (bool, Option<usize>),
    what: &str,
    decide: impl FnOnce(&Context) -> Result<T>,
) -> Result<T> {
    let ctx = Context::new(&ContextDesc { validation, device_index, window: None })?;
    let messages = ctx.validation_counter();
    let decided = decide(&ctx);
    drop(ctx);
    let count = messages.load(Ordering::SeqCst);
    if count > 0 {
        bail!("the validation layer reported {count} message(s) while {what} (printed above)");
    }
    decided
}

/// `name`'s technique; for `auto`, probed on a context of its own (the viewer makes its own
/// for the window), which must leave the validation layer silent.
pub fn resolve_alone(name: &str, scene: SceneProbe, (validation, device_index): (bool, Option<usize>)) -> Result<Technique> {
    if let Some(t) = technique_choice(name)? {
        return Ok(t);
    }
    let (technique, why, _) = on_own_context((validation, device_index), "probing for --technique auto", |ctx| pick(ctx, Some(scene)))?;
    announce(technique, &why);
    Ok(technique)
}

/// The rasteriser for `settings` on `ctx`'s device and, where `auto` (`choice` None) chose it,
/// why. Techniques without a visibility buffer draw with the hardware (`--raster` given with
/// one is refused before, or where auto picked it, said to be unused); a device without what
/// the asked-for raster needs draws with the hardware, and says so; auto renders `scene` with
/// each rasteriser the device can run (hardware, hybrid and compute, those with `split`) and
/// keeps the fastest.
pub fn resolve_raster(
    ctx: &Context,
    scene: &Scene,
    settings: &RenderSettings,
    (choice, split): (Option<Raster>, u32),
) -> Result<(Raster, Option<String>)> {
    if settings.technique.geometry() != Geometry::Meshlets {
        return Ok((Raster::Hardware, None));
    }
    let device = &ctx.info.name;
    let features = &ctx.info.features;
    let cpu = ctx.info.device_type == ml_vk::vk::PhysicalDeviceType::CPU;
    if choice.is_none() && settings.antialiasing != Antialiasing::Off && !cpu {
        // With samples on a GPU, the compute raster: every raster keeps them, but the hybrid's
        // and the hardware's multisampled draws run on the fragment units (on the H200 at 8
        // samples: 1.26 ms a frame against 3.08 and 6.79). A CPU driver times them as without
        // (lavapipe draws the bench scene's samples with its rasteriser many times faster).
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

/// `--aa` as given: a sample count, or None for auto.
pub fn antialiasing_choice(name: &str) -> Result<Option<Antialiasing>> {
    if name == AUTO {
        return Ok(None);
    }
    Antialiasing::from_name(name).map(Some).map_err(|e| anyhow::anyhow!("{e}, or auto"))
}

/// The samples for `settings` (its technique known, its raster not yet where `raster` is None:
/// with samples, the compute raster where the device runs it) on `ctx`'s device: `choice`, or
/// for auto (None) `ml_render::auto_antialiasing` — the first count these settings
/// pass their check with — and why; none for a supersampled render (`supersample` > 1), whose
/// K×K pixels a pixel are its samples.
pub fn resolve_antialiasing(
    ctx: &Context,
    settings: &RenderSettings,
    (choice, raster): (Option<Antialiasing>, (Option<Raster>, u32)),
    (lights, supersample): (usize, u32),
) -> (Antialiasing, Option<String>) {
    if let Some(aa) = choice {
        return (aa, None);
    }
    if supersample > 1 {
        return (
            Antialiasing::Off,
            Some(format!("--supersample {supersample} filters {supersample}x{supersample} samples a pixel already")),
        );
    }
    let cpu = ctx.info.device_type == ml_vk::vk::PhysicalDeviceType::CPU;
    let takes = |aa: Antialiasing| {
        let mut s = RenderSettings { antialiasing: aa, ..*settings };
        if settings.technique.geometry() == Geometry::Meshlets && raster.0.is_none() {
            let compute = Raster::compute(raster.1);
            s.raster = if missing_raster_feature(compute, &ctx.info.features).is_none() { compute } else { Raster::Hardware };
        }
        s.check(ctx, lights)
    };
    let (aa, why) = ml_render::auto_antialiasing(cpu, takes);
    (aa, Some(why))
}

/// `resolve_antialiasing` on a context of its own (the viewer makes its own for the window),
/// which must leave the validation layer silent; auto's choice is announced.
pub fn resolve_antialiasing_alone(
    settings: &RenderSettings,
    choice: (Option<Antialiasing>, (Option<Raster>, u32)),
    lights: usize,
    (validation, device_index): (bool, Option<usize>),
) -> Result<Antialiasing> {
    if let Some(aa) = choice.0 {
        return Ok(aa);
    }
    let (aa, why) = on_own_context((validation, device_index), "choosing --aa auto's samples", |ctx| {
        Ok(resolve_antialiasing(ctx, settings, choice, (lights, 1)))
    })?;
    if let Some(why) = why {
        println!("auto aa: {}: {why}", aa.name());
    }
    Ok(aa)
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
        return Ok(Raster::Hardware);
    }
    let (raster, why) = on_own_context((validation, device_index), "timing the rasterisers for --raster auto", |ctx| {
        resolve_raster(ctx, scene, settings, choice)
    })?;
    if let Some(why) = why {
        println!("auto raster: {}: {why}", raster.name());
    }
    Ok(raster)
}

/// `--raster auto`'s order of preference (the compute raster was the fastest wherever a GPU
/// measured it): the first within PICK_MARGIN of the fastest is kept.
fn raster_rank(raster: &Raster) -> u8 {
    match raster {
        Raster::Compute { large: LargeTriangles::Bins { .. }, .. } => 0,
        Raster::Compute { large: LargeTriangles::Hardware, .. } => 1,
        Raster::Hardware => 2,
    }
}

/// Render `scene` with `settings` and each of `candidates`, timed in this order (the
/// hardware's, cheap on every device, first: the slow ones then leave after a frame), and keep
/// the first of the order of preference within the margin of the fastest; the line that says
/// so.
pub fn pick_raster(ctx: &Context, scene: &Scene, settings: &RenderSettings, candidates: &[Raster]) -> Result<(Raster, String)> {
    let mut timed: Vec<Timed<Raster>> = Vec::new();
    for &raster in candidates {
        let best = timed.iter().map(|t| t.ms).fold(f64::INFINITY, f64::min);
        timed.push(time_renders(ctx, scene, RenderSettings { raster, ..*settings }, best)?.of(raster));
    }
    let mut preference = candidates.to_vec();
    preference.sort_by_key(raster_rank);
    let picked = pick_within_margin(&timed, &preference);
    let order: Vec<&str> = preference.iter().map(|r| r.name()).collect();
    Ok((picked, format!("{}; {}", describe(&timed, |r| r.name()), margin_rule(&order))))
}

/// Frames each candidate renders in auto's scene probes, after its warm-up.
pub const PROBE_FRAMES: usize = 3;
/// A candidate's warm-up on a GPU: frames for at least this much wall time (a GPU raises its
/// clocks only under load, and lowers them while the CPU makes the next candidate's
/// pipelines), and then until its frames stop getting faster (STEADY), at most
/// WARM_UP_MAX_MS; on a CPU driver one frame (no clocks to raise).
const WARM_UP_MS: f64 = 200.0;
const WARM_UP_MAX_MS: f64 = 1500.0;
/// Frames whose median is within this share of the median of the frames before them are
/// the steady state (each group WARM_UP_GROUP frames).
const STEADY: f64 = 0.03;
const WARM_UP_GROUP: usize = 5;
/// A candidate whose first timed frame takes this many times the best median so far is out
/// after that frame (on a CPU driver the slow rasters take seconds a frame).
const CLEARLY_SLOWER: f64 = 2.0;
/// auto keeps its first preference unless another candidate is faster by more than this
/// share: repeated probes on a busy machine, or a GPU whose clock moves, then pick the same.
pub const PICK_MARGIN: f64 = 0.10;

/// One candidate's frames in a scene probe: their median GPU time (wall time on a device
/// without timestamps) and how many were timed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Timed<T> {
    pub candidate: T,
    pub ms: f64,
    pub frames: usize,
}

/// A median and a frame count not yet tied to a candidate.
struct Frames(f64, usize);

impl Frames {
    fn of<T>(self, candidate: T) -> Timed<T> {
        Timed { candidate, ms: self.0, frames: self.1 }
    }
}

/// `scene` rendered with `settings` one frame at a time: warmed up, then PROBE_FRAMES frames
/// timed, and their median. A candidate is out after one frame where that frame takes
/// CLEARLY_SLOWER times `best` (the best median so far): the first timed one, or the warm-up's
/// only one where that alone lasted the warm-up's time (seconds a frame, a CPU driver).
fn time_renders(ctx: &Context, scene: &Scene, settings: RenderSettings, best: f64) -> Result<Frames> {
    let mut renderer = Renderer::new(ctx, scene.clone(), RenderSettings { frames: 1, ..settings })?;
    let mut frame = || -> Result<f64> {
        let stats = renderer.render()?.stats;
        Ok(stats.gpu_ms().map_or(stats.wall_ms_per_frame(), |passes| passes.iter().map(|(_, ms)| ms).sum()))
    };
    let start = std::time::Instant::now();
    let elapsed_ms = || start.elapsed().as_secs_f64() * 1e3;
    let first = frame()?;
    if ctx.info.device_type == ml_vk::vk::PhysicalDeviceType::CPU || elapsed_ms() >= WARM_UP_MS {
        // One frame took the warm-up's time (a CPU driver warms up in one): a candidate
        // clearly slower than the best is out after it.
        if first > CLEARLY_SLOWER * best {
            return Ok(Frames(first, 1));
        }
    } else {
        let mut warm = vec![first];
        while elapsed_ms() < WARM_UP_MAX_MS && !(elapsed_ms() >= WARM_UP_MS && steady(&warm)) {
            warm.push(frame()?);
        }
    }
    let mut times = Vec::new();
    while times.len() < PROBE_FRAMES {
        times.push(frame()?);
        if times[0] > CLEARLY_SLOWER * best {
            break;
        }
    }
    times.sort_by(f64::total_cmp);
    Ok(Frames(times[times.len() / 2], times.len()))
}

/// Whether the last WARM_UP_GROUP frames of `times` are as fast as the group before them
/// (within STEADY): the clocks have stopped rising.
fn steady(times: &[f64]) -> bool {
    let n = times.len();
    if n < 2 * WARM_UP_GROUP {
        return false;
    }
    let median = |group: &[f64]| {
        let mut g = group.to_vec();
        g.sort_by(f64::total_cmp);
        g[g.len() / 2]
    };
    let (before, last) = (median(&times[n - 2 * WARM_UP_GROUP..n - WARM_UP_GROUP]), median(&times[n - WARM_UP_GROUP..]));
    last >= before * (1.0 - STEADY)
}

/// The first of `preference` among `timed` whose time is within PICK_MARGIN of the fastest.
pub fn pick_within_margin<T: Copy + PartialEq>(timed: &[Timed<T>], preference: &[T]) -> T {
    let fastest = timed.iter().map(|t| t.ms).fold(f64::INFINITY, f64::min);
    preference
        .iter()
        .filter_map(|p| timed.iter().find(|t| t.candidate == *p))
        .find(|t| t.ms <= fastest * (1.0 + PICK_MARGIN))
        .map_or_else(|| timed.iter().min_by(|a, b| a.ms.total_cmp(&b.ms)).expect("a candidate").candidate, |t| t.candidate)
}

/// What the probe measured, e.g. "a frame of this scene took 0.958 ms compute, 1.467 ms
/// hardware (medians of 3 frames after a warm-up; hybrid out after one frame)".
fn describe<T>(timed: &[Timed<T>], name: impl Fn(&T) -> &'static str) -> String {
    let each: Vec<String> = timed.iter().map(|t| format!("{:.3} ms {}", t.ms, name(&t.candidate))).collect();
    let out: Vec<&str> = timed.iter().filter(|t| t.frames < PROBE_FRAMES).map(|t| name(&t.candidate)).collect();
    let out = if out.is_empty() { String::new() } else { format!("; {} out after one frame", out.join(", ")) };
    format!("a frame of this scene took {} (medians of {PROBE_FRAMES} frames after a warm-up{out})", each.join(", "))
}

/// How auto chose among `order`.
fn margin_rule(order: &[&str]) -> String {
    format!("kept: the first of {} within {:.0} % of the fastest", order.join(", "), PICK_MARGIN * 100.0)
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

    /// The first preference within the margin of the fastest, however the candidates were
    /// timed; beyond it, the fastest.
    #[test]
    fn the_first_preference_within_the_margin_is_kept() {
        let t = |candidate, ms| Timed { candidate, ms, frames: PROBE_FRAMES };
        let order = ["compute", "hybrid", "hardware"];
        assert_eq!(pick_within_margin(&[t("hardware", 1.0), t("hybrid", 2.0), t("compute", 1.09)], &order), "compute");
        assert_eq!(pick_within_margin(&[t("hardware", 1.0), t("hybrid", 1.05), t("compute", 1.2)], &order), "hybrid");
        assert_eq!(pick_within_margin(&[t("hardware", 1.0), t("hybrid", 1.2), t("compute", 1.2)], &order), "hardware");
        assert_eq!(pick_within_margin(&[t("hardware", 0.3), t("compute", 3.0)], &order), "hardware");
        // Timed but not in the order: still a candidate.
        assert_eq!(pick_within_margin(&[t("other", 0.5), t("compute", 3.0)], &order), "other");
        let line = describe(&[t("hardware", 1.0), Timed { candidate: "compute", ms: 9.0, frames: 1 }], |n| n);
        assert!(line.contains("1.000 ms hardware, 9.000 ms compute") && line.ends_with("compute out after one frame)"), "{line}");
    }

    /// The warm-up ends once a group of frames is no faster than the group before it.
    #[test]
    fn frames_are_steady_once_they_stop_getting_faster() {
        let rising: Vec<f64> = (0..10).map(|i| 2.0 - 0.1 * i as f64).collect();
        assert!(!steady(&rising), "still getting faster");
        assert!(steady(&[1.0; 10]) && steady(&[1.0, 1.0, 1.0, 1.0, 1.0, 1.02, 0.99, 1.0, 0.98, 1.01]));
        assert!(!steady(&[1.0; 9]), "too few frames to tell");
        let mut settled = rising.clone();
        settled.extend([1.0; 10]);
        assert!(steady(&settled));
    }

    #[test]
    fn auto_is_a_choice_and_unknown_names_say_so() {
        assert_eq!(technique_choice("auto").unwrap(), None);
        assert_eq!(technique_choice("deferred-compute").unwrap(), Some(Technique::DeferredCompute));
        let e = technique_choice("raytracing").unwrap_err().to_string();
        assert!(e.contains("raytracing") && e.ends_with("or auto"), "{e}");
    }
}
