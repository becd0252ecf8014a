//! The tables `render` and `info` print: a finished render's settings and measurements
//! (`render_rows`), a device's facts (`device_rows`), as rows of a two-column table.

use ml_render::report::FrameStats;
use ml_render::settings::{Geometry, LargeTriangles, Raster, RenderSettings};
use ml_render::{gbuffer_bytes_per_pixel, gbuffer_images, GBufferKind};
use ml_vk::DeviceInfo;
use std::path::Path;

/// Rows as a table: keys in a column as wide as the widest, then the values.
pub fn table(rows: &[(&str, String)]) -> String {
    let width = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    rows.iter().map(|(k, v)| format!("{k:<width$}  {v}\n")).collect()
}

/// A device and its driver in one line.
pub fn device_line(info: &DeviceInfo) -> String {
    format!("{} ({}, {} {})", info.name, info.type_name(), info.driver_name, info.driver_info)
}

/// What a finished render is reported with besides its frame measurements.
#[derive(Clone, Copy, Debug)]
pub struct RenderFacts<'a> {
    /// `device_line` of the device it ran on.
    pub device: &'a str,
    /// The settings it ran with (the technique `auto` picked, where it picked).
    pub settings: &'a RenderSettings,
    /// Point lights of the scene.
    pub lights: usize,
    /// Directional lights of the scene.
    pub directional: usize,
    /// Which images the scene's G-buffer has (textures of objects' own and PBR extensions
    /// varying per point widen it).
    pub gbuffer: GBufferKind,
    /// Why `auto` picked the technique; None where it was asked for by name.
    pub auto: Option<&'a str>,
    /// Why `--raster auto` picked the rasteriser; None where it was asked for by name.
    pub raster_auto: Option<&'a str>,
    /// Why `--aa auto` took its samples (None: given).
    pub aa_auto: Option<&'a str>,
    /// Where the image was written.
    pub output: &'a Path,
    /// `--supersample`: the image rendered this many times wider and taller, filtered down.
    pub supersample: u32,
    /// The camera it was seen from, as `--camera` reads it.
    pub camera: &'a str,
    /// An image sequence's writing (None: one image).
    pub sequence: Option<&'a crate::output::WritingStats>,
}

/// Who drew the visibility buffer, in words.
pub fn raster_line(raster: Raster) -> String {
    match raster {
        Raster::Hardware => "hardware (indexed draw per culling phase)".to_owned(),
        Raster::Compute { split, large: LargeTriangles::Hardware } => format!(
            "hybrid (triangles up to {split} px a side in compute; larger ones and those crossing the near plane by the hardware; 64-bit atomic min)"
        ),
        Raster::Compute { split, large: LargeTriangles::Bins { bin_list, .. } } => format!(
            "compute (triangles up to {split} px a side a thread each; larger ones and those crossing the near plane clipped, a work group per 64x64 bin, lists of {bin_list} to start, grown when a frame overflows them; 64-bit atomic min)"
        ),
    }
}

