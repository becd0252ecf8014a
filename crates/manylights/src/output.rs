//! Where `render` writes: one PNG, or an image sequence of them, each replaced only once it
//! is complete (ml_cpu::files::write_png), after the path was checked before any GPU work.

use anyhow::{bail, Context as _, Result};
use ml_cpu::files;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

/// An image sequence's pattern: the name before and after its run of #, and the run's length.
pub type SequencePattern = (String, String, usize);

/// `--out`, checked before any work: a PNG's name, with a run of # for an image sequence (the
/// name before and after it and its length; None without a #). An error where # stands
/// elsewhere than in one run of the file name.
pub fn sequence_pattern(out: &Path) -> Result<Option<SequencePattern>> {
    if !out.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        bail!("--out '{}': the image is written as PNG, so its name must end in .png", out.display());
    }
    let text = out.to_string_lossy();
    let Some(first) = text.find('#') else { return Ok(None) };
    let run = text[first..].find(|c| c != '#').map_or(text.len() - first, |n| n);
    let (before, after) = (&text[..first], &text[first + run..]);
    if after.contains('#') || after.contains(std::path::MAIN_SEPARATOR) {
        bail!("--out '{text}': an image sequence's name has one run of # in the file name (e.g. frames/####.png)");
    }
    Ok(Some((before.to_owned(), after.to_owned(), run)))
}

/// Frame `i`'s file of a sequence pattern.
pub fn sequence_path((before, after, digits): &SequencePattern, i: u32) -> PathBuf {
    PathBuf::from(format!("{before}{i:0digits$}{after}"))
}

/// Fail before rendering if the image (or any of a sequence's frames `to_write`) could not be
/// written: nothing is computed for nothing, and a sequence never stops after replacing some
/// of an earlier run's frames. A sequence's folder is made for it (a single image's must
/// exist).
pub fn prepare(out: &Path, sequence: Option<&SequencePattern>, to_write: &[u32]) -> Result<()> {
    let Some(pattern) = sequence else { return Ok(files::check_writable(out)?) };
    let first = sequence_path(pattern, 0);
    if let Some(folder) = first.parent().filter(|p| !p.as_os_str().is_empty() && !p.is_dir()) {
        std::fs::create_dir_all(folder).with_context(|| format!("cannot make folder '{}'", folder.display()))?;
    }
    for &i in to_write {
        files::check_writable(&sequence_path(pattern, i))?;
    }
    Ok(())
}

/// `--shard` (I/N, or env: a Slurm array task's, its variables read through `env`) as
/// (I, N), checked: only for an image sequence, as `--resume` is.
pub fn shard_choice(shard: Option<&str>, resume: bool, sequence: bool, env: impl Fn(&str) -> Option<String>) -> Result<Option<(u32, u32)>> {
    if !sequence && (shard.is_some() || resume) {
        bail!("--shard and --resume are for an image sequence: give --out a run of # (e.g. frames/####.png)");
    }
    shard.map(|text| parse_shard(text, env)).transpose()
}

/// A `--shard` value (I/N, or env: a Slurm array task's, its variables read through `env`) as
/// (I, N), checked.
pub fn parse_shard(text: &str, env: impl Fn(&str) -> Option<String>) -> Result<(u32, u32)> {
    let (index, count) = if text == "env" {
        let var = |name: &str| {
            env(name).map(|v| v.trim().parse::<u64>().map_err(|_| anyhow::anyhow!("--shard env: {name}='{v}' is not a whole number")))
        };
        let (Some(id), Some(count)) = (var("SLURM_ARRAY_TASK_ID"), var("SLURM_ARRAY_TASK_COUNT")) else {
            bail!("--shard env: SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT are not set (not a Slurm array task): give --shard I/N");
        };
        let (id, count, min) = (id?, count?, var("SLURM_ARRAY_TASK_MIN").transpose()?.unwrap_or(0));
        match id.checked_sub(min) {
            Some(index) => (index, count),
            None => bail!("--shard env: SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"),
        }
    } else {
        let parse = |v: &str| v.trim().parse::<u64>().ok();
        match text.split_once('/').and_then(|(i, n)| Some((parse(i)?, parse(n)?))) {
            Some(pair) => pair,
            None => bail!("--shard '{text}': give I/N (shard I of N, I from 0) or env"),
        }
    };
    if count == 0 || count > 100_000 || index >= count {
        bail!("--shard {index}/{count}: the shard is one of 1 to 100000, numbered from 0");
    }
    Ok((index as u32, count as u32))
}

/// Shard (I, N)'s block of `items` in order: ⌊items·I/N⌋ up to ⌊items·(I+1)/N⌋ (all of them
/// without a shard). The blocks of 0 to N − 1 cover every item once.
pub fn shard_block(items: u64, shard: Option<(u32, u32)>) -> std::ops::Range<u64> {
    let (index, count) = shard.unwrap_or((0, 1));
    let bound = |k: u32| items * u64::from(k) / u64::from(count);
    bound(index)..bound(index + 1)
}

