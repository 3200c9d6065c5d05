/* A C renderer that embeds softshadow: its own Vulkan instance (validation and synchronization
 * validation on, a messenger counting errors) and device, its own depth "prepass" (a ground at
 * y = 0 and the top of a box, seen straight down through an orthographic camera, cleared into a
 * D32 reverse-Z depth image), and softshadow_record writing the box's shadow V into the
 * engine's target inside the embedder's command buffers, which it submits itself, two frames in
 * flight. The engine gets the embedder's host allocator (VkAllocationCallbacks counting its
 * blocks). The last frame's V is copied out and written as a 16-bit PGM; the last finished
 * frame's pass times and the host blocks made and still alive after the engine are printed.
 *
 *   cc examples/c/embedder.c -Iinclude -Ltarget/debug -lsoftshadow -lvulkan -o embedder
 *   ./embedder OUT_DIR
 *
 * tests/c_abi.rs compiles and runs it and checks the shadow lands where physics puts it. */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <vulkan/vulkan.h>

#include "softshadow.h"
#include "check.h"

#define SIDE 64
#define FRAMES 8
/* The camera: 10 m above the ground looking down, 3 m each way, planes at 1 m and 20 m. */
#define HEIGHT 10.0f
#define HALF 3.0f
#define NEAR 1.0f
#define FAR 20.0f

#define VK(call)                                                              \
    do {                                                                      \
        VkResult result_ = (call);                                            \
        if (result_ != VK_SUCCESS) {                                          \
            fprintf(stderr, "%s failed with VkResult %d\n", #call, (int)result_); \
            exit(1);                                                          \
        }                                                                     \
    } while (0)

static int validation_errors = 0;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT type,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user) {
    (void)type;
    (void)user;
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        validation_errors++;
        fprintf(stderr, "validation: %s\n", data->pMessage);
    }
    return VK_FALSE;
}

/* The embedder's host allocator: C11 aligned_alloc, each block prefixed by its size and
 * alignment, counted. */
static size_t host_made = 0, host_live = 0;

static void *VKAPI_CALL host_allocate(void *user, size_t size, size_t align, VkSystemAllocationScope scope) {
    (void)user;
    (void)scope;
    if (align < 2 * sizeof(size_t)) align = 2 * sizeof(size_t);
    size_t total = (size + 2 * align - 1) / align * align; /* the prefix takes one alignment */
    unsigned char *base = aligned_alloc(align, total);
    if (!base) return NULL;
    unsigned char *p = base + align;
    ((size_t *)p)[-1] = size;
    ((size_t *)p)[-2] = align;
    host_made++;
    host_live++;
    return p;
}

static void VKAPI_CALL host_free(void *user, void *memory) {
    (void)user;
    if (!memory) return;
    size_t align = ((size_t *)memory)[-2];
    free((unsigned char *)memory - align);
    host_live--;
}

static void *VKAPI_CALL host_reallocate(void *user, void *original, size_t size, size_t align, VkSystemAllocationScope scope) {
    if (size == 0) {
        host_free(user, original);
        return NULL;
    }
    void *moved = host_allocate(user, size, align, scope);
    if (moved && original) {
        size_t old = ((size_t *)original)[-1];
        memcpy(moved, original, old < size ? old : size);
        host_free(user, original);
    }
    return moved;
}

static const float CUBE[8 * 3] = {
    -0.5f, -0.5f, -0.5f, 0.5f, -0.5f, -0.5f, 0.5f, 0.5f, -0.5f, -0.5f, 0.5f, -0.5f,
    -0.5f, -0.5f, 0.5f,  0.5f, -0.5f, 0.5f,  0.5f, 0.5f, 0.5f,  -0.5f, 0.5f, 0.5f,
};
static const uint32_t CUBE_INDICES[12 * 3] = {
    0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
    3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5,
};

/* Reverse-Z orthographic depth of a surface `distance` below the camera. */
static float depth_at(float distance) { return (FAR - distance) / (FAR - NEAR); }

