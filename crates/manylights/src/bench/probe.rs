//! `manylights bench --probe`: the compute-vs-fragment probe (ml_render::stage_probe) at the
//! bench's resolution for several loop lengths — fragment and compute time (median, p95) and
//! their ratio — written to probe.csv and probe.json, with what `--technique auto` makes of
//! the longest loop measured.

use super::sheet::spread_json;
use super::BenchArgs;
use anyhow::{bail, Result};
use ml_render::stage_probe::{pick_lighting_path, StageProbe, StageTimes};
use ml_vk::Context;
use serde_json::{json, Value};

/// The longest loop --probe-lights accepts.
pub const MAX_LIGHTS: u32 = 65_536;

/// One loop length: measured, or skipped with the reason.
pub struct ProbeRow {
    lights: u32,
    outcome: Result<StageTimes, String>,
}

pub fn run(ctx: &Context, a: &BenchArgs, (w, h): (u32, u32), lengths: &[u32]) -> Result<Vec<ProbeRow>> {
    let max = ctx.info.limits.max_image_dimension2_d;
    if w == 0 || h == 0 || w > max || h > max {
        bail!("--resolution {w}x{h}: each side must be 1 to {max} on this device");
    }
    let longest = lengths.last().copied().unwrap_or(1);
    let mut probe = StageProbe::new(ctx, w, h, longest)?;
    let rows = measure_all(ctx, a, &mut probe, lengths);
    probe.destroy(ctx);
    rows
}

fn measure_all(ctx: &Context, a: &BenchArgs, probe: &mut StageProbe, lengths: &[u32]) -> Result<Vec<ProbeRow>> {
    let rounds = a.rounds()?;
    let bar = indicatif::ProgressBar::new(lengths.len() as u64);
    bar.set_style(indicatif::ProgressStyle::with_template("{bar:30} {pos}/{len} {msg}").expect("a valid template"));
    let mut rows = Vec::new();
    // (lights, ms of one fragment + one compute pass) of the last length measured.
    let mut previous: Option<(u32, f64)> = None;
    for &lights in lengths {
        bar.set_message(format!("probe at {lights} lights per pixel"));
        // The time grows linearly with the loop; the first length is estimated from one round.
        let (ms, how) = match previous {
            Some((n, ms)) => (ms * f64::from(lights) / f64::from(n), format!("scaled from {n} lights")),
            None => {
                let t = probe.measure(ctx, lights, 0, 1)?;
                (t.fragment.median + t.compute.median, "one round measured".to_owned())
            }
        };
        let estimate_s = ms * f64::from(rounds) / 1e3;
        if estimate_s > a.budget_s {
            let why =
                format!("skipped: {rounds} rounds would take about {estimate_s:.0} s ({ms:.0} ms a round, {how}; budget {} s)", a.budget_s);
            rows.push(ProbeRow { lights, outcome: Err(why) });
            bar.inc(1);
            continue;
        }
        let t = probe.measure(ctx, lights, a.warmup, a.frames)?;
        previous = Some((lights, t.fragment.mean + t.compute.mean));
        rows.push(ProbeRow { lights, outcome: Ok(t) });
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(rows)
}

pub fn times_json(t: &StageTimes) -> Value {
    json!({
        "lights": t.lights,
        "pixels": t.pixels,
        "fragment": spread_json(&t.fragment),
        "compute": spread_json(&t.compute),
        "ratio": t.ratio(),
        "clock": clock(t),
    })
}

fn clock(t: &StageTimes) -> &'static str {
    if t.timestamps {
        "gpu timestamps"
    } else {
        "wall time per submission"
    }
}

/// `meshlets`: whether the device runs the meshlet techniques (what `auto` picks depends on it).
pub fn write(a: &BenchArgs, (w, h): (u32, u32), device: &Value, meshlets: bool, rows: &[ProbeRow]) -> Result<()> {
    let mut csv =
        String::from("lights,width,height,frames,status,fragment_median_ms,fragment_p95_ms,compute_median_ms,compute_p95_ms,ratio,clock\n");
    let mut json_rows = Vec::new();
    for r in rows {
        let head = format!("{},{w},{h},{}", r.lights, a.frames);
        match &r.outcome {
            Ok(t) => {
                csv += &format!(
                    "{head},measured,{:.4},{:.4},{:.4},{:.4},{:.3},{}\n",
                    t.fragment.median,
                    t.fragment.p95,
                    t.compute.median,
                    t.compute.p95,
                    t.ratio(),
                    clock(t)
                );
                json_rows.push(json!({ "status": "measured", "times": times_json(t) }));
            }
            Err(why) => {
                csv += &format!("{head},\"{why}\",,,,,,\n");
                json_rows.push(json!({ "lights": r.lights, "status": why }));
            }
        }
    }
    let longest = rows.iter().rev().find_map(|r| r.outcome.as_ref().ok());
    let pick = longest.map(|t| pick_lighting_path(t, meshlets));
    let report = json!({
        "device": device,
        "commit": env!("MANYLIGHTS_COMMIT"),
        "settings": {
            "resolution": [w, h], "frames": a.frames, "warmup": a.warmup, "budget_s": a.budget_s,
            "probe_lights": a.probe_lights,
        },
        "auto": pick.as_ref().map(|(technique, why)| json!({ "technique": technique.name(), "why": why })),
        "results": json_rows,
    });
    // The two replace an earlier run's together, or neither does.
    let json = serde_json::to_string_pretty(&report).expect("plain JSON values");
    let [csv_path, json_path] = super::PROBE_RESULTS.map(|name| a.out.join(name));
    ml_cpu::files::write_all_replacing(&[(csv_path, csv.as_bytes()), (json_path, json.as_bytes())])?;
    print!("{csv}");
    match pick {
        Some((technique, why)) => crate::auto::announce(technique, &why),
        None => println!("auto: nothing measured within the budget"),
    }
    Ok(())
}
