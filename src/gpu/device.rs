//! What the engine needs of a device, checked in one place: picking a device for a context of
//! our own, and accepting the device an embedder created.

use std::ffi::CStr;

use ash::vk;

use crate::error::{Error, Result, VkContext};

/// Device extensions every context needs: push descriptors bind every pass's inputs.
const DEVICE_EXTENSIONS: [&CStr; 1] = [ash::khr::push_descriptor::NAME];

/// A command of each of [`DEVICE_EXTENSIONS`]: Vulkan cannot list the extensions a device was
/// created with, but it hands out their commands only when they were enabled.
const EXTENSION_COMMANDS: [&CStr; DEVICE_EXTENSIONS.len()] = [c"vkCmdPushDescriptorSetKHR"];

type Feature13 = for<'a, 'b> fn(&'a mut vk::PhysicalDeviceVulkan13Features<'b>) -> &'a mut vk::Bool32;

/// The Vulkan 1.3 features every context needs, by their specification names. maintenance4
/// (required of every Vulkan 1.3 device) lets SPIR-V 1.6 compute shaders declare their workgroup
/// size with LocalSizeId, as shaderc emits it.
const VULKAN13_FEATURES: [(&str, Feature13); 3] = [
    ("dynamicRendering", |f| &mut f.dynamic_rendering),
    ("synchronization2", |f| &mut f.synchronization2),
    ("maintenance4", |f| &mut f.maintenance4),
];

type Feature10 = fn(&mut vk::PhysicalDeviceFeatures) -> &mut vk::Bool32;

/// The Vulkan 1.0 features every context needs. depthClamp: shadow volumes extruded to
/// infinity are kept whole instead of being cut by the far (and near) planes.
const CORE_FEATURES: [(&str, Feature10); 1] = [("depthClamp", |f| &mut f.depth_clamp)];

/// Depth-stencil formats in order of preference; Vulkan guarantees one of them.
const DEPTH_STENCIL_FORMATS: [vk::Format; 2] = [vk::Format::D32_SFLOAT_S8_UINT, vk::Format::D24_UNORM_S8_UINT];

/// The device extensions a device must have enabled to run the engine.
pub fn required_device_extensions() -> &'static [&'static CStr] {
    &DEVICE_EXTENSIONS
}

/// The Vulkan 1.3 features a device must have enabled to run the engine (chain them into
/// `VkDeviceCreateInfo`).
pub fn required_vulkan13_features() -> vk::PhysicalDeviceVulkan13Features<'static> {
    let mut features = vk::PhysicalDeviceVulkan13Features::default();
    for (_, field) in VULKAN13_FEATURES {
        *field(&mut features) = vk::TRUE;
    }
    features
}

/// The Vulkan 1.0 features a device must have enabled to run the engine
/// (`VkDeviceCreateInfo::pEnabledFeatures`).
pub fn required_core_features() -> vk::PhysicalDeviceFeatures {
    let mut features = vk::PhysicalDeviceFeatures::default();
    for (_, field) in CORE_FEATURES {
        *field(&mut features) = vk::TRUE;
    }
    features
}

/// What a context with a window needs beyond a headless one (hypermine's `Base::new` device
/// filter): the window system's instance extensions, the swapchain's device extension, and a
/// check that a queue family can present to the surface.
#[derive(Clone, Copy)]
pub struct DeviceFilter<'a> {
    /// Instance extensions to enable besides debug utils and validation.
    pub instance_extensions: &'a [&'a CStr],
    /// Device extensions to enable besides [`required_device_extensions`].
    pub device_extensions: &'a [&'a CStr],
    /// Whether queue family `family` of `physical` serves the caller.
    pub supports: &'a dyn Fn(&ash::Instance, vk::PhysicalDevice, u32) -> bool,
    /// What `supports` checks, in words completing "a queue family that …" for the error raised
    /// when no family passes.
    pub requirement: &'a str,
    /// Creates the window's surface once the instance exists (it must exist before a device is
    /// picked); the chosen queue family must then also present to it. The context keeps the
    /// surface and destroys it before the instance.
    pub surface: Option<&'a CreateSurface<'a>>,
}

/// Makes a surface on a fresh instance (see [`DeviceFilter::surface`]).
pub type CreateSurface<'a> = dyn Fn(&ash::Entry, &ash::Instance) -> Result<vk::SurfaceKHR> + 'a;

impl DeviceFilter<'static> {
    /// No extras: every graphics and compute queue family with timestamps will do.
    pub const HEADLESS: DeviceFilter<'static> = DeviceFilter {
        instance_extensions: &[],
        device_extensions: &[],
        supports: &any_family,
        requirement: "",
        surface: None,
    };
}