/// The frames a run writes, ascending: of `frames`, shard (I, N)'s ⌊F·I/N⌋ up to
/// ⌊F·(I+1)/N⌋ (every frame without one), less, where `existing` gives the sequence, those
/// whose files exist (`--resume`) — regular files: anything else at a frame's path stays to
/// be written, and `prepare` refuses it.
pub fn frames_to_write(frames: u32, shard: Option<(u32, u32)>, existing: Option<&SequencePattern>) -> Vec<u32> {
    let written = |p: &SequencePattern, i: u32| std::fs::symlink_metadata(sequence_path(p, i)).is_ok_and(|m| m.is_file());
    shard_block(u64::from(frames), shard).map(|i| i as u32).filter(|&i| existing.is_none_or(|p| !written(p, i))).collect()
}

/// An image as it is written: `rgba` (`size`) filtered down by `k` each axis where
/// supersampled (`--supersample`), and its size then; as it is where k is 1.
pub fn filtered_down(rgba: Vec<u8>, size: (u32, u32), k: u32) -> (Vec<u8>, (u32, u32)) {
    let image = if k == 1 { rgba } else { ml_cpu::supersample::downsample(&rgba, size, k) };
    (image, (size.0 / k, size.1 / k))
}

/// An image sequence's frames encoded and written on rayon's threads while the GPU renders the
/// next ones: the renderer hands a frame over and goes on, waiting only while `limit` frames
/// are already being written (their images' memory is bounded by it). Each file is replaced
/// only once complete (files::write_png); the first failure is returned by the next `write` or
/// by `finish`, and no frame is handed over after it.
pub struct FrameWriter {
    state: Arc<(Mutex<Writing>, Condvar)>,
    limit: usize,
    started: Instant,
    /// Time the renderer spent waiting for a free place.
    waited: Duration,
}

#[derive(Default)]
struct Writing {
    pending: usize,
    written: u32,
    /// Encoding (with the filtering down of a supersampled image) and writing, each summed
    /// over the threads.
    encoding: Duration,
    writing: Duration,
    failure: Option<String>,
}

/// What a sequence's writing took (`FrameWriter::finish`).
#[derive(Clone, Copy, Debug)]
pub struct WritingStats {
    pub frames: u32,
    pub threads: usize,
    /// Encoding a frame (PNG, and filtering down where supersampled) and writing it, means over
    /// the frames (on one thread).
    pub encode_ms_per_frame: f64,
    pub write_ms_per_frame: f64,
    /// From the first frame handed over to the last written.
    pub wall_ms: f64,
    /// What the renderer waited for a free place in all.
    pub waited_ms: f64,
}

impl FrameWriter {
    pub fn new() -> FrameWriter {
        let threads = rayon::current_num_threads();
        FrameWriter { state: Arc::default(), limit: 2 * threads, started: Instant::now(), waited: Duration::ZERO }
    }

    /// Encode and write `rgba` (`size`, filtered down by `supersample` each axis first) to
    /// `path` on another thread; waits while `limit` frames are being written. The first
    /// failure of an earlier frame, if any.
    pub fn write(&mut self, path: PathBuf, rgba: Vec<u8>, size: (u32, u32), supersample: u32) -> Result<()> {
        let (lock, freed) = &*self.state;
        let wait = Instant::now();
        let mut w = freed.wait_while(lock.lock().expect("a writer thread panicked"), |w| w.pending >= self.limit).expect("not poisoned");
        self.waited += wait.elapsed();
        if let Some(failure) = &w.failure {
            bail!("{failure}");
        }
        if w.written == 0 && w.pending == 0 {
            self.started = Instant::now();
        }
        w.pending += 1;
        drop(w);
        let state = Arc::clone(&self.state);
        rayon::spawn(move || {
            let begun = Instant::now();
            let (image, size) = filtered_down(rgba, size, supersample);
            let encoded = files::png_bytes(&path, &image, size);
            let written = Instant::now();
            let result = encoded.and_then(|png| files::write_bytes_replacing(&path, &png));
            let (lock, freed) = &*state;
            let mut w = lock.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            w.encoding += written - begun;
            w.writing += written.elapsed();
            w.pending -= 1;
            w.written += 1;
            if let Err(e) = result {
                w.failure.get_or_insert(e.to_string());
            }
            freed.notify_all();
        });
        Ok(())
    }

    /// Wait until every frame handed over is written; the first failure, else what it took.
    pub fn finish(&mut self) -> Result<WritingStats> {
        let (lock, freed) = &*self.state;
        let w = freed.wait_while(lock.lock().expect("a writer thread panicked"), |w| w.pending > 0).expect("not poisoned");
        if let Some(failure) = &w.failure {
            bail!("{failure}");
        }
        Ok(WritingStats {
            frames: w.written,
            threads: rayon::current_num_threads(),
            encode_ms_per_frame: w.encoding.as_secs_f64() * 1e3 / f64::from(w.written.max(1)),
            write_ms_per_frame: w.writing.as_secs_f64() * 1e3 / f64::from(w.written.max(1)),
            wall_ms: self.started.elapsed().as_secs_f64() * 1e3,
            waited_ms: self.waited.as_secs_f64() * 1e3,
        })
    }
}

