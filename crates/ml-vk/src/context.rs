//! Instance (with optional validation + synchronization validation and a debug messenger
//! that counts messages), physical-device choice, logical device, one graphics queue, and
//! the memory allocator; for the viewer, a window's surface (the queue can present to it and
//! the device has VK_KHR_swapchain).

use crate::error::{Result, VkError, VkResultExt};
use crate::object_cache::ObjectCache;
use ash::{ext::debug_utils, vk};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use std::ffi::{c_void, CStr};
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
/// The lowest Vulkan version we run on: any Vulkan 1.2+ device (docs/DESIGN.md#headless-first).
pub const MIN_API: u32 = vk::API_VERSION_1_2;

#[derive(Clone, Debug, Default)]
pub struct ContextDesc {
    /// Enable the Khronos validation layer with synchronization validation.
    pub validation: bool,
    /// Pick this device (index in `manylights info`) instead of the best one.
    pub device_index: Option<usize>,
    /// Present to this window: make its surface, and a device that can present to it.
    pub window: Option<WindowHandles>,
}

/// A window's raw handles (winit's, through raw-window-handle).
#[derive(Clone, Copy, Debug)]
pub struct WindowHandles {
    pub display: raw_window_handle::RawDisplayHandle,
    pub window: raw_window_handle::RawWindowHandle,
}

/// A window's Vulkan surface.
pub struct Surface {
    pub loader: ash::khr::surface::Instance,
    pub raw: vk::SurfaceKHR,
}

/// What `info` prints about a device and what the renderer checks against.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    pub api_version: u32,
    pub driver_name: String,
    pub driver_info: String,
    pub limits: vk::PhysicalDeviceLimits,
    /// Optional features the device has (and the context enables).
    pub features: OptionalFeatures,
    /// Whether it has a graphics queue and Vulkan ≥ 1.2.
    pub suitable: bool,
}

/// Features beyond Vulkan 1.2's required ones that some path uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OptionalFeatures {
    /// Cube-map arrays (several shadowed point lights).
    pub image_cube_array: bool,
    /// VK_KHR_multiview, core in 1.1 (one pass renders all six faces of a shadow cube).
    pub multiview: bool,
    /// shaderOutputLayer (Vulkan 1.2): a vertex shader picks the layer it draws into.
    pub shader_output_layer: bool,
    /// fullDrawIndexUint32 (core 1.0): index values up to 2^32 − 1, as the visibility raster's
    /// compacted indices (a draw slot and a meshlet vertex) use them.
    pub full_draw_index_uint32: bool,
    /// shaderSampledImageArrayDynamicIndexing (core 1.0): a texture array indexed by a value
    /// the same for the whole subgroup, the way the visibility pass reads objects' textures.
    pub sampled_image_array_indexing: bool,
    /// shaderInt64 with shaderBufferInt64Atomics (Vulkan 1.2): 64-bit atomics on buffers.
    pub buffer_int64_atomics: bool,
    /// geometryShader (core 1.0): besides geometry shaders, gl_PrimitiveID in fragment
    /// shaders (the visibility buffer's triangle index).
    pub geometry_shader: bool,
    /// fragmentStoresAndAtomics (core 1.0): fragment shaders write storage buffers (the
    /// compute rasteriser's large triangles, drawn by the hardware into its 64-bit buffer).
    pub fragment_stores_and_atomics: bool,
    /// Subgroup ballots in compute shaders (Vulkan 1.1 subgroup properties): the masked compute
    /// raster gathers the covered pixels of a subgroup before testing their alpha.
    pub compute_subgroup_ballot: bool,
}

impl DeviceInfo {
    pub fn api_version_string(&self) -> String {
        let v = self.api_version;
        format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
    }

    pub fn type_name(&self) -> &'static str {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
            vk::PhysicalDeviceType::CPU => "CPU",
            _ => "other",
        }
    }

    fn preference(&self) -> u32 {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 0,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 3,
            _ => 4,
        }
    }
}

/// Instance-level state shared by `Context` and `list_devices`.
struct InstanceParts {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    messages: Arc<AtomicU32>,
    surface: Option<Surface>,
}

