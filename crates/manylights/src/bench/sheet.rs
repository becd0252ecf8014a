//! bench's result sheet: a row per combination in results.json, and results.csv and
//! results.png made from those rows alone — so a sweep measured in shards (`--shard`, each a
//! block of the rows, e.g. one Slurm array task each) and joined by `--merge` writes the
//! sheet one process measuring every row would have written.

use super::{Measured, Variant};
use anyhow::{bail, Context as _, Result};
use ml_render::report::Spread;
use ml_render::{Antialiasing, Geometry, Raster, Technique};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// What a run writes in its folder.
pub(super) const RESULTS: [&str; 3] = ["results.csv", "results.json", "results.png"];

/// The largest results.json `--merge` reads (a sweep of every technique at thousands of
/// counts is a few MB).
const MAX_SHEET_BYTES: u64 = 256 << 20;

pub(super) fn spread_json(s: &Spread) -> Value {
    json!({ "median_ms": s.median, "p95_ms": s.p95, "mean_ms": s.mean })
}

/// Row `row` of the sweep (its place among every combination, shards or not) as results.json
/// keeps it: what was measured, or why not.
pub(super) fn row_json(row: usize, m: &Measured, skip: usize) -> Value {
    let (technique, raster) = (m.variant.technique.name(), raster_name(m.variant));
    let aa = m.variant.antialiasing.name();
    let Some(out) = &m.output else {
        let why = m.skipped.clone().unwrap_or_default();
        return json!({ "row": row, "technique": technique, "raster": raster, "aa": aa, "lights": m.lights, "status": why });
    };
    let stats = &out.stats;
    let passes = stats.gpu_spread(skip).unwrap_or_default();
    json!({
        "row": row,
        "technique": technique,
        "raster": raster,
        "aa": aa,
        "lights": m.lights,
        "status": "measured",
        "passes": passes.iter().map(|(n, s)| json!({ "pass": n, "gpu": spread_json(s) })).collect::<Vec<_>>(),
        "cpu": stats.cpu_spread(skip).as_ref().map(|(total, phases)| {
            let mut j = json!({ "total": spread_json(total) });
            for (name, s) in phases {
                j[*name] = spread_json(s);
            }
            j
        }),
        "clusters": m.grid.map(|d| [d.x, d.y, d.z]),
        "lights_per_cluster": stats.clusters.map(|c| json!({ "mean": c.mean_lights, "max": c.max_lights })),
    })
}

/// The raster column: the visibility technique's rasteriser, empty for the others.
fn raster_name(v: Variant) -> &'static str {
    if v.technique.geometry() == Geometry::Meshlets {
        v.raster.name()
    } else {
        ""
    }
}

/// results.csv of a report: a line per pass of each measured row, one per row otherwise.
fn csv(report: &Value) -> String {
    let settings = &report["settings"];
    let (w, h, frames) = (&settings["resolution"][0], &settings["resolution"][1], &settings["frames"]);
    let mut csv = String::from(
        "technique,raster,aa,lights,width,height,frames,status,pass,gpu_median_ms,gpu_p95_ms,gpu_mean_ms,cpu_median_ms,cpu_p95_ms,cpu_assign_median_ms,cpu_upload_median_ms,cpu_record_median_ms,cpu_submit_median_ms,clusters,lights_per_cluster_mean,lights_per_cluster_max\n",
    );
    let text = |v: &Value| v.as_str().unwrap_or_default().to_owned();
    let ms = |v: &Value| format!("{:.4}", v.as_f64().unwrap_or(f64::NAN));
    for r in rows(report) {
        let head = format!("{},{},{},{},{w},{h},{frames}", text(&r["technique"]), text(&r["raster"]), text(&r["aa"]), r["lights"]);
        if r["status"] != "measured" {
            csv += &format!("{head},\"{}\",,,,,,,,,,,,,\n", text(&r["status"]));
            continue;
        }
        let cpu = &r["cpu"];
        let cpu_cols = if cpu.is_null() {
            ",,,,,".to_owned()
        } else {
            let phases: Vec<String> = ml_render::report::CpuPhases::NAMES.iter().map(|name| ms(&cpu[*name]["median_ms"])).collect();
            format!("{},{},{}", ms(&cpu["total"]["median_ms"]), ms(&cpu["total"]["p95_ms"]), phases.join(","))
        };
        let grid = r["clusters"].as_array().map_or(String::new(), |d| d.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("x"));
        let per_cluster = &r["lights_per_cluster"];
        let clusters = if per_cluster.is_null() {
            (String::new(), String::new())
        } else {
            (format!("{:.3}", per_cluster["mean"].as_f64().unwrap_or(f64::NAN)), per_cluster["max"].to_string())
        };
        let passes = r["passes"].as_array().map(Vec::as_slice).unwrap_or_default();
        if passes.is_empty() {
            csv += &format!("{head},measured (no GPU timestamps),,,,,{cpu_cols},{grid},{},{}\n", clusters.0, clusters.1);
        }
        for p in passes {
            let gpu = &p["gpu"];
            csv += &format!(
                "{head},measured,{},{},{},{},{cpu_cols},{grid},{},{}\n",
                text(&p["pass"]),
                ms(&gpu["median_ms"]),
                ms(&gpu["p95_ms"]),
                ms(&gpu["mean_ms"]),
                clusters.0,
                clusters.1
            );
        }
    }
    csv
}