impl Drop for FrameWriter {
    /// Frames still being written finish (a failed render returns after its last frame is on
    /// disk or refused, never while a thread writes).
    fn drop(&mut self) {
        let (lock, freed) = &*self.state;
        drop(freed.wait_while(lock.lock().unwrap_or_else(|p| p.into_inner()), |w| w.pending > 0));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequence_patterns_number_frames_in_their_run_of_hashes() {
        let p = sequence_pattern(Path::new("frames/####.png")).unwrap().unwrap();
        assert_eq!(sequence_path(&p, 7), PathBuf::from("frames/0007.png"));
        assert_eq!(sequence_path(&p, 12345), PathBuf::from("frames/12345.png"));
        let p = sequence_pattern(Path::new("turn-#.png")).unwrap().unwrap();
        assert_eq!(sequence_path(&p, 3), PathBuf::from("turn-3.png"));
        assert_eq!(sequence_pattern(Path::new("plain.png")).unwrap(), None);
        for bad in ["a#b#.png", "frames#/#.png", "##x##.png", "##.jpg", "out"] {
            assert!(sequence_pattern(Path::new(bad)).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_sequence_writer_writes_every_frame_and_stops_at_the_first_failure() {
        let folder = std::env::temp_dir().join(format!("manylights-writer-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        // Frame i: a 4x2 image (each 2x2 block one value) filtered down to 2x1 by 2x2 blocks.
        let frame = |i: u8| (0..8u32).flat_map(|p| [i, (p % 4 / 2) as u8 * 100, 0, 255]).collect::<Vec<u8>>();
        let mut writer = FrameWriter::new();
        for i in 0..20u8 {
            writer.write(folder.join(format!("{i:02}.png")), frame(i), (4, 2), 2).unwrap();
        }
        let stats = writer.finish().unwrap();
        assert_eq!(stats.frames, 20);
        for i in 0..20u8 {
            let image = image::open(folder.join(format!("{i:02}.png"))).unwrap().to_rgba8();
            assert_eq!((image.width(), image.height()), (2, 1), "frame {i}");
            assert_eq!(image.as_raw(), &[i, 0, 0, 255, i, 100, 0, 255], "frame {i}");
        }
        // A frame that cannot be written: its error comes back, from `finish` or the next frame
        // handed over, and nothing is handed over after it.
        let mut writer = FrameWriter::new();
        writer.write(folder.join("missing/00.png"), frame(0), (4, 2), 2).unwrap();
        let failure = writer.finish().unwrap_err().to_string();
        assert!(failure.contains("missing/00.png"), "{failure}");
        assert!(writer.write(folder.join("01.png"), frame(1), (4, 2), 2).is_err());
        std::fs::remove_dir_all(&folder).unwrap();
    }

    #[test]
    fn shards_split_a_sequence_into_blocks_that_cover_it_once() {
        for frames in 0..20u32 {
            for count in 1..8u32 {
                let all: Vec<u32> = (0..count).flat_map(|i| frames_to_write(frames, Some((i, count)), None)).collect();
                assert_eq!(all, (0..frames).collect::<Vec<_>>(), "{frames} frames in {count} shards");
            }
        }
        assert_eq!(frames_to_write(10, Some((1, 3)), None), vec![3, 4, 5]);
    }

    #[test]
    fn shards_are_given_as_index_and_count_or_by_slurm() {
        let none = |_: &str| None;
        assert_eq!(shard_choice(Some("1/4"), false, true, none).unwrap(), Some((1, 4)));
        assert_eq!(shard_choice(None, true, true, none).unwrap(), None);
        for bad in ["4/4", "0/0", "1", "a/b", "-1/4", "env"] {
            assert!(shard_choice(Some(bad), false, true, none).is_err(), "{bad}");
        }
        assert!(shard_choice(Some("0/2"), false, false, none).is_err(), "a single image");
        assert!(shard_choice(None, true, false, none).is_err(), "--resume of a single image");
        let slurm = |id: &'static str| {
            move |name: &str| match name {
                "SLURM_ARRAY_TASK_ID" => Some(id.to_owned()),
                "SLURM_ARRAY_TASK_MIN" => Some("4".to_owned()),
                "SLURM_ARRAY_TASK_COUNT" => Some("3".to_owned()),
                _ => None,
            }
        };
        assert_eq!(shard_choice(Some("env"), false, true, slurm("5")).unwrap(), Some((1, 3)));
        assert!(shard_choice(Some("env"), false, true, slurm("3")).is_err(), "below the array's first task");
        assert!(shard_choice(Some("env"), false, true, slurm("7")).is_err(), "past the array's last task");
    }
}
