//! Frame measurements: per-pass GPU times, CPU phases, light lists, exposure, device memory,
//! and what each feature's passes count (`FeatureStats`, defined by the feature). The binary
//! prints them.

use std::any::Any;
use std::sync::Arc;

/// What a feature's passes counted in a frame, defined by the feature (the culling's, the
/// shadow raster's, the atlas's): kept in `FrameStats` without the report knowing the type,
/// read back typed (`FrameStats::feature`) or as the rows a table shows.
pub trait FeatureStats: Any + std::fmt::Debug + Send + Sync {
    /// Its rows: a label and its text each.
    fn rows(&self) -> Vec<(&'static str, String)>;
}

/// Per-pass GPU times (timestamp queries) and CPU times of every frame.
#[derive(Clone, Debug)]
pub struct FrameStats {
    pub pass_names: Vec<&'static str>,
    /// Every frame's GPU ms per pass and CPU ms per phase, in the order the frames finished.
    gpu_samples: Vec<Vec<f64>>,
    cpu_samples: Vec<CpuPhases>,
    pub frames: u32,
    pub wall_ms: f64,
    /// Cluster statistics of the last frame (clustered techniques).
    pub clusters: Option<ml_cpu::cluster::ClusterStats>,
    /// How often a frame's light-index buffer had to grow.
    pub index_growths: u32,
    /// deferred, deferred-clustered: whether the transient G-buffer got lazily allocated
    /// memory (only devices that have such memory, i.e. tilers, give it).
    pub gbuffer_lazily_allocated: Option<bool>,
    /// What the features' passes counted in the last frame (the culling, the shadow
    /// raster, the atlas's plan), each as its feature defines it: `feature` reads one back,
    /// `feature_rows` gives them all as rows of a table. One of each type.
    features: Vec<Arc<dyn FeatureStats>>,
    /// Auto exposure: the EV the returned image was exposed with, and how often its frame was
    /// rendered again for the exposure to settle.
    pub exposure_ev: Option<f32>,
    pub exposure_repeats: u32,
    /// How often frames were drawn again because one overflowed a list that grew since
    /// (`FrameWork::redraws`): the last frame, or an image sequence's from the first such.
    pub redraws: u32,
    /// What the renderer had allocated when the last frame finished.
    pub memory: Option<ml_vk::context::MemoryUse>,
    /// An image sequence's frames taken out of host-visible memory for the sink: their count
    /// and the render thread's milliseconds for it in all.
    pub read_back: (u32, f64),
}

/// Mean GPU milliseconds per pass (None when the device has no timestamps).
pub type PassTimes = Option<Vec<(&'static str, f64)>>;

impl FrameStats {
    pub fn new(pass_names: &[&'static str]) -> FrameStats {
        FrameStats {
            pass_names: pass_names.to_vec(),
            gpu_samples: Vec::new(),
            cpu_samples: Vec::new(),
            frames: 0,
            wall_ms: 0.0,
            clusters: None,
            index_growths: 0,
            gbuffer_lazily_allocated: None,
            features: Vec::new(),
            exposure_ev: None,
            exposure_repeats: 0,
            redraws: 0,
            memory: None,
            read_back: (0, 0.0),
        }
    }

    /// A feature's figures of the last frame, in place of its earlier ones.
    pub fn set_feature<T: FeatureStats>(&mut self, stats: T) {
        let stats: Arc<dyn FeatureStats> = Arc::new(stats);
        match self.features.iter_mut().find(|f| (&***f as &dyn Any).is::<T>()) {
            Some(f) => *f = stats,
            None => self.features.push(stats),
        }
    }

    /// The last frame's figures of the feature whose stats type is `T` (None: it did not
    /// run or report).
    pub fn feature<T: FeatureStats>(&self) -> Option<&T> {
        self.features.iter().find_map(|f| (&**f as &dyn Any).downcast_ref::<T>())
    }

    /// Every feature's rows (label, text), in the order the features first reported.
    pub fn feature_rows(&self) -> Vec<(&'static str, String)> {
        self.features.iter().flat_map(|f| f.rows()).collect()
    }

    pub fn add_gpu(&mut self, ms: &[f64]) {
        self.gpu_samples.push(ms.to_vec());
    }

    /// Mean CPU light-assignment time over the frames that assigned (the CPU-built techniques).
    pub fn assign_ms(&self) -> Option<f64> {
        let assigned: Vec<f64> = self.cpu_samples.iter().filter_map(|p| p.assign).collect();
        (!assigned.is_empty()).then(|| assigned.iter().sum::<f64>() / assigned.len() as f64)
    }

    pub fn add_cpu(&mut self, phases: CpuPhases) {
        self.cpu_samples.push(phases);
    }

    /// Median, 95th percentile and mean GPU ms of each pass over the frames after the first
    /// `skip` (warm-up); None without timestamps or frames.
    pub fn gpu_spread(&self, skip: usize) -> Option<Vec<(&'static str, Spread)>> {
        let frames = self.gpu_samples.get(skip..).filter(|f| !f.is_empty())?;
        Some(self.pass_names.iter().enumerate().map(|(i, n)| (*n, Spread::of(frames.iter().map(|f| f[i]).collect()))).collect())
    }

    /// The same for the CPU time per frame (assign, upload, record, submit), and for each
    /// phase of it.
    pub fn cpu_spread(&self, skip: usize) -> Option<(Spread, [(&'static str, Spread); 4])> {
        let frames = self.cpu_samples.get(skip..).filter(|s| !s.is_empty())?;
        let phase = |i: usize| Spread::of(frames.iter().map(|p| p.as_array()[i]).collect());
        Some((Spread::of(frames.iter().map(CpuPhases::total).collect()), std::array::from_fn(|i| (CpuPhases::NAMES[i], phase(i)))))
    }

    pub fn gpu_ms(&self) -> PassTimes {
        let frames = &self.gpu_samples;
        (!frames.is_empty()).then(|| {
            let mean = |i: usize| frames.iter().map(|f| f[i]).sum::<f64>() / frames.len() as f64;
            self.pass_names.iter().enumerate().map(|(i, n)| (*n, mean(i))).collect()
        })
    }

    /// CPU time to assign, upload, record and submit one frame.
    pub fn cpu_ms(&self) -> f64 {
        self.cpu_samples.iter().map(CpuPhases::total).sum::<f64>() / self.frames.max(1) as f64
    }

    /// Wall-clock time per frame over the whole run (includes waiting for the GPU).
    pub fn wall_ms_per_frame(&self) -> f64 {
        self.wall_ms / self.frames.max(1) as f64
    }
}

/// One frame's CPU milliseconds by phase.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CpuPhases {
    /// Light assignment (clustered-cpu, deferred-clustered; None elsewhere).
    pub assign: Option<f64>,
    /// Writing the frame's buffers: animated lights, cluster lists, uniforms.
    pub upload: f64,
    /// Recording the command buffer.
    pub record: f64,
    /// vkQueueSubmit.
    pub submit: f64,
}

impl CpuPhases {
    pub const NAMES: [&'static str; 4] = ["assign", "upload", "record", "submit"];

    /// The phases in NAMES order, a technique that does not assign counting 0 for it.
    pub fn as_array(&self) -> [f64; 4] {
        [self.assign.unwrap_or(0.0), self.upload, self.record, self.submit]
    }

    pub fn total(&self) -> f64 {
        self.as_array().iter().sum()
    }
}

/// Median, 95th percentile (nearest rank) and mean of some samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spread {
    pub median: f64,
    pub p95: f64,
    pub mean: f64,
}

impl Spread {
    /// Of a non-empty list.
    pub fn of(mut samples: Vec<f64>) -> Spread {
        samples.sort_by(f64::total_cmp);
        let rank = |q: f64| samples[((q * samples.len() as f64).ceil() as usize).clamp(1, samples.len()) - 1];
        Spread { median: rank(0.5), p95: rank(0.95), mean: samples.iter().sum::<f64>() / samples.len() as f64 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, PartialEq)]
    struct Counted(u32);

    impl FeatureStats for Counted {
        fn rows(&self) -> Vec<(&'static str, String)> {
            vec![("counted", self.0.to_string())]
        }
    }

    #[derive(Debug)]
    struct Other;

    impl FeatureStats for Other {
        fn rows(&self) -> Vec<(&'static str, String)> {
            vec![("other", "a".into()), ("other", "b".into())]
        }
    }

    #[test]
    fn a_feature_s_figures_replace_its_last_ones_and_keep_their_place() {
        let mut stats = FrameStats::new(&[]);
        assert_eq!(stats.feature::<Counted>(), None);
        stats.set_feature(Counted(1));
        stats.set_feature(Other);
        stats.set_feature(Counted(2));
        assert_eq!(stats.feature::<Counted>(), Some(&Counted(2)));
        let rows: Vec<String> = stats.feature_rows().into_iter().map(|(l, t)| format!("{l} {t}")).collect();
        assert_eq!(rows, ["counted 2", "other a", "other b"]);
    }

    #[test]
    fn spreads_take_nearest_ranks_and_skip_the_warm_up() {
        let s = Spread::of((1..=20).rev().map(f64::from).collect());
        assert_eq!((s.median, s.p95, s.mean), (10.0, 19.0, 10.5));
        let mut stats = FrameStats::new(&["a", "b"]);
        for i in 0..5 {
            stats.add_gpu(&[100.0 * f64::from(i == 0), f64::from(i)]);
            let i = f64::from(i);
            stats.add_cpu(CpuPhases { assign: Some(i), upload: 2.0 * i, record: 0.5, submit: 0.25 });
        }
        let gpu = stats.gpu_spread(1).unwrap();
        assert_eq!(gpu[0], ("a", Spread { median: 0.0, p95: 0.0, mean: 0.0 }));
        assert_eq!(gpu[1].1.median, 2.0);
        let (total, phases) = stats.cpu_spread(1).unwrap();
        assert_eq!((total.p95, total.median), (12.75, 6.75));
        assert_eq!(phases.map(|(n, s)| (n, s.median)), [("assign", 2.0), ("upload", 4.0), ("record", 0.5), ("submit", 0.25)]);
        assert!(stats.gpu_spread(5).is_none());
    }
}