/// The rows of the table `render` prints (`table`).
pub fn render_rows(facts: &RenderFacts, stats: &FrameStats) -> Vec<(&'static str, String)> {
    let settings = facts.settings;
    let technique = settings.technique;
    let mut rows = vec![
        ("device", facts.device.to_owned()),
        ("resolution", format!("{}x{}", settings.width / facts.supersample, settings.height / facts.supersample)),
        ("technique", technique.name().to_owned() + if facts.auto.is_some() { " (auto)" } else { "" }),
        ("shading", settings.shading.name().to_owned()),
        ("lights", facts.lights.to_string()),
        ("frames", stats.frames.to_string()),
        ("camera", format!("--camera {}", facts.camera)),
    ];
    if let Some(why) = facts.auto {
        rows.push(("auto", why.to_owned()));
    }
    if facts.supersample > 1 {
        let k = facts.supersample;
        rows.push((
            "supersample",
            format!(
                "{k}x{k}: rendered at {}x{}, each {k}x{k} block filtered to a pixel in linear light (times are the large image's)",
                settings.width, settings.height
            ),
        ));
    }
    match stats.gpu_ms() {
        Some(passes) => rows.extend(passes.into_iter().map(|(name, ms)| ("gpu ms", format!("{ms:.3}  ({name} pass, mean)")))),
        None => rows.push(("gpu ms", "n/a (device has no timestamp queries)".into())),
    }
    if technique.geometry() == Geometry::Meshlets {
        rows.push(("visibility", "4 bytes/pixel + depth (meshlet instance << 7 | triangle, u32)".to_owned()));
        rows.push(("raster", raster_line(settings.raster) + if facts.raster_auto.is_some() { " (auto)" } else { "" }));
        if let Some(why) = facts.raster_auto {
            rows.push(("auto raster", why.to_owned()));
        }
        if settings.antialiasing == ml_render::Antialiasing::Off {
            rows.push(("anti-aliasing", "off (one sample a pixel, at its centre)".to_owned()));
        }
    } else if technique.lights_in_subpass() || technique.lights_in_compute() {
        rows.push(("g-buffer", gbuffer_line(facts.gbuffer, stats.gbuffer_lazily_allocated)));
    }
    // What the features' passes counted (the culling, the shadow raster, the atlas).
    rows.extend(stats.feature_rows());
    if let Some(why) = facts.aa_auto {
        rows.push(("auto aa", format!("{}: {why}", settings.antialiasing.name())));
    }
    if let Some(ms) = stats.assign_ms() {
        rows.push(("cpu assign ms", format!("{ms:.3}  (light assignment, mean)")));
    }
    if let Some(c) = stats.clusters {
        let d = settings.clusters;
        rows.push(("clusters", format!("{}x{}x{} = {}", d.x, d.y, d.z, d.count())));
        rows.push(("lights/cluster", format!("mean {:.2}, max {}", c.mean_lights, c.max_lights)));
        rows.push(("index list", format!("{} entries ({} buffer growths)", c.index_len, stats.index_growths)));
    }
    if let Some(legend) = settings.debug_view.legend(stats) {
        rows.push(("heat legend", legend));
    }
    if let Some(o) = settings.omni {
        let which = if o.all { "every light reaching the view" } else { "the strongest" };
        match o.atlas() {
            Some(a) => rows.push((
                "omni shadows",
                format!(
                    "atlas: {} light(s) ({which}), faces sized by the screen{}, budget {} MiB, cache {}",
                    o.lights,
                    a.fixed_size.map_or(String::new(), |s| format!(" (fixed: {s}²)")),
                    a.budget_mib,
                    if a.cache { "on" } else { "off" }
                ),
            )),
            None if o.rays() => {
                let which = if o.all { format!("every point light: {}", facts.lights) } else { format!("the strongest {}", o.lights) };
                let suns = if facts.directional > 0 { format!(" and {} directional", facts.directional) } else { String::new() };
                rows.push(("omni shadows", format!("rays: {which}{suns}, a shadow ray per point and light that reaches it")));
            }
            None => rows.push((
                "omni shadows",
                format!("{}: {} light(s) ({which}), cubes of 6×{}² (distance / radius, D32)", o.mode.name(), o.lights, o.size),
            )),
        }
    }
    if settings.shading == ml_render::ShadingModel::BlinnPhong && settings.sun_shadow != ml_render::SunShadowMode::Rays {
        let (by, size) = (settings.sun_shadow.name(), ml_render::SHADOW_MAP_SIZE);
        rows.push(("sun shadow", format!("the sun's {size}² shadow map by {by}, drawn in the first frame (its pass's time above)")));
    }
    if let Some(ev) = stats.exposure_ev {
        let repeats = stats.exposure_repeats;
        rows.push((
            "exposure",
            format!("auto: {ev:+.2} EV (metered on the GPU; the last frame rendered {repeats} more time(s) to settle)"),
        ));
    }
    if stats.redraws > 0 {
        rows.push((
            "redrawn",
            format!("{} time(s): a frame overflowed lists that have grown since, drawn again (a sequence: from it on)", stats.redraws),
        ));
    }
    if let Some(m) = stats.memory {
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        rows.push((
            "memory",
            format!(
                "{:.1} MiB in {} buffers and images ({:.1} MiB of blocks reserved from Vulkan; device-local and host-visible)",
                mib(m.allocated),
                m.allocations,
                mib(m.reserved)
            ),
        ));
    }
    if let Some(kib) = peak_resident_kib() {
        rows.push(("host memory", format!("{} MiB at the peak (resident; the scene, its decoded textures, the driver)", kib >> 10)));
    }
    rows.push(("cpu ms/frame", format!("{:.3}  (assign + upload + record + submit)", stats.cpu_ms())));
    rows.push(("wall ms/frame", format!("{:.3}", stats.wall_ms_per_frame())));
    if let Some(w) = facts.sequence {
        let per_second = f64::from(w.frames) / (w.wall_ms / 1e3).max(1e-9);
        let (taken, taken_ms) = stats.read_back;
        rows.push((
            "sequence",
            format!(
                "{} frames written, {per_second:.1} a second; a frame: read back {:.2} ms (render thread), encoded {:.1} ms and written {:.1} ms on {} threads; the renderer waited {:.0} ms for the writers in all",
                w.frames,
                taken_ms / f64::from(taken.max(1)),
                w.encode_ms_per_frame,
                w.write_ms_per_frame,
                w.threads,
                w.waited_ms
            ),
        ));
    }
    rows.push(("output", facts.output.display().to_string()));
    rows
}

/// This process's peak resident memory in KiB (Linux: VmHWM in /proc/self/status; None
/// elsewhere).
fn peak_resident_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The G-buffer of a scene (with object textures or not): its size, its images, and whether
/// it got lazily allocated memory (None: it lives outside a render pass).
fn gbuffer_line(kind: GBufferKind, lazily_allocated: Option<bool>) -> String {
    let memory = match lazily_allocated {
        Some(true) => "; transient, lazily allocated",
        Some(false) => "; transient (this device has no lazily allocated memory)",
        None => "",
    };
    let layout: Vec<&str> = gbuffer_images(kind).iter().map(|g| g.layout).collect();
    format!("{} bytes/pixel + depth ({}){memory}", gbuffer_bytes_per_pixel(kind), layout.join(", "))
}

