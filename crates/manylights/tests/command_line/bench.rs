//! `manylights bench` (docs/usage.md#bench-the-benchmark-harness): a tiny run — 3 techniques
//! (visibility with both rasterisers) × 2 light counts, 64×64, 5 frames — on lavapipe with
//! validation writes results.csv and results.json with every column and a row per pass and the
//! results.png plot, and a combination over the time budget is skipped with its reason instead
//! of run. A sweep in shards (one through Slurm's variables) joined by `--merge` is the
//! sheet of the whole sweep.

use std::process::Command;

#[test]
fn a_tiny_bench_writes_its_tables() {
    let out_dir = std::env::temp_dir().join(format!("manylights-bench-{}", std::process::id()));
    let args = ["bench", "--validation", "--techniques", "forward,clustered-gpu,visibility", "--lights", "64,1k", "--resolution", "64x64"];
    let run = Command::new(env!("CARGO_BIN_EXE_manylights"))
        .args(args)
        .args(["--frames", "3", "--warmup", "0", "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(!stderr.contains("VALIDATION"), "{stderr}");
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for column in [
        "technique",
        "raster",
        "aa",
        "lights",
        "status",
        "pass",
        "gpu_median_ms",
        "gpu_p95_ms",
        "cpu_median_ms",
        "cpu_assign_median_ms",
        "cpu_upload_median_ms",
        "cpu_record_median_ms",
        "cpu_submit_median_ms",
        "lights_per_cluster_mean",
    ] {
        assert!(header.contains(&column), "no column {column}: {header:?}");
    }
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let of = |technique: &str, raster: &str| rows.iter().filter(|r| r[col("technique")] == technique && r[col("raster")] == raster).count();
    // forward: one pass; clustered-gpu: build + shading; at 64 and 1,000 lights.
    assert_eq!((of("forward", ""), of("clustered-gpu", "")), (2, 2 * 2), "{csv}");
    // visibility, a row per pass for each rasteriser (light grid build, two phases of culling and
    // raster, the pyramid, the lighting): the compute raster's passes say so.
    assert!(of("visibility", "hardware") >= 2 * 7 && of("visibility", "compute") >= 2 * 7, "{csv}");
    for pass in ["cull + compute raster (late)", "large triangles (late)"] {
        assert!(rows.iter().any(|r| r[col("raster")] == "compute" && r[col("pass")] == pass), "{csv}");
    }
    assert_eq!(rows.len(), of("forward", "") + of("clustered-gpu", "") + of("visibility", "hardware") + of("visibility", "compute"));
    for r in &rows {
        assert_eq!(r.len(), header.len(), "{r:?}");
        assert_eq!(r[col("status")], "measured");
        assert_eq!(r[col("aa")], "off", "{r:?}");
        let (median, p95): (f64, f64) = (r[col("gpu_median_ms")].parse().unwrap(), r[col("gpu_p95_ms")].parse().unwrap());
        assert!(median > 0.0 && p95 >= median, "{r:?}");
        // CPU phases: recording takes time in every technique; only CPU-built clusters assign.
        let phase = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert!(phase("cpu_record_median_ms") > 0.0 && phase("cpu_median_ms") >= phase("cpu_record_median_ms"), "{r:?}");
        assert_eq!(phase("cpu_assign_median_ms"), 0.0, "{r:?}");
    }
    let clustered = rows.iter().find(|r| r[0] == "clustered-gpu" && r[col("lights")] == "1000").unwrap();
    // clustered-gpu assigns to the light grid: no cluster grid to report.
    assert_eq!((clustered[col("clusters")], clustered[col("lights_per_cluster_mean")]), ("", ""), "{clustered:?}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("results.json")).unwrap()).unwrap();
    assert!(json["device"]["name"].is_string() && json["commit"].is_string(), "{json}");
    assert_eq!(json["settings"]["frames"], 3);
    assert_eq!(json["results"].as_array().unwrap().len(), 8);
    assert_eq!(json["results"][3]["raster"], "compute", "{json}");
    // What auto would run here, from the quick probe.
    assert!(["visibility", "deferred-compute", "deferred-clustered"].contains(&json["auto"]["technique"].as_str().unwrap()), "{json}");
    assert!(json["auto"]["probe"]["ratio"].as_f64().unwrap() > 0.0, "{json}");
    // The plot: frame time against lights, a line per technique.
    let plot = image::open(out_dir.join("results.png")).expect("results.png").to_rgb8();
    assert_eq!(plot.dimensions(), (960, 600));
    let coloured = plot.pixels().filter(|p| p.0.iter().max().unwrap() - p.0.iter().min().unwrap() > 100).count();
    assert!(coloured > 500, "the plot has no coloured lines ({coloured} pixels)");

    // A budget no frame fits: every combination is skipped and says why; at 1M lights from the
    // estimate at 64 (scaled linearly), without rendering a frame of them. And 16 samples a
    // pixel, which lavapipe's (and the H200's) attachments do not take: a row that says so,
    // not the end of the sweep (a device that takes them skips it for the budget).
    let skipped = Command::new(env!("CARGO_BIN_EXE_manylights"))
        .args(["bench", "--techniques", "forward,clustered-gpu", "--lights", "64,1M", "--resolution", "32x32", "--aa", "off,16"])
        .args(["--frames", "3", "--warmup", "0", "--budget-s", "0.000001", "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(skipped.status.success(), "{}", String::from_utf8_lossy(&skipped.stderr));
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    let (rows, sixteen): (Vec<&str>, Vec<&str>) = csv.lines().skip(1).partition(|r| r.contains(",off,"));
    assert_eq!((rows.len(), sixteen.len()), (4, 4), "{csv}");
    for r in &sixteen {
        assert!(r.contains(",16,") && (r.contains("\"not measured: --aa 16: ") || r.contains("skipped: ")), "{csv}");
    }
    assert!(rows[0].starts_with("forward,,off,64,") && rows[0].contains("skipped: 3 frames would take"), "{csv}");
    assert!(rows[0].contains("one frame measured") && rows[1].contains("one frame measured"), "{csv}");
    assert!(rows[2].starts_with("forward,,off,1000000,") && rows[2].contains("scaled from 64 lights"), "{csv}");
    assert!(rows[3].contains("skipped: one frame would take about") && rows[3].contains("scaled from 64 lights"), "{csv}");
}

/// Two shards of a 4-row sweep (2 counts × 2 techniques), the second as Slurm's array task 1
/// of 2 (`--shard env`), each measuring its block; `--merge` writes the whole sweep's sheet:
/// the rows in the sweep's order, the table the shards' tables end to end; a missing, repeated
/// or foreign shard is refused in one line.
#[test]
fn shards_measure_their_block_and_merge_into_the_whole_sheet() {
    let dir = std::env::temp_dir().join(format!("manylights-bench-shards-{}", std::process::id()));
    let folder = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let sweep = ["bench", "--techniques", "forward,clustered-gpu", "--lights", "64,1k", "--resolution", "32x32", "--frames", "2"];
    let run = |shard: &str, out: &str, slurm: Option<&str>| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_manylights"));
        command.args(sweep).args(["--warmup", "0", "--aa", "off", "--shard", shard, "--out", out]);
        command.env_remove("SLURM_ARRAY_TASK_MIN");
        if let Some(task) = slurm {
            command.env("SLURM_ARRAY_TASK_ID", task).env("SLURM_ARRAY_TASK_COUNT", "2");
        }
        let output = command.output().unwrap();
        assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    };
    run("0/2", &folder("a"), None);
    run("env", &folder("b"), Some("1"));
    let sheet = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(name).join("results.json")).unwrap()).unwrap()
    };
    let rows_of = |s: &serde_json::Value| -> Vec<(u64, String, u64)> {
        s["results"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| (r["row"].as_u64().unwrap(), r["technique"].as_str().unwrap().to_owned(), r["lights"].as_u64().unwrap()))
            .collect()
    };
    let (a, b) = (sheet("a"), sheet("b"));
    assert_eq!((a["shard"]["index"].as_u64(), b["shard"]["index"].as_u64(), a["rows"].as_u64()), (Some(0), Some(1), Some(4)), "{a}\n{b}");
    assert_eq!(rows_of(&a), [(0, "forward".to_owned(), 64), (1, "clustered-gpu".to_owned(), 64)]);
    assert_eq!(rows_of(&b), [(2, "forward".to_owned(), 1000), (3, "clustered-gpu".to_owned(), 1000)]);
    let merge = |folders: &str, extra: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_manylights"))
            .args(["bench", "--merge", folders, "--out", &folder("whole")])
            .args(extra)
            .output()
            .unwrap()
    };
    let merged = merge(&format!("{},{}", folder("b"), folder("a")), &[]);
    assert!(merged.status.success(), "{}", String::from_utf8_lossy(&merged.stderr));
    let whole = sheet("whole");
    assert!(whole.get("shard").is_none() && whole["rows"] == 4, "{whole}");
    assert_eq!(rows_of(&whole), [rows_of(&a), rows_of(&b)].concat());
    let table = |name: &str| std::fs::read_to_string(dir.join(name).join("results.csv")).unwrap();
    let (ta, tb) = (table("a"), table("b"));
    let header = ta.lines().next().unwrap();
    assert_eq!(table("whole"), format!("{header}\n{}{}", &ta[header.len() + 1..], &tb[header.len() + 1..]));
    assert!(image::open(dir.join("whole").join("results.png")).is_ok());
    for (folders, extra, says) in [
        (folder("a"), &[][..], "shard 1 of 2 is missing"),
        (format!("{},{}", folder("a"), folder("a")), &[][..], "shard 0 of 2 is given twice"),
        (format!("{},{}", folder("a"), folder("b")), &["--frames", "3"][..], "--frames does not apply to bench --merge"),
        (folder("nothing"), &[][..], "--merge: cannot read"),
    ] {
        let refused = merge(&folders, extra);
        let stderr = String::from_utf8_lossy(&refused.stderr);
        assert!(!refused.status.success() && stderr.contains(says) && stderr.trim().lines().count() == 1, "{stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_bench_arguments_are_one_error_line() {
    for (args, needle) in [
        (&["bench", "--lights", "many"][..], "not a light count"),
        (&["bench", "--techniques", "raytracing"][..], "raytracing"),
        (&["bench", "--resolution", "big"][..], "expected WxH"),
        (&["bench", "--raster", "hardware,sideways"][..], "rasteriser 'sideways' in --raster"),
        (&["bench", "--probe", "--probe-lights", "100k"][..], "at most 65536 lights per pixel"),
        (&["bench", "--probe", "--resolution", "0x10"][..], "each side must be 1 to"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_manylights")).args(args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.lines().count() == 1 && stderr.contains(needle), "{args:?}: {stderr}");
    }
}

/// `bench --probe`: both kinds of pass timed over the same pixels per loop length, the ratio
/// and auto's pick written to probe.csv and probe.json; a length over the budget is skipped.
#[test]
fn the_probe_writes_its_ratios() {
    let out_dir = std::env::temp_dir().join(format!("manylights-probe-{}", std::process::id()));
    let run = Command::new(env!("CARGO_BIN_EXE_manylights"))
        .args(["bench", "--probe", "--validation", "--resolution", "64x48", "--frames", "3", "--warmup", "1"])
        .args(["--probe-lights", "4,16", "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    assert!(run.status.success() && !stderr.contains("VALIDATION"), "{stderr}");
    assert!(stdout.lines().any(|l| l.starts_with("auto: deferred-c") || l.starts_with("auto: visibility")), "{stdout}");
    let csv = std::fs::read_to_string(out_dir.join("probe.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name}: {header:?}"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.iter().map(|r| r[col("lights")]).collect::<Vec<_>>(), ["4", "16"], "{csv}");
    for r in &rows {
        assert_eq!((r.len(), r[col("status")], r[col("width")], r[col("height")]), (header.len(), "measured", "64", "48"), "{r:?}");
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        assert!(num("fragment_median_ms") > 0.0 && num("fragment_p95_ms") >= num("fragment_median_ms"), "{r:?}");
        assert!(num("compute_median_ms") > 0.0 && num("compute_p95_ms") >= num("compute_median_ms"), "{r:?}");
        let ratio = num("fragment_median_ms") / num("compute_median_ms");
        assert!((num("ratio") - ratio).abs() <= 0.01 * ratio, "{r:?}");
    }
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out_dir.join("probe.json")).unwrap()).unwrap();
    assert!(json["device"]["name"].is_string() && json["auto"]["technique"].is_string(), "{json}");
    assert_eq!(json["results"][1]["times"]["lights"], 16);

    // No round fits the budget: the length is skipped and says why.
    let skipped = Command::new(env!("CARGO_BIN_EXE_manylights"))
        .args(["bench", "--probe", "--resolution", "32x32", "--frames", "2", "--warmup", "0", "--probe-lights", "8"])
        .args(["--budget-s", "0.000001", "--out", out_dir.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(skipped.status.success(), "{}", String::from_utf8_lossy(&skipped.stderr));
    let csv = std::fs::read_to_string(out_dir.join("probe.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().contains("skipped: 2 rounds would take"), "{csv}");
    assert!(String::from_utf8_lossy(&skipped.stdout).contains("auto: nothing measured"));
}

/// On a CPU driver (as CI's lavapipe is) a bench without --resolution, --frames, --warmup
/// and --lights measures what the driver can finish, says so, and writes its plot; a bench
/// whose every combination is skipped writes a plot too, an empty one.
#[test]
fn a_bench_on_a_cpu_picks_what_it_can_finish_and_always_plots() {
    let out_dir = std::env::temp_dir().join(format!("manylights-bench-cpu-{}", std::process::id()));
    let run = |extra: &[&str]| {
        let run = Command::new(env!("CARGO_BIN_EXE_manylights"))
            .args(["bench", "--techniques", "clustered-gpu", "--out", out_dir.to_str().unwrap()])
            .args(extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr).into_owned();
        assert!(run.status.success(), "{stderr}");
        stderr
    };
    let stderr = run(&["--lights", "1k"]);
    let info = Command::new(env!("CARGO_BIN_EXE_manylights")).arg("info").output().unwrap();
    if String::from_utf8_lossy(&info.stdout).contains("CPU") {
        assert!(stderr.contains("is a CPU driver: measuring --resolution 320x180 --frames 5 --warmup 1"), "{stderr}");
        assert!(!stderr.contains("--lights 1k,16k"), "--lights was given: {stderr}");
        let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
        assert!(csv.contains(",1000,320,180,5,measured,"), "{csv}");
    }
    assert!(out_dir.join("results.png").is_file());
    std::fs::remove_file(out_dir.join("results.png")).unwrap();
    run(&["--lights", "1k", "--resolution", "64x36", "--frames", "2", "--budget-s", "0.000001"]);
    let csv = std::fs::read_to_string(out_dir.join("results.csv")).unwrap();
    assert!(!csv.contains(",measured,"), "{csv}");
    assert!(out_dir.join("results.png").is_file(), "no plot where nothing was measured");
}
