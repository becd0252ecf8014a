//! Sequences on a render farm (docs/farm.md), each rendered in shards and equal, byte for byte,
//! to the sequence one process renders:
//! - on a real scheduler: a single-machine Slurm cluster — Debian's slurm-wlm and munge, which
//!   `scripts/setup.sh tests` installs — started in a temporary folder as the user running the
//!   tests (its own munge key and socket, its own ports), runs docs/farm/sequence.sh as a job
//!   array of 4 tasks; every task renders its block of the frames;
//! - docs/farm/indexed-job.yaml's container command, run once per completion index with the
//!   variables Kubernetes gives each pod (no Kubernetes runs here: this checks the manifest's
//!   command and its use of the index, not a cluster).
//!
//! What farm.md shows of the two is what the files hold.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// The daemons of the test's cluster, stopped when it ends (even by a failed assertion).
struct Cluster {
    dir: PathBuf,
}

impl Drop for Cluster {
    fn drop(&mut self) {
        for daemon in ["slurmd", "slurmctld", "munged"] {
            if let Ok(pid) = std::fs::read_to_string(self.dir.join(format!("{daemon}.pid"))) {
                let _ = Command::new("kill").arg(pid.trim()).status();
            }
        }
    }
}

/// A program of slurm-wlm or munge: on the PATH, or where Debian puts the daemons.
fn program(name: &str) -> PathBuf {
    let on_path = std::env::var_os("PATH").map(|p| std::env::split_paths(&p).map(|d| d.join(name)).find(|f| f.is_file()));
    on_path
        .flatten()
        .or_else(|| ["/usr/sbin", "/usr/bin"].map(|d| Path::new(d).join(name)).into_iter().find(|f| f.is_file()))
        .unwrap_or_else(|| panic!("{name} is missing: the tests need slurm-wlm and munge (bash scripts/setup.sh tests installs them)"))
}

/// The sequence the tests render in shards: 8 frames, small.
const SEQUENCE: [&str; 14] =
    ["--scene", "seed", "--technique", "forward", "--lights", "64", "--width", "64", "--height", "36", "--frames", "8", "--exposure", "0"];

fn docs(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs").join(name)
}

fn farm_md() -> String {
    std::fs::read_to_string(docs("farm.md")).unwrap()
}

/// PATH with the manylights under test first (the scripts call `manylights`).
fn path_with_manylights() -> std::ffi::OsString {
    let binary = Path::new(env!("CARGO_BIN_EXE_manylights"));
    let rest: Vec<PathBuf> = std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()).collect();
    std::env::join_paths(std::iter::once(binary.parent().unwrap().to_path_buf()).chain(rest)).unwrap()
}

/// The frames in `sharded` are SEQUENCE's frames as one process renders them (into `whole`).
fn assert_one_process_frames(sharded: &Path, whole: &Path) {
    run(Command::new(env!("CARGO_BIN_EXE_manylights")).arg("render").args(SEQUENCE).arg("--out").arg(whole.join("####.png")));
    for frame in 0..8 {
        let name = format!("{frame:04}.png");
        let (a, b) = (std::fs::read(sharded.join(&name)).unwrap(), std::fs::read(whole.join(&name)).unwrap());
        assert!(a == b, "frame {frame} differs between the shards and one process");
    }
}

