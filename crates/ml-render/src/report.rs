//! Frame measurements and the table `render` prints.

/// Per-pass GPU times (timestamp queries) and CPU times, summed over frames.
#[derive(Clone, Debug)]
pub struct FrameStats {
    pub pass_names: Vec<&'static str>,
    gpu_sum_ms: Vec<f64>,
    gpu_frames: u32,
    cpu_sum_ms: f64,
    assign_sum_ms: f64,
    assign_frames: u32,
    pub frames: u32,
    pub wall_ms: f64,
    /// Cluster statistics of the last frame (clustered techniques).
    pub clusters: Option<ml_cpu::cluster::ClusterStats>,
    /// How often a frame's light-index buffer had to grow.
    pub index_growths: u32,
    /// clustered-gpu: frames whose light lists overflowed (reported, never shown as final).
    pub overflowed_frames: u32,
    /// clustered-gpu: extra frames rendered because the last one overflowed.
    pub rerendered_frames: u32,
    /// deferred, deferred-clustered: whether the transient G-buffer got lazily allocated
    /// memory (only devices that have such memory, i.e. tilers, give it).
    pub gbuffer_lazily_allocated: Option<bool>,
}

/// Mean GPU milliseconds per pass (None when the device has no timestamps).
pub type PassTimes = Option<Vec<(&'static str, f64)>>;

impl FrameStats {
    pub fn new(pass_names: &[&'static str]) -> FrameStats {
        FrameStats {
            pass_names: pass_names.to_vec(),
            gpu_sum_ms: vec![0.0; pass_names.len()],
            gpu_frames: 0,
            cpu_sum_ms: 0.0,
            assign_sum_ms: 0.0,
            assign_frames: 0,
            frames: 0,
            wall_ms: 0.0,
            clusters: None,
            index_growths: 0,
            overflowed_frames: 0,
            rerendered_frames: 0,
            gbuffer_lazily_allocated: None,
        }
    }

    pub fn add_gpu(&mut self, ms: &[f64]) {
        for (sum, v) in self.gpu_sum_ms.iter_mut().zip(ms) {
            *sum += v;
        }
        self.gpu_frames += 1;
    }

    pub fn add_assign_ms(&mut self, ms: f64) {
        self.assign_sum_ms += ms;
        self.assign_frames += 1;
    }

    /// Mean CPU light-assignment time (clustered-cpu).
    pub fn assign_ms(&self) -> Option<f64> {
        (self.assign_frames > 0).then(|| self.assign_sum_ms / self.assign_frames as f64)
    }

    pub fn add_cpu_ms(&mut self, ms: f64) {
        self.cpu_sum_ms += ms;
    }

    pub fn gpu_ms(&self) -> PassTimes {
        (self.gpu_frames > 0).then(|| self.pass_names.iter().zip(&self.gpu_sum_ms).map(|(n, s)| (*n, s / self.gpu_frames as f64)).collect())
    }

    /// CPU time to update, record and submit one frame.
    pub fn cpu_ms(&self) -> f64 {
        self.cpu_sum_ms / self.frames.max(1) as f64
    }

    /// Wall-clock time per frame over the whole run (includes waiting for the GPU).
    pub fn wall_ms_per_frame(&self) -> f64 {
        self.wall_ms / self.frames.max(1) as f64
    }
}

/// The table `manylights render` prints.
pub fn table(rows: &[(&str, String)]) -> String {
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    rows.iter().map(|(k, v)| format!("{k:<width$}  {v}\n")).collect()
}
