//! Pipelines, pipeline layouts, descriptor set layouts and render passes, made once per
//! context and shared by everything that asks for the same one: a renderer made again with
//! settings seen before (the viewer switching back to a technique, a test drawing several
//! scenes the same way) takes the pipelines the first one made instead of compiling them again.
//! Making a pipeline is the slow part of making a renderer: on lavapipe the lighting shader's
//! front end alone (SPIR-V to NIR and its passes, which run before Mesa's disk cache is
//! consulted) takes 0.5–1.2 s, ten to fifty times the frame it renders.
//!
//! Layouts and render passes are small and few: the context keeps every distinct one until it
//! goes away, so a handle stands for its contents and a pipeline's key can name it. Pipelines
//! are counted: `release_pipeline` hands one back, and the context keeps up to
//! `IDLE_PIPELINES` nobody holds (the longest unused destroyed first). Keys hold every field
//! of the create info that the helpers in `shader` set, and the SPIR-V as a 128-bit hash.

use ash::vk;
use ash::vk::Handle;
use std::collections::hash_map::DefaultHasher;
use std::collections::HashMap;
use std::hash::{Hash, Hasher};

/// Pipelines kept while nobody holds them. A renderer holds 20–40; this keeps a few
/// configurations' worth for whoever switches back.
pub const IDLE_PIPELINES: usize = 256;

/// The fields of a create info as words: equal words, equal objects.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub(crate) struct Key(Vec<u64>);

impl Key {
    pub fn new(kind: u64) -> Key {
        Key(vec![kind])
    }

    /// Its first word: what kind of object it is the key of.
    pub fn kind(&self) -> u64 {
        self.0[0]
    }

    pub fn word(&mut self, w: impl Into<u64>) -> &mut Key {
        self.0.push(w.into());
        self
    }

    pub fn handle(&mut self, h: impl vk::Handle) -> &mut Key {
        self.word(h.as_raw())
    }

    /// A float by its bits (0.0 and -0.0 differ: as they would in a pipeline).
    pub fn float(&mut self, f: f32) -> &mut Key {
        self.word(f.to_bits())
    }

    /// Bytes as their length and a 128-bit hash (two SipHashes with distinct prefixes).
    pub fn bytes(&mut self, b: &[u8]) -> &mut Key {
        self.word(b.len() as u64);
        for salt in [0x6d6c_u64, 0x7370_u64] {
            let mut h = DefaultHasher::new();
            salt.hash(&mut h);
            b.hash(&mut h);
            self.word(h.finish());
        }
        self
    }

    /// Specialization constants (id, value).
    pub fn constants(&mut self, constants: &[(u32, u32)]) -> &mut Key {
        self.word(constants.len() as u64);
        for &(id, value) in constants {
            self.word(u64::from(id) << 32 | u64::from(value));
        }
        self
    }
}

struct CachedPipeline {
    pipeline: vk::Pipeline,
    /// Holders (`release_pipeline` not yet called for each time it was handed out).
    users: u32,
    /// When the last holder released it (a counter, not a clock).
    released: u64,
}

/// The kinds of object a key is the key of (its first word): pipelines, counted, and the
/// objects kept for the context's life.
pub(crate) const COMPUTE_PIPELINE: u64 = 1;
pub(crate) const GRAPHICS_PIPELINE: u64 = 2;
pub(crate) const SET_LAYOUT: u64 = 3;
pub(crate) const PIPELINE_LAYOUT: u64 = 4;
pub(crate) const RENDER_PASS: u64 = 5;

/// The context's shared objects (`Context::objects`).
#[derive(Default)]
pub(crate) struct ObjectCache {
    /// Set layouts, pipeline layouts and render passes (raw handles; the key's first word
    /// says which), kept until the context goes away.
    kept: HashMap<Key, u64>,
    pipelines: HashMap<Key, CachedPipeline>,
    keys: HashMap<vk::Pipeline, Key>,
    releases: u64,
}

impl ObjectCache {
    /// The kept object of `key` (a raw handle), if made.
    pub fn kept(&self, key: &Key) -> Option<u64> {
        self.kept.get(key).copied()
    }

    /// `raw`, just made for `key`, kept unless another thread kept one first: the one kept.
    pub fn keep(&mut self, key: Key, raw: u64) -> u64 {
        *self.kept.entry(key).or_insert(raw)
    }

    /// The pipeline of `key`, counted as held once more; None: not made yet.
    pub fn take_pipeline(&mut self, key: &Key) -> Option<vk::Pipeline> {
        let cached = self.pipelines.get_mut(key)?;
        cached.users += 1;
        Some(cached.pipeline)
    }

    /// A pipeline just made for `key`, held once: (the one to use, the one to destroy where
    /// another thread made the same meanwhile).
    pub fn add_pipeline(&mut self, key: Key, pipeline: vk::Pipeline) -> (vk::Pipeline, Option<vk::Pipeline>) {
        if let Some(first) = self.take_pipeline(&key) {
            return (first, Some(pipeline));
        }
        self.keys.insert(pipeline, key.clone());
        self.pipelines.insert(key, CachedPipeline { pipeline, users: 1, released: 0 });
        (pipeline, None)
    }