fn rows(report: &Value) -> &[Value] {
    report["results"].as_array().map(Vec::as_slice).unwrap_or_default()
}

/// A row's combination, read back from its names.
fn variant_of(r: &Value) -> Option<Variant> {
    let technique = Technique::from_name(r["technique"].as_str()?).ok()?;
    let raster = match r["raster"].as_str()? {
        "" => Raster::Hardware,
        name => Raster::from_name(name, Raster::DEFAULT_SPLIT).ok()?,
    };
    let antialiasing = Antialiasing::from_name(r["aa"].as_str()?).ok()?;
    Some(Variant { technique, raster, antialiasing })
}

/// Per combination, (lights, GPU ms per frame: the pass medians summed) of each measured count.
pub(super) fn frame_times(report: &Value) -> Vec<(Variant, Vec<(f64, f64)>)> {
    let mut series: Vec<(Variant, Vec<(f64, f64)>)> = Vec::new();
    for r in rows(report) {
        let (Some(variant), Some(passes), Some(lights)) = (variant_of(r), r["passes"].as_array(), r["lights"].as_f64()) else { continue };
        if passes.is_empty() {
            continue;
        }
        let ms: f64 = passes.iter().filter_map(|p| p["gpu"]["median_ms"].as_f64()).sum();
        match series.iter_mut().find(|(v, _)| *v == variant) {
            Some((_, points)) => points.push((lights, ms)),
            None => series.push((variant, vec![(lights, ms)])),
        }
    }
    series
}

/// results.csv, results.json and results.png of `report` in `out`: the three replace an
/// earlier run's together, or none does. Prints the table.
pub(super) fn write(out: &Path, report: &Value) -> Result<()> {
    let size = (
        report["settings"]["resolution"][0].as_u64().unwrap_or(0) as u32,
        report["settings"]["resolution"][1].as_u64().unwrap_or(0) as u32,
    );
    // Always a plot, empty (and saying why) where nothing was measured.
    let (plot_size, rgb) = plot(&frame_times(report), size).map_err(|e| anyhow::anyhow!("cannot draw results.png: {e}"))?;
    let rgba: Vec<u8> = rgb.chunks_exact(3).flat_map(|p| [p[0], p[1], p[2], 255]).collect();
    let [csv_path, json_path, png_path] = RESULTS.map(|name| out.join(name));
    let png = ml_cpu::files::png_bytes(&png_path, &rgba, plot_size)?;
    let json = serde_json::to_string_pretty(report).expect("plain JSON values");
    let table = csv(report);
    ml_cpu::files::write_all_replacing(&[(csv_path, table.as_bytes()), (json_path, json.as_bytes()), (png_path, &png)])?;
    print!("{table}");
    Ok(())
}