fn any_family(_: &ash::Instance, _: vk::PhysicalDevice, _: u32) -> bool {
    true
}

/// A device the engine can run on, and what the context keeps of it.
pub(super) struct Suitable {
    pub physical: vk::PhysicalDevice,
    pub props: vk::PhysicalDeviceProperties,
    pub queue_family: u32,
    pub depth_stencil_format: vk::Format,
}

/// A surface and its instance-level commands.
pub(super) type Surface = (ash::khr::surface::Instance, vk::SurfaceKHR);

/// A real GPU when present, lavapipe otherwise; `wanted` (a name substring) overrides. With a
/// `surface`, only queue families that can present to it qualify. The error names each device
/// and why it cannot be used.
pub(super) fn pick_device(
    instance: &ash::Instance,
    wanted: Option<&str>,
    filter: &DeviceFilter,
    surface: Option<&Surface>,
) -> Result<Suitable> {
    let devices = unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    let mut usable = Vec::new();
    let mut refused = Vec::new();
    for physical in devices {
        let props = unsafe { instance.get_physical_device_properties(physical) };
        match suitability(instance, physical, &props, filter, surface) {
            Ok((queue_family, depth_stencil_format)) => {
                usable.push(Suitable { physical, props, queue_family, depth_stencil_format })
            }
            Err(why) => refused.push(format!("{}: {why}", name_of(&props))),
        }
    }
    if usable.is_empty() {
        let why = if refused.is_empty() { "no Vulkan device".to_string() } else { refused.join("; ") };
        return Err(Error::NoDevice(format!("no usable Vulkan device ({why}): {}", super::context::INSTALL_HINT)));
    }
    if let Some(wanted) = wanted {
        let lower = wanted.to_lowercase();
        let names: Vec<_> = usable.iter().map(|s| name_of(&s.props)).collect();
        return usable.into_iter().find(|s| name_of(&s.props).to_lowercase().contains(&lower)).ok_or_else(|| {
            Error::NoDevice(format!("SOFTSHADOW_DEVICE={wanted} matches no device (have: {})", names.join(", ")))
        });
    }
    let rank = |t: vk::PhysicalDeviceType| match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    };
    Ok(usable.into_iter().min_by_key(|s| rank(s.props.device_type)).expect("non-empty"))
}

/// The queue family and depth-stencil format `physical` offers, or why it cannot be used.
fn suitability(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    props: &vk::PhysicalDeviceProperties,
    filter: &DeviceFilter,
    surface: Option<&Surface>,
) -> std::result::Result<(u32, vk::Format), String> {
    api_1_3(props)?;
    let available = unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
    let missing: Vec<_> = DEVICE_EXTENSIONS
        .iter()
        .chain(filter.device_extensions)
        .filter(|name| !available.iter().any(|e| e.extension_name_as_c_str() == Ok(**name)))
        .map(|name| name.to_string_lossy())
        .collect();
    if !missing.is_empty() {
        return Err(format!("lacks {}", missing.join(", ")));
    }
    features_supported(instance, physical)?;
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let capable: Vec<u32> = (0..families.len() as u32).filter(|&i| family_capable(&families[i as usize])).collect();
    if capable.is_empty() {
        return Err("no graphics and compute queue family with timestamps".into());
    }
    let family = capable
        .into_iter()
        .find(|&i| {
            (filter.supports)(instance, physical, i)
                && surface.is_none_or(|(loader, surface)| {
                    unsafe { loader.get_physical_device_surface_support(physical, i, *surface) }.unwrap_or(false)
                })
        })
        .ok_or_else(|| format!("no graphics and compute queue family that {}", filter.requirement))?;
    Ok((family, depth_stencil_format(instance, physical)?))
}