impl InstanceParts {
    fn new(validation: bool, window: Option<WindowHandles>) -> Result<InstanceParts> {
        crate::driver_env::prepare();
        // SAFETY: loading the system Vulkan loader; its symbols are used through ash only.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| VkError::Loader(e.to_string()))?;
        let mut layers = Vec::new();
        let mut extensions = Vec::new();
        if let Some(w) = window {
            let needed = ash_window::enumerate_required_extensions(w.display)
                .map_err(|e| VkError::Call { what: "the window system's surface extensions", result: e })?;
            extensions.extend_from_slice(needed);
        }
        if validation {
            // SAFETY: plain enumeration.
            let available = unsafe { entry.enumerate_instance_layer_properties() }.ctx("vkEnumerateInstanceLayerProperties")?;
            if !available.iter().any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER)) {
                return Err(VkError::NoValidationLayer);
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(debug_utils::NAME.as_ptr());
        }
        let app = vk::ApplicationInfo::default().application_name(c"manylights").engine_name(c"manylights").api_version(MIN_API);
        let enabled = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled);
        let messages = Arc::new(AtomicU32::new(0));
        let messenger_info = || {
            vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&messages) as *mut c_void)
        };
        let mut instance_messenger = messenger_info();
        let mut info =
            vk::InstanceCreateInfo::default().application_info(&app).enabled_layer_names(&layers).enabled_extension_names(&extensions);
        if validation {
            // Chained so that instance creation and destruction are validated too.
            info = info.push_next(&mut features).push_next(&mut instance_messenger);
        }
        // SAFETY: all pointers in `info` outlive the call.
        let instance = match unsafe { entry.create_instance(&info, None) } {
            Ok(i) => i,
            Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => return Err(VkError::NoDriver),
            Err(e) => return Err(VkError::Call { what: "vkCreateInstance", result: e }),
        };
        let debug = if validation {
            let loader = debug_utils::Instance::new(&entry, &instance);
            // SAFETY: `messages` outlives the messenger (both dropped in `Drop`, messenger first).
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info(), None) };
            match messenger {
                Ok(m) => Some((loader, m)),
                Err(e) => {
                    // SAFETY: nothing else was created from the instance yet.
                    unsafe { instance.destroy_instance(None) };
                    return Err(VkError::Call { what: "vkCreateDebugUtilsMessengerEXT", result: e });
                }
            }
        } else {
            None
        };
        let mut parts = InstanceParts { entry, instance, debug, messages, surface: None };
        if let Some(w) = window {
            // SAFETY: the handles come from a live window that outlives the context (the viewer's
            // contract); the instance has the extensions they need.
            match unsafe { ash_window::create_surface(&parts.entry, &parts.instance, w.display, w.window, None) } {
                Ok(raw) => parts.surface = Some(Surface { loader: ash::khr::surface::Instance::new(&parts.entry, &parts.instance), raw }),
                Err(e) => {
                    parts.destroy();
                    return Err(VkError::Call { what: "vkCreate*SurfaceKHR", result: e });
                }
            }
        }
        Ok(parts)
    }

    /// Whether queue family `family` of `pd` can present to the surface (true without one).
    fn presents(&self, pd: vk::PhysicalDevice, family: u32) -> bool {
        self.surface.as_ref().is_none_or(|s| {
            // SAFETY: a physical device and surface of this instance.
            unsafe { s.loader.get_physical_device_surface_support(pd, family, s.raw) }.unwrap_or(false)
        })
    }

    fn devices(&self) -> Result<Vec<(vk::PhysicalDevice, DeviceInfo)>> {
        // SAFETY: plain enumeration on a live instance.
        let physical = unsafe { self.instance.enumerate_physical_devices() }.ctx("vkEnumeratePhysicalDevices")?;
        if physical.is_empty() {
            return Err(VkError::NoDriver);
        }
        Ok(physical.into_iter().enumerate().map(|(index, pd)| (pd, self.describe(index, pd))).collect())
    }

    fn describe(&self, index: usize, pd: vk::PhysicalDevice) -> DeviceInfo {
        // SAFETY: queries on a physical device of this instance.
        let props = unsafe { self.instance.get_physical_device_properties(pd) };
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        if props.api_version >= MIN_API {
            let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver).push_next(&mut subgroup);
            // SAFETY: core in 1.1+, and the device reports 1.2+.
            unsafe { self.instance.get_physical_device_properties2(pd, &mut props2) };
        }
        let mut v11 = vk::PhysicalDeviceVulkan11Features::default();
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut features = OptionalFeatures::default();
        if props.api_version >= MIN_API {
            let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut v11).push_next(&mut v12);
            // SAFETY: core in 1.1+, and the device reports 1.2+.
            unsafe { self.instance.get_physical_device_features2(pd, &mut features2) };
            let core = &features2.features;
            let on = |f: vk::Bool32| f == vk::TRUE;
            features = OptionalFeatures {
                image_cube_array: on(core.image_cube_array),
                multiview: on(v11.multiview),
                shader_output_layer: on(v12.shader_output_layer),
                full_draw_index_uint32: on(core.full_draw_index_uint32),
                sampled_image_array_indexing: on(core.shader_sampled_image_array_dynamic_indexing),
                buffer_int64_atomics: on(core.shader_int64) && on(v12.shader_buffer_int64_atomics),
                geometry_shader: on(core.geometry_shader),
                fragment_stores_and_atomics: on(core.fragment_stores_and_atomics),
                compute_subgroup_ballot: subgroup.supported_stages.contains(vk::ShaderStageFlags::COMPUTE)
                    && subgroup.supported_operations.contains(vk::SubgroupFeatureFlags::BALLOT),
            };
        }
        let name = c_text(props.device_name_as_c_str());
        DeviceInfo {
            features,
            index,
            name,
            device_type: props.device_type,
            api_version: props.api_version,
            driver_name: c_text(driver.driver_name_as_c_str()),
            driver_info: c_text(driver.driver_info_as_c_str()),
            limits: props.limits,
            suitable: props.api_version >= MIN_API
                && graphics_queue_family(&self.instance, pd).is_some_and(|(family, _)| self.presents(pd, family)),
        }
    }

    fn destroy(&mut self) {
        // SAFETY: called once, after every child object is gone.
        unsafe {
            if let Some(s) = self.surface.take() {
                s.loader.destroy_surface(s.raw, None);
            }
            if let Some((loader, m)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(m, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

fn c_text(text: std::result::Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    text.map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

fn graphics_queue_family(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Option<(u32, vk::QueueFamilyProperties)> {
    // SAFETY: query on a valid physical device.
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    families
        .into_iter()
        .enumerate()
        .find(|(_, f)| f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE))
        .map(|(i, f)| (i as u32, f))
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the AtomicU32 inside the Arc that the Context keeps alive; `data` is
    // valid for the duration of the callback per the Vulkan spec.
    unsafe {
        (*(user as *const AtomicU32)).fetch_add(1, Ordering::SeqCst);
        let message = if data.is_null() || (*data).p_message.is_null() {
            std::borrow::Cow::Borrowed("(no message)")
        } else {
            CStr::from_ptr((*data).p_message).to_string_lossy()
        };
        eprintln!("vulkan {severity:?} {kind:?}: {message}");
    }
    vk::FALSE
}

/// The device everything renders with.
/// Memory the allocator holds for a context: what its buffers and images take, and the
/// blocks it reserved from Vulkan to sub-allocate them from (device-local and host-visible).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryUse {
    pub allocated: u64,
    pub allocations: usize,
    pub reserved: u64,
}

pub struct Context {
    parts: InstanceParts,
    pub physical_device: vk::PhysicalDevice,
    pub info: DeviceInfo,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub queue_family: u32,
    /// Bits of a timestamp that are valid on our queue (0: no GPU timing).
    pub timestamp_valid_bits: u32,
    /// Whether compute pipelines print the driver's statistics of their shaders (registers,
    /// shared memory) as they are made: asked for with `MANYLIGHTS_PIPELINE_STATS`, on a device
    /// with VK_KHR_pipeline_executable_properties.
    pub pipeline_stats: bool,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(crate) transient_pool: vk::CommandPool,
    /// Pipelines, layouts and render passes shared by whoever asks for the same one.
    pub(crate) objects: Mutex<ObjectCache>,
}

/// The environment variable that asks for compute pipelines' statistics (`Context::pipeline_stats`).
pub const PIPELINE_STATS_VAR: &str = "MANYLIGHTS_PIPELINE_STATS";

/// Whether `pd` offers the device extension `name`.
fn has_device_extension(instance: &ash::Instance, pd: vk::PhysicalDevice, name: &std::ffi::CStr) -> bool {
    // SAFETY: a physical device of this instance.
    let extensions = unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
    extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name))
}

/// Describe every Vulkan device (for `manylights info`).
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let mut parts = InstanceParts::new(false, None)?;
    let devices = parts.devices().map(|d| d.into_iter().map(|(_, info)| info).collect());
    parts.destroy();
    devices
}

impl Context {
    pub fn new(desc: &ContextDesc) -> Result<Context> {
        let mut parts = InstanceParts::new(desc.validation, desc.window)?;
        match Self::with_instance(&parts, desc) {
            Ok((physical_device, info, device, queue_family, timestamp_valid_bits, pipeline_stats)) => {
                // SAFETY: the device was created with one queue in this family.
                let queue = unsafe { device.get_device_queue(queue_family, 0) };
                let allocator = Allocator::new(&AllocatorCreateDesc {
                    instance: parts.instance.clone(),
                    device: device.clone(),
                    physical_device,
                    debug_settings: Default::default(),
                    buffer_device_address: false,
                    allocation_sizes: Default::default(),
                })
                .map_err(|source| VkError::Alloc { what: "the allocator".into(), source })?;
                let pool_info = vk::CommandPoolCreateInfo::default()
                    .queue_family_index(queue_family)
                    .flags(vk::CommandPoolCreateFlags::TRANSIENT | vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
                // SAFETY: valid device and create info.
                let transient_pool = unsafe { device.create_command_pool(&pool_info, None) }.ctx("vkCreateCommandPool")?;
                Ok(Context {
                    parts,
                    physical_device,
                    info,
                    device,
                    queue,
                    queue_family,
                    timestamp_valid_bits,
                    pipeline_stats,
                    allocator: ManuallyDrop::new(Mutex::new(allocator)),
                    transient_pool,
                    objects: Mutex::new(ObjectCache::default()),
                })
            }
            Err(e) => {
                parts.destroy();
                Err(e)
            }
        }
    }

    #[allow(clippy::type_complexity)]
    fn with_instance(parts: &InstanceParts, desc: &ContextDesc) -> Result<(vk::PhysicalDevice, DeviceInfo, ash::Device, u32, u32, bool)> {
        let devices = parts.devices()?;
        let (pd, info) = match desc.device_index {
            Some(index) => {
                let count = devices.len();
                let (pd, info) = devices.into_iter().nth(index).ok_or(VkError::DeviceIndex { index, count })?;
                if !info.suitable {
                    return Err(VkError::NoSuitableDevice(format!(": device {index} '{}' is not", info.name)));
                }
                (pd, info)
            }
            None => devices
                .into_iter()
                .filter(|(_, i)| i.suitable)
                .min_by_key(|(_, i)| i.preference())
                .ok_or(VkError::NoSuitableDevice(String::new()))?,
        };
        let (family, family_props) = graphics_queue_family(&parts.instance, pd).expect("checked by `suitable`");
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
        // Optional features, enabled where the device has them; the renderer checks `info.features`
        // before it needs one and refuses in one line otherwise.
        let features = info.features;
        let core = vk::PhysicalDeviceFeatures::default()
            .image_cube_array(features.image_cube_array)
            .full_draw_index_uint32(features.full_draw_index_uint32)
            .shader_sampled_image_array_dynamic_indexing(features.sampled_image_array_indexing)
            .shader_int64(features.buffer_int64_atomics)
            .geometry_shader(features.geometry_shader)
            .fragment_stores_and_atomics(features.fragment_stores_and_atomics);
        let mut v11 = vk::PhysicalDeviceVulkan11Features::default().multiview(features.multiview);
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default()
            .shader_output_layer(features.shader_output_layer)
            .shader_buffer_int64_atomics(features.buffer_int64_atomics);
        let mut extensions = if parts.surface.is_some() { vec![ash::khr::swapchain::NAME.as_ptr()] } else { Vec::new() };
        let mut executable_info = vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default().pipeline_executable_info(true);
        let mut info_create =
            vk::DeviceCreateInfo::default().queue_create_infos(&queues).enabled_features(&core).push_next(&mut v11).push_next(&mut v12);
        let stats_extension = ash::khr::pipeline_executable_properties::NAME;
        let pipeline_stats = std::env::var_os(PIPELINE_STATS_VAR).is_some() && {
            let has = has_device_extension(&parts.instance, pd, stats_extension);
            if !has {
                eprintln!(
                    "{PIPELINE_STATS_VAR}: {} does not report pipeline statistics (no {})",
                    info.name,
                    stats_extension.to_string_lossy()
                );
            }
            has
        };
        if pipeline_stats {
            extensions.push(stats_extension.as_ptr());
            info_create = info_create.push_next(&mut executable_info);
        }
        let info_create = info_create.enabled_extension_names(&extensions);
        // SAFETY: valid physical device and create info; only supported features are enabled.
        let device = unsafe { parts.instance.create_device(pd, &info_create, None) }.ctx("vkCreateDevice")?;
        Ok((pd, info, device, family, family_props.timestamp_valid_bits, pipeline_stats))
    }

    pub fn instance(&self) -> &ash::Instance {
        &self.parts.instance
    }

    pub fn entry(&self) -> &ash::Entry {
        &self.parts.entry
    }

    /// The window's surface (a context made with `ContextDesc::window`).
    pub fn surface(&self) -> Option<&Surface> {
        self.parts.surface.as_ref()
    }

    /// Validation messages (warnings and errors) so far, through a handle that stays readable
    /// after the context is gone (the layer reports leaked objects while the device and
    /// instance are destroyed); 0 without validation.
    pub fn validation_counter(&self) -> Arc<AtomicU32> {
        self.parts.messages.clone()
    }

    /// The shared pipelines, layouts and render passes (object_cache.rs).
    pub(crate) fn objects(&self) -> std::sync::MutexGuard<'_, ObjectCache> {
        // As the allocator's: a panic elsewhere leaves the maps consistent.
        self.objects.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Pipelines the context keeps (object_cache.rs), and of those the ones someone holds
    /// (handed out by `shader` and not yet released: none once every renderer is gone).
    pub fn pipeline_counts(&self) -> (usize, usize) {
        self.objects().pipeline_counts()
    }

    pub fn allocator(&self) -> std::sync::MutexGuard<'_, Allocator> {
        // A poisoned lock only means another thread panicked mid-allocation; the allocator's
        // own state is still consistent for freeing.
        self.allocator.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// What the allocator holds now: every buffer and image (but lazily allocated
    /// attachments, which tilers back only as they are drawn).
    pub fn memory_use(&self) -> MemoryUse {
        let report = self.allocator().generate_report();
        MemoryUse { allocated: report.total_allocated_bytes, allocations: report.allocations.len(), reserved: report.total_capacity_bytes }
    }

    pub fn format_supports(&self, format: vk::Format, features: vk::FormatFeatureFlags) -> bool {
        // SAFETY: query on our physical device.
        let props = unsafe { self.parts.instance.get_physical_device_format_properties(self.physical_device, format) };
        props.optimal_tiling_features.contains(features)
    }

    /// The sample counts the device offers for 2D optimal-tiling images of `format` made for
    /// `usage` (empty where it cannot make such an image at all).
    pub fn image_sample_counts(&self, format: vk::Format, usage: vk::ImageUsageFlags) -> vk::SampleCountFlags {
        // SAFETY: query on our physical device.
        let props = unsafe {
            self.parts.instance.get_physical_device_image_format_properties(
                self.physical_device,
                format,
                vk::ImageType::TYPE_2D,
                vk::ImageTiling::OPTIMAL,
                usage,
                vk::ImageCreateFlags::empty(),
            )
        };
        props.map(|p| p.sample_counts).unwrap_or(vk::SampleCountFlags::empty())
    }

    /// Bytes of the device's largest device-local memory heap.
    pub fn device_local_bytes(&self) -> u64 {
        // SAFETY: a physical device of this instance.
        let props = unsafe { self.instance().get_physical_device_memory_properties(self.physical_device) };
        let heaps = &props.memory_heaps[..props.memory_heap_count as usize];
        heaps.iter().filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL)).map(|h| h.size).max().unwrap_or(0)
    }

    /// A LAZILY_ALLOCATED memory type among `type_bits` (what an image accepts), if the device
    /// has one (tile-based GPUs; not desktop NVIDIA, not lavapipe).
    pub fn lazily_allocated_memory_type(&self, type_bits: u32) -> Option<u32> {
        // SAFETY: a physical device of this instance.
        let props = unsafe { self.instance().get_physical_device_memory_properties(self.physical_device) };
        (0..props.memory_type_count).find(|&i| {
            type_bits & (1 << i) != 0 && props.memory_types[i as usize].property_flags.contains(vk::MemoryPropertyFlags::LAZILY_ALLOCATED)
        })
    }

    pub fn wait_idle(&self) -> Result<()> {
        // SAFETY: valid device.
        unsafe { self.device.device_wait_idle() }.ctx("vkDeviceWaitIdle")
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // SAFETY: the owner has destroyed every resource; waiting first makes that safe even on
        // an error path that left work in flight.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.objects.get_mut().unwrap_or_else(|e| e.into_inner()).destroy(&self.device);
            self.device.destroy_command_pool(self.transient_pool, None);
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
        }
        self.parts.destroy();
    }
}