/// The shards' sheets in `folders` joined into the one sheet of the whole sweep: every shard
/// of one run (same commit, settings, device and number of rows), each once, their rows in
/// the sweep's order. Refused in one line where a shard is missing, repeated or of another run.
pub(super) fn merge(folders: &[PathBuf]) -> Result<Value> {
    let mut sheets = Vec::new();
    for folder in folders {
        let path = folder.join("results.json");
        let bytes =
            ml_cpu::files::read_regular(&path, MAX_SHEET_BYTES).with_context(|| format!("--merge: cannot read '{}'", path.display()))?;
        let sheet: Value =
            serde_json::from_slice(&bytes).with_context(|| format!("--merge: '{}' is not a bench results.json", path.display()))?;
        let (Some(index), Some(count)) = (sheet["shard"]["index"].as_u64(), sheet["shard"]["count"].as_u64()) else {
            bail!("--merge: '{}' is not a shard's sheet (a run with --shard writes one)", path.display());
        };
        sheets.push((path, index, count, sheet));
    }
    let Some((first_path, _, count, first)) = sheets.first() else { bail!("--merge: give the shards' folders, comma-separated") };
    for (path, index, n, sheet) in &sheets {
        let differ = |what: &str| {
            anyhow::anyhow!(
                "--merge: '{}' and '{}' are shards of different runs (their {what} differ)",
                first_path.display(),
                path.display()
            )
        };
        if n != count {
            return Err(differ("shard counts"));
        }
        if let Some(key) = ["commit", "settings", "rows"].into_iter().find(|key| sheet[*key] != first[*key]) {
            return Err(differ(key));
        }
        if sheet["device"]["name"] != first["device"]["name"] {
            bail!(
                "--merge: '{}' ran on {} and '{}' on {}: their times do not compare",
                first_path.display(),
                first["device"]["name"],
                path.display(),
                sheet["device"]["name"]
            );
        }
        if sheets.iter().filter(|(_, i, _, _)| i == index).count() > 1 {
            bail!("--merge: shard {index} of {count} is given twice ('{}')", path.display());
        }
    }
    if let Some(missing) = (0..*count).find(|i| !sheets.iter().any(|(_, index, _, _)| index == i)) {
        bail!("--merge: shard {missing} of {count} is missing");
    }
    let mut results: Vec<Value> = sheets.iter().flat_map(|(_, _, _, s)| rows(s).iter().cloned()).collect();
    results.sort_by_key(|r| r["row"].as_u64());
    let total = first["rows"].as_u64().unwrap_or(0);
    if results.len() as u64 != total || results.iter().enumerate().any(|(i, r)| r["row"].as_u64() != Some(i as u64)) {
        bail!("--merge: the shards' rows are not the sweep's {total} rows, each once");
    }
    let mut merged = first.clone();
    merged.as_object_mut().expect("a JSON object").remove("shard");
    merged["results"] = Value::Array(results);
    Ok(merged)
}

/// results.png: GPU ms per frame against lights, log-log, a line per technique (the text in
/// egui's embedded Ubuntu font: no system fonts needed).
/// The frame-time plot: its size and RGB8 pixels (written by the caller, which replaces the
/// previous plot only with a complete one).
type Plot = ((u32, u32), Vec<u8>);

fn plot(series: &[(Variant, Vec<(f64, f64)>)], (w, h): (u32, u32)) -> Result<Plot, Box<dyn std::error::Error>> {
    use plotters::prelude::*;
    static FONT: std::sync::Once = std::sync::Once::new();
    FONT.call_once(|| {
        // Fails only for a broken font file, which egui's is not; text would then be missing.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
    let points = series.iter().flat_map(|(_, p)| p.iter());
    let measured = points.clone().count() > 0;
    // Nothing measured: the axes of 1k–1M lights and 0.1–100 ms, empty.
    let (x0, x1) = if measured { points.clone().fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.0), hi.max(p.0))) } else { (1e3, 1e6) };
    let (y0, y1) = if measured { points.fold((f64::MAX, f64::MIN), |(lo, hi), p| (lo.min(p.1), hi.max(p.1))) } else { (0.1, 100.0) };
    // Whole decades, so that the log axes have labels.
    let decades =
        |lo: f64, hi: f64| (10f64.powf(lo.log10().floor()), 10f64.powf(hi.log10().ceil()).max(10f64.powf(lo.log10().floor() + 1.0)));
    let ((x0, x1), (y0, y1)) = (decades(x0, x1), decades(y0, y1));
    const SIZE: (u32, u32) = (960, 600);
    let mut rgb = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            if measured {
                format!("GPU ms per frame at {w}x{h} (median)")
            } else {
                format!("GPU ms per frame at {w}x{h}: nothing measured (results.csv says why)")
            },
            ("sans-serif", 24),
        )
        .margin(16)
        // Room for the last decade's label, which is centred on the right edge.
        .margin_right(48)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("lights")
        .y_desc("GPU ms per frame")
        .x_label_formatter(&|v| count_label(*v))
        .y_label_formatter(&|v| format!("{v}"))
        .draw()?;
    for (variant, points) in series {
        // A variant keeps its colour in every plot, whichever others are in it.
        let index = Technique::ALL.iter().position(|t| *t == variant.technique).unwrap_or(0);
        let colour = Palette99::pick(if variant.raster == Raster::Hardware { index } else { Technique::ALL.len() + index }).to_rgba();
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(variant.label())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    drop(chart);
    drop(root);
    Ok((SIZE, rgb))
}

/// 1000 → 1k, 1000000 → 1M (axis labels).
pub(super) fn count_label(v: f64) -> String {
    match v {
        v if v >= 1e6 => format!("{}M", v / 1e6),
        v if v >= 1e3 => format!("{}k", v / 1e3),
        v => format!("{v:.0}"),
    }
}