static uint32_t memory_type(VkPhysicalDevice physical, uint32_t bits, VkMemoryPropertyFlags flags) {
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(physical, &props);
    for (uint32_t i = 0; i < props.memoryTypeCount; i++) {
        if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & flags) == flags) return i;
    }
    fprintf(stderr, "no memory type\n");
    exit(1);
}

static void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect, VkPipelineStageFlags2 src_stage,
                          VkAccessFlags2 src_access, VkImageLayout old_layout, VkPipelineStageFlags2 dst_stage,
                          VkAccessFlags2 dst_access, VkImageLayout new_layout) {
    VkImageMemoryBarrier2 b = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2,
        .srcStageMask = src_stage,
        .srcAccessMask = src_access,
        .dstStageMask = dst_stage,
        .dstAccessMask = dst_access,
        .oldLayout = old_layout,
        .newLayout = new_layout,
        .srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED,
        .image = image,
        .subresourceRange = {aspect, 0, 1, 0, 1},
    };
    VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .imageMemoryBarrierCount = 1, .pImageMemoryBarriers = &b};
    vkCmdPipelineBarrier2(cmd, &dep);
}

int main(int argc, char **argv) {
    const char *out_dir = argc > 1 ? argv[1] : ".";

    /* The embedder's instance, with validation and synchronization validation. */
    VkDebugUtilsMessengerCreateInfoEXT messenger_ci = {
        .sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT,
        .messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT,
        .messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT,
        .pfnUserCallback = on_message,
    };
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features_ext = {
        .sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT,
        .pNext = &messenger_ci,
        .enabledValidationFeatureCount = 1,
        .pEnabledValidationFeatures = &sync,
    };
    const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
    const char *instance_ext[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
    VkApplicationInfo app = {.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO, .apiVersion = VK_API_VERSION_1_3};
    VkInstanceCreateInfo instance_ci = {
        .sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO,
        .pNext = &features_ext,
        .pApplicationInfo = &app,
        .enabledLayerCount = 1,
        .ppEnabledLayerNames = layers,
        .enabledExtensionCount = 2,
        .ppEnabledExtensionNames = instance_ext,
    };
    VkInstance instance;
    VK(vkCreateInstance(&instance_ci, NULL, &instance));
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
        (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT");
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger =
        (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT");
    VkDebugUtilsMessengerEXT messenger;
    VK(create_messenger(instance, &messenger_ci, NULL, &messenger));

    /* A Vulkan 1.3 device with a graphics queue family, created with what softshadow needs. */
    VkPhysicalDevice physicals[8];
    uint32_t physical_count = 8;
    VK(vkEnumeratePhysicalDevices(instance, &physical_count, physicals));
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    uint32_t family = 0;
    for (uint32_t i = 0; i < physical_count && physical == VK_NULL_HANDLE; i++) {
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(physicals[i], &props);
        VkQueueFamilyProperties families[16];
        uint32_t family_count = 16;
        vkGetPhysicalDeviceQueueFamilyProperties(physicals[i], &family_count, families);
        for (uint32_t f = 0; f < family_count && props.apiVersion >= VK_API_VERSION_1_3; f++) {
            if ((families[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) && families[f].timestampValidBits > 0) {
                physical = physicals[i];
                family = f;
                break;
            }
        }
    }
    if (physical == VK_NULL_HANDLE) {
        fprintf(stderr, "no Vulkan 1.3 device\n");
        return 1;
    }
    const char *device_ext[8];
    uint32_t device_ext_count = 0;
    while (device_ext_count < 8 && softshadow_required_device_extension(device_ext_count)) {
        device_ext[device_ext_count] = softshadow_required_device_extension(device_ext_count);
        device_ext_count++;
    }
    VkPhysicalDeviceVulkan13Features v13 = {
        .sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES,
        .synchronization2 = VK_TRUE,
        .dynamicRendering = VK_TRUE,
        .maintenance4 = VK_TRUE,
    };
    VkPhysicalDeviceFeatures core = {.depthClamp = VK_TRUE};
    float priority = 1.0f;
    VkDeviceQueueCreateInfo queue_ci = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO,
        .queueFamilyIndex = family,
        .queueCount = 1,
        .pQueuePriorities = &priority,
    };
    VkDeviceCreateInfo device_ci = {
        .sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO,
        .pNext = &v13,
        .queueCreateInfoCount = 1,
        .pQueueCreateInfos = &queue_ci,
        .enabledExtensionCount = device_ext_count,
        .ppEnabledExtensionNames = device_ext,
        .pEnabledFeatures = &core,
    };
    VkDevice device;
    VK(vkCreateDevice(physical, &device_ci, NULL, &device));
    VkQueue queue;
    vkGetDeviceQueue(device, family, 0, &queue);

    /* The engine on the embedder's objects, and the scene: a box at x = 1 under a light at
     * (4, 8, 0). The scene's own camera is not used on this path. */
    const VkAllocationCallbacks host = {
        .pfnAllocation = host_allocate,
        .pfnReallocation = host_reallocate,
        .pfnFree = host_free,
    };
    softshadow_vulkan vulkan = {
        .get_instance_proc_addr = (const void *)vkGetInstanceProcAddr,
        .instance = instance,
        .physical_device = physical,
        .device = device,
        .queue_family = family,
        .queue_index = 0,
        .allocation_callbacks = &host,
    };
    softshadow_engine *engine = NULL;
    CHECK(softshadow_engine_create_from_vulkan(&vulkan, &engine));
    CHECK(softshadow_engine_set_technique(engine, "pcss", 5));
    softshadow_object box = {
        .positions = CUBE,
        .vertex_count = 8,
        .indices = CUBE_INDICES,
        .index_count = 36,
        .transform = {.position = {1.0f, 0.5f, 0.0f}, .rotation_deg = {0, 0, 0}, .scale = {1, 1, 1}},
        .color = {0.8f, 0.3f, 0.2f},
        .casts = 1,
        .receives = 1,
    };
    softshadow_scene_desc desc = {
        .camera = {.position = {0, 12, 0}, .target = {0, 0, 0}, .up = {0, 0, -1}, .fov_y_deg = 45, .ortho_half_height = 0},
        .light = {.position = {4, 8, 0}, .radius = 0.2f},
        .has_ground = 1,
        .ground_height = 0,
        .ground_half_size = 10,
        .objects = &box,
        .object_count = 1,
    };
    softshadow_scene *scene = NULL;
    CHECK(softshadow_scene_create(&desc, &scene));

    /* The embedder's depth image and its view, a readback buffer, two command buffers. */
    VkImageCreateInfo image_ci = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO,
        .imageType = VK_IMAGE_TYPE_2D,
        .format = VK_FORMAT_D32_SFLOAT,
        .extent = {SIDE, SIDE, 1},
        .mipLevels = 1,
        .arrayLayers = 1,
        .samples = VK_SAMPLE_COUNT_1_BIT,
        .tiling = VK_IMAGE_TILING_OPTIMAL,
        .usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
    };
    VkImage depth;
    VK(vkCreateImage(device, &image_ci, NULL, &depth));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, depth, &req);
    VkMemoryAllocateInfo alloc = {
        .sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO,
        .allocationSize = req.size,
        .memoryTypeIndex = memory_type(physical, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT),
    };
    VkDeviceMemory depth_memory;
    VK(vkAllocateMemory(device, &alloc, NULL, &depth_memory));
    VK(vkBindImageMemory(device, depth, depth_memory, 0));
    VkImageViewCreateInfo view_ci = {
        .sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO,
        .image = depth,
        .viewType = VK_IMAGE_VIEW_TYPE_2D,
        .format = VK_FORMAT_D32_SFLOAT,
        .subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1},
    };
    VkImageView depth_view;
    VK(vkCreateImageView(device, &view_ci, NULL, &depth_view));

    VkBufferCreateInfo buffer_ci = {
        .sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO,
        .size = SIDE * SIDE * 2,
        .usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT,
    };
    VkBuffer readback;
    VK(vkCreateBuffer(device, &buffer_ci, NULL, &readback));
    vkGetBufferMemoryRequirements(device, readback, &req);
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = memory_type(physical, req.memoryTypeBits,
                                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    VkDeviceMemory readback_memory;
    VK(vkAllocateMemory(device, &alloc, NULL, &readback_memory));
    VK(vkBindBufferMemory(device, readback, readback_memory, 0));

    VkCommandPoolCreateInfo pool_ci = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO,
        .flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT,
        .queueFamilyIndex = family,
    };
    VkCommandPool pool;
    VK(vkCreateCommandPool(device, &pool_ci, NULL, &pool));
    VkCommandBufferAllocateInfo cmd_ai = {
        .sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
        .commandPool = pool,
        .level = VK_COMMAND_BUFFER_LEVEL_PRIMARY,
        .commandBufferCount = 2,
    };
    VkCommandBuffer cmds[2];
    VK(vkAllocateCommandBuffers(device, &cmd_ai, cmds));
    VkFence fences[2];
    VkFenceCreateInfo fence_ci = {.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO, .flags = VK_FENCE_CREATE_SIGNALED_BIT};
    for (int i = 0; i < 2; i++) VK(vkCreateFence(device, &fence_ci, NULL, &fences[i]));

    /* The camera as the embedder renders with it (column-major): view x = world x, view y =
     * -world z, looking down -z from y = HEIGHT; orthographic, y down, reverse Z. */
    const float view[16] = {1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, -HEIGHT, 1};
    const float projection[16] = {
        1 / HALF, 0, 0, 0, 0, -1 / HALF, 0, 0, 0, 0, 1 / (FAR - NEAR), 0, 0, 0, FAR / (FAR - NEAR), 1,
    };
    /* Pixels whose centres lie on the box's top (x in [0.5, 1.5], z in [-0.5, 0.5]). */
    const VkClearRect box_top = {.rect = {{37, 27}, {11, 10}}, .baseArrayLayer = 0, .layerCount = 1};

    softshadow_image_state depth_last = {VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
    softshadow_recorded recorded;
    for (int frame = 0; frame < FRAMES; frame++) {
        VkCommandBuffer cmd = cmds[frame % 2];
        /* The frame two back used these: it must have finished (softshadow_record's contract). */
        VK(vkWaitForFences(device, 1, &fences[frame % 2], VK_TRUE, UINT64_MAX));
        VK(vkResetFences(device, 1, &fences[frame % 2]));
        VK(vkResetCommandBuffer(cmd, 0));
        VkCommandBufferBeginInfo begin = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        VK(vkBeginCommandBuffer(cmd, &begin));

        /* The embedder's prepass: the ground's depth everywhere, the box's top over it. */
        const VkPipelineStageFlags2 tests =
            VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
        const VkAccessFlags2 depth_rw =
            VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
        image_barrier(cmd, depth, VK_IMAGE_ASPECT_DEPTH_BIT, depth_last.stage, depth_last.access, VK_IMAGE_LAYOUT_UNDEFINED,
                      tests, depth_rw, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
        VkRenderingAttachmentInfo attachment = {
            .sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO,
            .imageView = depth_view,
            .imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
            .loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR,
            .storeOp = VK_ATTACHMENT_STORE_OP_STORE,
            .clearValue = {.depthStencil = {depth_at(HEIGHT), 0}},
        };
        VkRenderingInfo rendering = {
            .sType = VK_STRUCTURE_TYPE_RENDERING_INFO,
            .renderArea = {{0, 0}, {SIDE, SIDE}},
            .layerCount = 1,
            .pDepthAttachment = &attachment,
        };
        vkCmdBeginRendering(cmd, &rendering);
        VkClearAttachment top = {.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT, .clearValue = {.depthStencil = {depth_at(HEIGHT - 1.0f), 0}}};
        vkCmdClearAttachments(cmd, 1, &top, 1, &box_top);
        vkCmdEndRendering(cmd);

        /* softshadow's passes, into the embedder's command buffer. */
        softshadow_embedded_frame embedded = {
            .command_buffer = cmd,
            .reverse_z = 1,
            .near = NEAR,
            .far = FAR,
            .depth = {.image = (uint64_t)depth,
                      .format = VK_FORMAT_D32_SFLOAT,
                      .width = SIDE,
                      .height = SIDE,
                      .state = {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, tests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT}},
        };
        memcpy(embedded.view, view, sizeof view);
        memcpy(embedded.projection, projection, sizeof projection);
        CHECK(softshadow_record(engine, scene, &embedded, &recorded));
        depth_last = recorded.depth;

        if (frame == FRAMES - 1) {
            /* V out of the engine's target, then back to the state the engine left it in. */
            VkImage v = (VkImage)recorded.visibility_image;
            softshadow_image_state s = recorded.visibility;
            image_barrier(cmd, v, VK_IMAGE_ASPECT_COLOR_BIT, s.stage, s.access, (VkImageLayout)s.layout,
                          VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
            VkBufferImageCopy copy = {.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1}, .imageExtent = {SIDE, SIDE, 1}};
            vkCmdCopyImageToBuffer(cmd, v, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback, 1, &copy);
            image_barrier(cmd, v, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE,
                          VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.stage, s.access, (VkImageLayout)s.layout);
            VkMemoryBarrier2 host = {
                .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2,
                .srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT,
                .srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT,
                .dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT,
                .dstAccessMask = VK_ACCESS_2_HOST_READ_BIT,
            };
            VkDependencyInfo dep = {.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO, .memoryBarrierCount = 1, .pMemoryBarriers = &host};
            vkCmdPipelineBarrier2(cmd, &dep);
        }
        VK(vkEndCommandBuffer(cmd));
        VkCommandBufferSubmitInfo cmd_info = {.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO, .commandBuffer = cmd};
        VkSubmitInfo2 submit = {.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO_2, .commandBufferInfoCount = 1, .pCommandBufferInfos = &cmd_info};
        VK(vkQueueSubmit2(queue, 1, &submit, fences[frame % 2]));
    }
    VK(vkWaitForFences(device, 2, fences, VK_TRUE, UINT64_MAX));

    softshadow_pass_time passes[32];
    size_t count = 0;
    CHECK(softshadow_last_timings(engine, passes, 32, &count));
    for (size_t i = 0; i < count; i++) printf("pass %s %.4f ms\n", passes[i].name, passes[i].gpu_ms);

    void *mapped;
    VK(vkMapMemory(device, readback_memory, 0, SIDE * SIDE * 2, 0, &mapped));
    char path[1024];
    snprintf(path, sizeof path, "%s/visibility.pgm", out_dir);
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "cannot write %s\n", path);
        return 1;
    }
    fprintf(f, "P5\n%d %d\n65535\n", SIDE, SIDE);
    const uint16_t *v = mapped;
    for (int i = 0; i < SIDE * SIDE; i++) {
        unsigned char be[2] = {(unsigned char)(v[i] >> 8), (unsigned char)(v[i] & 0xff)};
        fwrite(be, 1, 2, f);
    }
    fclose(f);
    vkUnmapMemory(device, readback_memory);

    /* The engine first: it destroys only what it made. */
    CHECK(softshadow_engine_destroy(engine));
    CHECK(softshadow_scene_destroy(scene));
    printf("host blocks through the callbacks: %zu made, %zu alive after the engine\n", host_made, host_live);
    for (int i = 0; i < 2; i++) vkDestroyFence(device, fences[i], NULL);
    vkDestroyCommandPool(device, pool, NULL);
    vkDestroyBuffer(device, readback, NULL);
    vkFreeMemory(device, readback_memory, NULL);
    vkDestroyImageView(device, depth_view, NULL);
    vkDestroyImage(device, depth, NULL);
    vkFreeMemory(device, depth_memory, NULL);
    vkDestroyDevice(device, NULL);
    destroy_messenger(instance, messenger, NULL);
    vkDestroyInstance(instance, NULL);
    printf("%d frames recorded; wrote %s; %d validation errors\n", FRAMES, path, validation_errors);
    return validation_errors == 0 && host_live == 0 ? 0 : 1;
}