/// The rows `info` prints for a device: what it is and the limits manylights depends on.
pub fn device_rows(d: &DeviceInfo) -> Vec<(&'static str, String)> {
    let l = &d.limits;
    vec![
        ("device", format!("{}: {} ({})", d.index, d.name, d.type_name())),
        ("vulkan", d.api_version_string()),
        ("driver", format!("{} {}", d.driver_name, d.driver_info)),
        ("usable", if d.suitable { "yes".into() } else { "no (needs Vulkan 1.2 and a graphics queue)".to_string() }),
        ("maxImageDimension2D", l.max_image_dimension2_d.to_string()),
        ("maxStorageBufferRange", l.max_storage_buffer_range.to_string()),
        ("maxUniformBufferRange", l.max_uniform_buffer_range.to_string()),
        ("maxPushConstantsSize", l.max_push_constants_size.to_string()),
        ("maxComputeWorkGroupInvocations", l.max_compute_work_group_invocations.to_string()),
        ("maxComputeSharedMemorySize", l.max_compute_shared_memory_size.to_string()),
        ("timestampPeriod (ns)", l.timestamp_period.to_string()),
        ("timestampComputeAndGraphics", (l.timestamp_compute_and_graphics != 0).to_string()),
        ("maxImageArrayLayers", l.max_image_array_layers.to_string()),
        ("imageCubeArray", d.features.image_cube_array.to_string()),
        ("multiview", d.features.multiview.to_string()),
        ("shaderOutputLayer", d.features.shader_output_layer.to_string()),
        ("fullDrawIndexUint32", d.features.full_draw_index_uint32.to_string()),
        ("sampledImageArrayDynamicIndexing", d.features.sampled_image_array_indexing.to_string()),
        ("shaderBufferInt64Atomics", d.features.buffer_int64_atomics.to_string()),
        ("geometryShader", d.features.geometry_shader.to_string()),
        ("fragmentStoresAndAtomics", d.features.fragment_stores_and_atomics.to_string()),
        ("subgroup ballot in compute", d.features.compute_subgroup_ballot.to_string()),
        ("subPixelPrecisionBits", l.sub_pixel_precision_bits.to_string()),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn render_rows_follow_the_technique_and_describe_the_gbuffer_from_its_images() {
        use ml_render::settings::{RenderSettings, Technique};
        let settings = RenderSettings::new(Technique::DeferredClustered, 64, 36);
        let mut facts = RenderFacts {
            device: "gpu",
            settings: &settings,
            lights: 5,
            directional: 0,
            gbuffer: GBufferKind::Base,
            auto: None,
            raster_auto: None,
            aa_auto: None,
            output: Path::new("a.png"),
            supersample: 1,
            camera: "0,1,2:0,0,0:60",
            sequence: None,
        };
        let mut stats = FrameStats::new(&["g-buffer + lighting"]);
        stats.frames = 1;
        stats.gbuffer_lazily_allocated = Some(true);
        let rows = render_rows(&facts, &stats);
        let keys: Vec<&str> = rows.iter().map(|(k, _)| *k).collect();
        assert_eq!(
            keys,
            [
                "device",
                "resolution",
                "technique",
                "shading",
                "lights",
                "frames",
                "camera",
                "gpu ms",
                "g-buffer",
                "host memory",
                "cpu ms/frame",
                "wall ms/frame",
                "output"
            ]
        );
        let value = |rows: &[(&str, String)], key: &str| rows.iter().find(|(k, _)| *k == key).map(|(_, v)| v.clone()).unwrap();
        assert_eq!(value(&rows, "resolution"), "64x36");
        assert_eq!(value(&rows, "gpu ms"), "n/a (device has no timestamp queries)");
        assert_eq!(
            value(&rows, "g-buffer"),
            "16 bytes/pixel + depth (octahedral normal 2×f32, object index u32, albedo (sRGB)-occlusion RGBA8); transient, lazily allocated"
        );
        facts.gbuffer = GBufferKind::Material;
        facts.auto = Some("it was faster");
        let rows = render_rows(&facts, &stats);
        assert!(value(&rows, "g-buffer").starts_with("22 bytes/pixel + depth (octahedral normal 2×f32, object index u32, albedo (sRGB)-occlusion RGBA8, roughness-metallic RG8, emissive RGBA8)"));
        assert_eq!((value(&rows, "technique").as_str(), value(&rows, "auto").as_str()), ("deferred-clustered (auto)", "it was faster"));
        let forward = RenderSettings::new(Technique::Forward, 64, 36);
        let rows = render_rows(&RenderFacts { settings: &forward, ..facts }, &stats);
        assert!(rows.iter().all(|(k, _)| *k != "g-buffer"));
    }
}