/// Checks that the device an embedder created can run the engine: Vulkan 1.3, the required
/// features (as the embedder says it enabled them; Vulkan cannot be asked) and extensions, and a
/// queue family with graphics, compute and timestamps. Returns the depth-stencil format to use.
pub(super) fn check_embedder_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    device: &ash::Device,
    queue_family: u32,
    enabled: &vk::PhysicalDeviceVulkan13Features,
    enabled_core: &vk::PhysicalDeviceFeatures,
) -> Result<vk::Format> {
    let props = unsafe { instance.get_physical_device_properties(physical) };
    let invalid = |why: String| Error::Invalid(format!("the embedder's device {}: {why}", name_of(&props)));
    api_1_3(&props).map_err(invalid)?;
    if !has_command(instance, device, c"vkCmdBeginRendering") {
        return Err(invalid("was not created for Vulkan 1.3 (vkCmdBeginRendering is missing)".into()));
    }
    let not_enabled = missing_features(enabled);
    if !not_enabled.is_empty() {
        return Err(invalid(format!("was created without the Vulkan 1.3 features {}", not_enabled.join(", "))));
    }
    let not_enabled = missing_core_features(enabled_core);
    if !not_enabled.is_empty() {
        return Err(invalid(format!("was created without the features {}", not_enabled.join(", "))));
    }
    let missing: Vec<_> = DEVICE_EXTENSIONS
        .iter()
        .zip(EXTENSION_COMMANDS)
        .filter(|(_, command)| !has_command(instance, device, command))
        .map(|(name, _)| name.to_string_lossy())
        .collect();
    if !missing.is_empty() {
        return Err(invalid(format!("was created without {}", missing.join(", "))));
    }
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    match families.get(queue_family as usize) {
        None => return Err(invalid(format!("has no queue family {queue_family}"))),
        Some(f) if !family_capable(f) => {
            return Err(invalid(format!("queue family {queue_family} lacks graphics, compute or timestamps")));
        }
        Some(_) => {}
    }
    depth_stencil_format(instance, physical).map_err(invalid)
}

fn api_1_3(props: &vk::PhysicalDeviceProperties) -> std::result::Result<(), String> {
    let v = props.api_version;
    if v < vk::API_VERSION_1_3 {
        return Err(format!("Vulkan {}.{} is older than 1.3", vk::api_version_major(v), vk::api_version_minor(v)));
    }
    Ok(())
}

fn family_capable(family: &vk::QueueFamilyProperties) -> bool {
    family.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE) && family.timestamp_valid_bits > 0
}

/// Names of the required Vulkan 1.3 features that `have` lacks.
fn missing_features(have: &vk::PhysicalDeviceVulkan13Features) -> Vec<&'static str> {
    let mut have = *have;
    VULKAN13_FEATURES.iter().filter(|(_, field)| *field(&mut have) != vk::TRUE).map(|(name, _)| *name).collect()
}

/// Names of the required Vulkan 1.0 features that `have` lacks.
fn missing_core_features(have: &vk::PhysicalDeviceFeatures) -> Vec<&'static str> {
    let mut have = *have;
    CORE_FEATURES.iter().filter(|(_, field)| *field(&mut have) != vk::TRUE).map(|(name, _)| *name).collect()
}

fn features_supported(instance: &ash::Instance, physical: vk::PhysicalDevice) -> std::result::Result<(), String> {
    let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut v13);
    unsafe { instance.get_physical_device_features2(physical, &mut features) };
    let core = features.features;
    let mut missing = missing_features(&v13);
    missing.extend(missing_core_features(&core));
    if missing.is_empty() { Ok(()) } else { Err(format!("lacks the features {}", missing.join(", "))) }
}

fn has_command(instance: &ash::Instance, device: &ash::Device, name: &CStr) -> bool {
    unsafe { (instance.fp_v1_0().get_device_proc_addr)(device.handle(), name.as_ptr()) }.is_some()
}

/// The first of [`DEPTH_STENCIL_FORMATS`] usable as an optimally tiled depth-stencil attachment.
fn depth_stencil_format(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
) -> std::result::Result<vk::Format, String> {
    DEPTH_STENCIL_FORMATS
        .into_iter()
        .find(|&format| {
            unsafe { instance.get_physical_device_format_properties(physical, format) }
                .optimal_tiling_features
                .contains(vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT)
        })
        .ok_or_else(|| "neither D32_SFLOAT_S8_UINT nor D24_UNORM_S8_UINT is a depth-stencil attachment format".into())
}

pub(super) fn name_of(props: &vk::PhysicalDeviceProperties) -> String {
    props.device_name_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

pub(super) fn driver_of(instance: &ash::Instance, physical: vk::PhysicalDevice) -> String {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
    let name = driver.driver_name_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let info = driver.driver_info_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    format!("{name} {info}").trim().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_required_features_are_the_checked_ones() {
        assert!(missing_features(&required_vulkan13_features()).is_empty());
        let without = required_vulkan13_features().synchronization2(false);
        assert_eq!(missing_features(&without), ["synchronization2"]);
        assert!(missing_core_features(&required_core_features()).is_empty());
        assert_eq!(missing_core_features(&vk::PhysicalDeviceFeatures::default()), ["depthClamp"]);
    }
}