fn run(command: &mut Command) -> Output {
    let out = command.output().unwrap_or_else(|e| panic!("{command:?}: {e}"));
    assert!(out.status.success(), "{command:?}: {}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    out
}

/// slurm.conf of one node (this machine, `cpus` CPUs) whose files all lie in `dir`.
fn slurm_conf(dir: &Path, host: &str, cpus: usize, port: u32) -> String {
    let user = String::from_utf8(run(Command::new("id").arg("-un")).stdout).unwrap();
    let d = dir.display();
    format!(
        "ClusterName=manylights-test\nSlurmctldHost={host}\nSlurmUser={user}\nSlurmdUser={user}\n\
         AuthType=auth/munge\nAuthInfo=socket={d}/munge.socket\nCredType=cred/munge\n\
         StateSaveLocation={d}/state\nSlurmdSpoolDir={d}/spool\nSlurmctldPidFile={d}/slurmctld.pid\nSlurmdPidFile={d}/slurmd.pid\n\
         SlurmctldLogFile={d}/slurmctld.log\nSlurmdLogFile={d}/slurmd.log\nSlurmctldPort={port}\nSlurmdPort={}\n\
         ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nJobAcctGatherType=jobacct_gather/none\n\
         AccountingStorageType=accounting_storage/none\nSchedulerType=sched/builtin\nSelectType=select/cons_tres\n\
         SelectTypeParameters=CR_CPU\nReturnToService=2\nMpiDefault=none\n\
         NodeName={host} CPUs={cpus} State=UNKNOWN\nPartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP\n",
        port + 1,
        user = user.trim()
    )
}

#[test]
fn a_slurm_job_array_renders_the_sequence_one_process_renders() {
    let dir = std::env::temp_dir().join(format!("manylights-slurm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for sub in ["state", "spool", "frames", "whole"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    // munge: a key of our own (any 1,024 bytes; munged wants it private), on a socket of ours.
    let key = dir.join("munge.key");
    let mut seed = std::process::id() as u64 | 1;
    let bytes: Vec<u8> = (0..1024)
        .map(|_| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed as u8
        })
        .collect();
    std::fs::write(&key, bytes).unwrap();
    run(Command::new("chmod").arg("600").arg(&key));
    let host = String::from_utf8(run(Command::new("hostname").arg("-s")).stdout).unwrap().trim().to_owned();
    let cpus = std::thread::available_parallelism().map_or(1, |n| n.get());
    let port = 20_000 + std::process::id() % 20_000;
    let conf = dir.join("slurm.conf");
    std::fs::write(&conf, slurm_conf(&dir, &host, cpus, port)).unwrap();
    let cluster = Cluster { dir: dir.clone() };
    let file = |name: &str| dir.join(name);
    run(Command::new(program("munged")).arg("--force").arg(format!("--key-file={}", key.display())).args([
        format!("--socket={}", file("munge.socket").display()),
        format!("--pid-file={}", file("munged.pid").display()),
        format!("--log-file={}", file("munged.log").display()),
        format!("--seed-file={}", file("munged.seed").display()),
    ]));
    run(Command::new(program("slurmctld")).arg("-f").arg(&conf));
    run(Command::new(program("slurmd")).arg("-f").arg(&conf));
    // The node takes a moment to register.
    let started = Instant::now();
    loop {
        let sinfo = Command::new(program("sinfo")).args(["-h", "-o", "%t"]).env("SLURM_CONF", &conf).output().unwrap();
        if String::from_utf8_lossy(&sinfo.stdout).trim() == "idle" {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the node never became idle: {}",
            std::fs::read_to_string(file("slurmd.log")).unwrap_or_default()
        );
        std::thread::sleep(Duration::from_millis(200));
    }

    let script = docs("farm/sequence.sh");
    let lines = std::fs::read_to_string(&script).unwrap();
    let body: String = lines.lines().filter(|l| l.starts_with("#SBATCH") || l.starts_with("exec")).map(|l| format!("{l}\n")).collect();
    assert!(farm_md().contains(&body), "docs/farm.md does not show the script it names:\n{body}");
    run(Command::new(program("sbatch"))
        .arg("--wait")
        .arg(format!("--output={}/task-%a.out", dir.display()))
        .arg(&script)
        .args(SEQUENCE)
        .arg("--out")
        .arg(dir.join("frames/####.png"))
        .env("SLURM_CONF", &conf)
        .env("PATH", path_with_manylights()));
    // Each task rendered its block: two of the eight frames.
    for task in 0..4 {
        let log = std::fs::read_to_string(file(&format!("task-{task}.out"))).unwrap();
        assert!(log.contains("2 frames written"), "task {task}: {log}");
    }
    assert_one_process_frames(&dir.join("frames"), &dir.join("whole"));
    drop(cluster);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_indexed_jobs_pods_render_the_sequence_one_process_renders() {
    let manifest = std::fs::read_to_string(docs("farm/indexed-job.yaml")).unwrap();
    // The manifest's lines this test reads: the completions, the container's command and args
    // (YAML flow lists of JSON strings).
    let line =
        |key: &str| manifest.lines().map(str::trim).find_map(|l| l.strip_prefix(key)).unwrap_or_else(|| panic!("no {key} in the manifest"));
    let completions: u32 = line("completions:").trim().parse().unwrap();
    let command: Vec<String> = serde_json::from_str(line("command:")).unwrap();
    let args: Vec<String> = serde_json::from_str(line("args:")).unwrap();
    assert!(args[0].contains(&format!("--shard $SHARD/{completions}")), "the command's shard count is not the Job's completions: {args:?}");
    let index = "fieldPath: \"metadata.annotations['batch.kubernetes.io/job-completion-index']\"";
    for shown in [line("command:"), line("args:"), index] {
        assert!(manifest.contains(shown) && farm_md().contains(shown), "docs/farm.md does not show the manifest's {shown}");
    }
    let dir = std::env::temp_dir().join(format!("manylights-indexed-job-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let render_args = format!("{} --out {}/pods/####.png", SEQUENCE.join(" "), dir.display());
    for pod in 0..completions {
        run(Command::new(&command[0])
            .args(&command[1..])
            .args(&args)
            .env("SHARD", pod.to_string())
            .env("RENDER_ARGS", &render_args)
            .env("PATH", path_with_manylights()));
    }
    assert_one_process_frames(&dir.join("pods"), &dir.join("whole"));
    std::fs::remove_dir_all(&dir).ok();
}
