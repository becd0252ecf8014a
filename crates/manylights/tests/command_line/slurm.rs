//! Sequences on a real scheduler (docs/farm.md): a single-machine Slurm cluster — Debian's
//! slurm-wlm and munge, which `scripts/setup.sh tests` installs — started in a temporary
//! folder as the user running the tests (its own munge key and socket, its own ports), runs
//! docs/farm/sequence.sh as a job array of 4 tasks. Every task renders its block of the frames
//! and the sequence equals the one a single process renders, byte for byte; the script farm.md
//! shows is the file the test runs.

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

    let binary = Path::new(env!("CARGO_BIN_EXE_manylights"));
    let path = std::env::join_paths(
        std::iter::once(binary.parent().unwrap().to_path_buf()).chain(std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default())),
    )
    .unwrap();
    let sequence = [
        "--scene",
        "seed",
        "--technique",
        "forward",
        "--lights",
        "64",
        "--width",
        "64",
        "--height",
        "36",
        "--frames",
        "8",
        "--exposure",
        "0",
    ];
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/farm/sequence.sh");
    let farm = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/farm.md")).unwrap();
    let body: String = std::fs::read_to_string(&script)
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("#SBATCH") || l.starts_with("exec"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(farm.contains(&body), "docs/farm.md does not show the script it names:\n{body}");
    run(Command::new(program("sbatch"))
        .arg("--wait")
        .arg(format!("--output={}/task-%a.out", dir.display()))
        .arg(&script)
        .args(sequence)
        .arg("--out")
        .arg(dir.join("frames/####.png"))
        .env("SLURM_CONF", &conf)
        .env("PATH", &path));
    // Each task rendered its block: two of the eight frames.
    for task in 0..4 {
        let log = std::fs::read_to_string(file(&format!("task-{task}.out"))).unwrap();
        assert!(log.contains("2 frames written"), "task {task}: {log}");
    }
    // One process, the whole sequence: the same bytes, frame for frame.
    run(Command::new(binary).arg("render").args(sequence).arg("--out").arg(dir.join("whole/####.png")));
    for frame in 0..8 {
        let name = format!("{frame:04}.png");
        let (sharded, whole) =
            (std::fs::read(dir.join("frames").join(&name)).unwrap(), std::fs::read(dir.join("whole").join(&name)).unwrap());
        assert!(sharded == whole, "frame {frame} differs between the job array and one process");
    }
    drop(cluster);
    std::fs::remove_dir_all(&dir).ok();
}
