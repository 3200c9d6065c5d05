//! Validation: the Khronos layer with synchronization validation, and a messenger that records
//! every ERROR message so that tests fail on any.

use std::ffi::{CStr, c_void};
use std::sync::Mutex;

use ash::vk;

/// Validation errors seen so far. Boxed by the context so the callback's pointer stays put.
#[derive(Default)]
pub struct ValidationLog {
    errors: Mutex<Vec<String>>,
}

impl ValidationLog {
    pub fn errors(&self) -> Vec<String> {
        self.errors.lock().map(|e| e.clone()).unwrap_or_default()
    }
}

pub const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// The messenger description, also chained into instance creation so that messages from
/// `vkCreateInstance` and `vkDestroyInstance` are caught too.
pub fn messenger_info(log: &ValidationLog) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING)
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(callback))
        .user_data(log as *const ValidationLog as *mut c_void)
}

unsafe extern "system" fn callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid callback data; `user` is the boxed log, which outlives the
    // messenger and the instance (the context destroys both before dropping it).
    let (message, log) = unsafe {
        let message = (*data).message_as_c_str().map(|m| m.to_string_lossy().into_owned()).unwrap_or_default();
        (message, &*(user as *const ValidationLog))
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        eprintln!("[vulkan validation error] {message}");
        if let Ok(mut errors) = log.errors.lock() {
            errors.push(message);
        }
    } else {
        eprintln!("[vulkan validation warning] {message}");
    }
    vk::FALSE
}