    /// One holder of `pipeline` lets go; returns the pipelines to destroy now: `pipeline`
    /// itself where the cache never knew it, else the longest-idle beyond `IDLE_PIPELINES`.
    pub fn release_pipeline(&mut self, pipeline: vk::Pipeline) -> Vec<vk::Pipeline> {
        let Some(key) = self.keys.get(&pipeline) else { return vec![pipeline] };
        let cached = self.pipelines.get_mut(key).expect("every key has its pipeline");
        assert!(cached.users > 0, "a pipeline released more often than it was handed out");
        cached.users -= 1;
        if cached.users > 0 {
            return Vec::new();
        }
        self.releases += 1;
        cached.released = self.releases;
        let mut idle: Vec<(u64, vk::Pipeline)> =
            self.pipelines.values().filter(|c| c.users == 0).map(|c| (c.released, c.pipeline)).collect();
        if idle.len() <= IDLE_PIPELINES {
            return Vec::new();
        }
        idle.sort_unstable_by_key(|&(released, _)| released);
        let evicted: Vec<vk::Pipeline> = idle[..idle.len() - IDLE_PIPELINES].iter().map(|&(_, p)| p).collect();
        for p in &evicted {
            let key = self.keys.remove(p).expect("an idle pipeline has its key");
            self.pipelines.remove(&key);
        }
        evicted
    }

    /// Pipelines kept (held or idle), and those held now.
    pub fn pipeline_counts(&self) -> (usize, usize) {
        (self.pipelines.len(), self.pipelines.values().filter(|c| c.users > 0).count())
    }

    /// Destroy everything; the device must be idle.
    pub fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: the device is idle (the context waits before it calls here); pipelines go
        // before the layouts and render passes they were made with.
        unsafe {
            for (_, c) in self.pipelines.drain() {
                device.destroy_pipeline(c.pipeline, None);
            }
            // Pipeline layouts before the set layouts they were made of.
            for kind in [PIPELINE_LAYOUT, SET_LAYOUT, RENDER_PASS] {
                for (key, raw) in self.kept.iter().filter(|(key, _)| key.kind() == kind) {
                    match key.kind() {
                        PIPELINE_LAYOUT => device.destroy_pipeline_layout(vk::PipelineLayout::from_raw(*raw), None),
                        SET_LAYOUT => device.destroy_descriptor_set_layout(vk::DescriptorSetLayout::from_raw(*raw), None),
                        _ => device.destroy_render_pass(vk::RenderPass::from_raw(*raw), None),
                    }
                }
            }
            self.kept.clear();
        }
        self.keys.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ash::vk::Handle;

    fn key(n: u64) -> Key {
        let mut k = Key::new(9);
        k.word(n);
        k
    }

    #[test]
    fn equal_fields_make_equal_keys_and_any_field_tells_them_apart() {
        let a = || {
            let mut k = Key::new(1);
            k.bytes(b"spirv words").constants(&[(10, 1), (11, 0)]).float(1.0);
            k
        };
        assert_eq!(a(), a());
        let mut b = Key::new(1);
        b.bytes(b"spirv word!").constants(&[(10, 1), (11, 0)]).float(1.0);
        assert_ne!(a(), b);
        let mut c = Key::new(1);
        c.bytes(b"spirv words").constants(&[(10, 1), (11, 1)]).float(1.0);
        assert_ne!(a(), c);
    }

    #[test]
    fn a_pipeline_is_shared_while_held_and_kept_idle_up_to_the_bound() {
        let mut cache = ObjectCache::default();
        let p = |n: u64| vk::Pipeline::from_raw(n + 1);
        assert_eq!(cache.add_pipeline(key(0), p(0)), (p(0), None));
        assert_eq!(cache.add_pipeline(key(0), p(7000)), (p(0), Some(p(7000))), "made twice at once: the first kept");
        assert!(cache.release_pipeline(p(0)).is_empty());
        assert_eq!(cache.take_pipeline(&key(0)), Some(p(0)));
        assert!(cache.release_pipeline(p(0)).is_empty(), "still held once");
        assert!(cache.release_pipeline(p(0)).is_empty(), "idle, kept");
        assert_eq!(cache.pipeline_counts(), (1, 0));
        assert_eq!(cache.take_pipeline(&key(0)), Some(p(0)), "an idle pipeline is handed out again");
        for n in 1..=IDLE_PIPELINES as u64 {
            cache.add_pipeline(key(n), p(n));
            assert!(cache.release_pipeline(p(n)).is_empty());
        }
        // p(0) is held: the bound counts idle pipelines only. One more idle one evicts the
        // longest idle (p(1)), then p(0) released goes to the back of the line.
        cache.add_pipeline(key(1000), p(1000));
        assert_eq!(cache.release_pipeline(p(1000)), vec![p(1)]);
        assert_eq!(cache.release_pipeline(p(0)), vec![p(2)]);
        assert_eq!(cache.take_pipeline(&key(1)), None, "evicted");
        assert_eq!(cache.take_pipeline(&key(0)), Some(p(0)));
        // A pipeline the cache never made is the caller's to destroy.
        assert_eq!(cache.release_pipeline(p(5000)), vec![p(5000)]);
    }
}
