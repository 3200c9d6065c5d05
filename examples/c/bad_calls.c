/* Every kind of bad call to softshadow's C ABI: each must return the expected status and leave
 * a message, never crash. Prints one line per call; exits with the number of calls that did not
 * behave. tests/c_abi.rs runs it, under valgrind when valgrind is installed. */

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "softshadow.h"

static int failures = 0;

/* `says`: text the message must contain (NULL: any message). */
static void expect(const char *what, softshadow_status got, softshadow_status want, const char *says) {
    char message[256];
    size_t len = softshadow_last_error(message, sizeof message);
    int has_message = len > 0 && strlen(message) == (len < sizeof message ? len : sizeof message - 1);
    int ok = got == want && (want == SOFTSHADOW_OK || (has_message && (!says || strstr(message, says))));
    printf("%s %s -> %d (want %d): %s\n", ok ? "ok  " : "FAIL", what, (int)got, (int)want, message);
    failures += !ok;
}

#define EXPECT(call, want) expect(#call, (call), (want), NULL)
#define EXPECT_SAYING(call, want, says) expect(#call, (call), (want), (says))

/* VkAllocationCallbacks' layout, without including Vulkan's header. */
typedef struct {
    void *pUserData;
    void *pfnAllocation, *pfnReallocation, *pfnFree, *pfnInternalAllocation, *pfnInternalFree;
} allocation_callbacks;

static const float TRIANGLE[9] = {0, 0, 0, 1, 0, 0, 0, 0, 1};
static const uint32_t INDICES[3] = {0, 1, 2};
static const uint32_t OUT_OF_RANGE[3] = {0, 1, 99};

static softshadow_scene_desc good_desc(const softshadow_object *object) {
    softshadow_scene_desc d = {
        .camera = {.position = {0, 5, 5}, .target = {0, 0, 0}, .up = {0, 1, 0}, .fov_y_deg = 45},
        .light = {.position = {1, 6, 1}, .radius = 0.25f},
        .has_ground = 1,
        .ground_height = 0,
        .ground_half_size = 4,
        .objects = object,
        .object_count = 1,
    };
    return d;
}

int main(void) {
    /* Before any error: an empty message, safe with no buffer. */
    if (softshadow_last_error(NULL, 0) != 0) {
        printf("FAIL softshadow_last_error before any error is not empty\n");
        failures++;
    }
    if (strcmp(softshadow_version(), "0.1.0") != 0) {
        printf("FAIL softshadow_version() = %s\n", softshadow_version());
        failures++;
    }

    softshadow_engine *engine = NULL;
    softshadow_scene *scene = NULL;
    EXPECT(softshadow_engine_create_headless(0, NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_engine_destroy(NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_engine_set_size(NULL, 64, 64), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_engine_set_technique(NULL, "pcss", 5), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_render(NULL, NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_scene_destroy(NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_scene_load(NULL, 16, &scene), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_scene_load("scenes/default.toml", 19, &scene), SOFTSHADOW_ERROR_INVALID); /* no NUL within 19 */
    EXPECT(softshadow_scene_load("\xff\xfe.toml", 16, &scene), SOFTSHADOW_ERROR_INVALID);      /* not UTF-8 */
    EXPECT(softshadow_scene_load("no/such/scene.toml", 64, &scene), SOFTSHADOW_ERROR_SCENE);
    EXPECT(softshadow_scene_load("scenes/default.toml", 64, NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_scene_create(NULL, &scene), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_engine_create_from_vulkan(NULL, &engine), SOFTSHADOW_ERROR_NULL);
    /* Native windows: each refused before any handle is used (the Win32 one because this
     * loader has no VK_KHR_win32_surface, found before an instance exists). */
    int not_a_display = 0, not_a_window = 0;
    EXPECT(softshadow_engine_create_window(NULL, 0, &engine), SOFTSHADOW_ERROR_NULL);
    softshadow_native_window w = {.kind = 0, .display = &not_a_display, .window = 1};
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_INVALID, "window kind 0");
    w.kind = 99;
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_INVALID, "window kind 99");
    w = (softshadow_native_window){.kind = SOFTSHADOW_WINDOW_XLIB, .window = 1};
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_NULL, "xlib window's display");
    w.display = &not_a_display;
    w.window = 0;
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_NULL, "xlib window's window");
    w.window = 1;
    w.surface = &not_a_window;
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_INVALID, "`surface`");
    w = (softshadow_native_window){.kind = SOFTSHADOW_WINDOW_XCB, .display = &not_a_display, .window = 1ull << 32};
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_INVALID, "xcb_window_t");
    w.window = 1;
    EXPECT(softshadow_engine_create_window(&w, 0, NULL), SOFTSHADOW_ERROR_NULL);
    w = (softshadow_native_window){.kind = SOFTSHADOW_WINDOW_WAYLAND, .display = &not_a_display};
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_NULL, "wayland window's surface");
    w.surface = &not_a_window;
    w.window = 1;
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_INVALID, "`window`");
    w = (softshadow_native_window){.kind = SOFTSHADOW_WINDOW_WIN32};
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_NULL, "win32 window's surface");
    w.surface = &not_a_window;
    EXPECT_SAYING(softshadow_engine_create_window(&w, 0, &engine), SOFTSHADOW_ERROR_DEVICE, "VK_KHR_win32_surface");
    EXPECT(softshadow_present(NULL, NULL, NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_window_size(NULL, NULL, NULL), SOFTSHADOW_ERROR_NULL);
    softshadow_vulkan no_device = {0};
    EXPECT(softshadow_engine_create_from_vulkan(&no_device, &engine), SOFTSHADOW_ERROR_NULL);
    /* Allocation callbacks without pfnFree: refused before any handle is used. */
    int dummy = 0;
    allocation_callbacks no_free = {.pfnAllocation = &dummy, .pfnReallocation = &dummy};
    softshadow_vulkan bad_callbacks = {
        .get_instance_proc_addr = &dummy, .instance = &dummy, .physical_device = &dummy, .device = &dummy,
        .allocation_callbacks = &no_free,
    };
    EXPECT(softshadow_engine_create_from_vulkan(&bad_callbacks, &engine), SOFTSHADOW_ERROR_INVALID);

    softshadow_object object = {
        .positions = TRIANGLE,
        .vertex_count = 3,
        .indices = INDICES,
        .index_count = 3,
        .transform = {.position = {0, 1, 0}, .rotation_deg = {0, 0, 0}, .scale = {1, 1, 1}},
        .color = {0.5f, 0.5f, 0.5f},
        .casts = 1,
        .receives = 1,
    };
    softshadow_scene_desc d = good_desc(&object);
    d.camera.position[0] = NAN;
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_INVALID);
    d = good_desc(&object);
    d.camera.fov_y_deg = 200;
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_INVALID);
    d = good_desc(&object);
    d.light.radius = -1;
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_INVALID);
    d = good_desc(&object);
    d.objects = NULL;
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_NULL);
    softshadow_object bad = object;
    bad.index_count = 2;
    d = good_desc(&bad);
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_INVALID);
    bad = object;
    bad.indices = OUT_OF_RANGE;
    d = good_desc(&bad);
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_INVALID);
    bad = object;
    bad.positions = NULL;
    d = good_desc(&bad);
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_NULL);
    d = good_desc(&object);
    d.light.position[1] = -1; /* inside the ground */
    EXPECT(softshadow_scene_create(&d, &scene), SOFTSHADOW_ERROR_INVALID);

    /* Good handles, bad arguments. */
    d = good_desc(&object);
    if (softshadow_scene_create(&d, &scene) != SOFTSHADOW_OK || softshadow_engine_create_headless(0, &engine) != SOFTSHADOW_OK) {
        char message[256];
        softshadow_last_error(message, sizeof message);
        printf("FAIL cannot create a good scene and engine: %s\n", message);
        return 1;
    }
    EXPECT(softshadow_engine_set_technique(engine, "no-such-technique", 64), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_engine_set_technique(engine, "pcss", 4), SOFTSHADOW_ERROR_INVALID); /* no NUL within 4 */
    EXPECT(softshadow_engine_set_technique(engine, NULL, 4), SOFTSHADOW_ERROR_NULL);
    EXPECT(softshadow_engine_set_knob(engine, "no_such_knob", 64, 1), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_engine_set_knob(engine, "shadow_map_size", 64, 3), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_engine_set_knob(engine, "shadow_map_size", 64, NAN), SOFTSHADOW_ERROR_INVALID);
    uint32_t window_width = 0, window_height = 0;
    EXPECT(softshadow_window_size(engine, &window_width, &window_height), SOFTSHADOW_ERROR_INVALID); /* no window */
    EXPECT(softshadow_present(engine, scene, NULL), SOFTSHADOW_ERROR_INVALID);                      /* no window */
    EXPECT(softshadow_engine_set_size(engine, 0, 64), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_engine_set_size(engine, 64, 1u << 30), SOFTSHADOW_ERROR_INVALID);
    softshadow_transform nan_transform = {.position = {0, NAN, 0}, .rotation_deg = {0, 0, 0}, .scale = {1, 1, 1}};
    EXPECT(softshadow_scene_set_transform(scene, 0, &nan_transform), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_scene_set_transform(scene, 7, &object.transform), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_scene_set_transform(scene, 0, NULL), SOFTSHADOW_ERROR_NULL);
    softshadow_light dark = {.position = {0, 5, 0}, .radius = INFINITY};
    EXPECT(softshadow_scene_set_light(scene, &dark), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_scene_set_camera(scene, NULL), SOFTSHADOW_ERROR_NULL);
    softshadow_camera ortho_zero = {.position = {0, 5, 0}, .target = {0, 0, 0}, .up = {0, 0, 1}, .fov_y_deg = 0, .ortho_half_height = 0};
    EXPECT(softshadow_scene_set_camera(scene, &ortho_zero), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_scene_object_count(scene, NULL), SOFTSHADOW_ERROR_NULL);

    EXPECT(softshadow_engine_set_size(engine, 16, 16), SOFTSHADOW_OK);
    uint8_t small[16];
    EXPECT(softshadow_capture(engine, scene, small, sizeof small, NULL, 0), SOFTSHADOW_ERROR_BUFFER_TOO_SMALL);
    uint16_t v[16 * 16];
    EXPECT(softshadow_capture(engine, scene, NULL, 0, v, 16 * 16), SOFTSHADOW_OK);
    size_t count = 0;
    EXPECT(softshadow_last_timings(engine, NULL, 0, &count), SOFTSHADOW_ERROR_BUFFER_TOO_SMALL);
    EXPECT(softshadow_last_timings(engine, NULL, 0, NULL), SOFTSHADOW_ERROR_NULL);

    /* The embedded path refuses what it can check before touching a handle. */
    softshadow_recorded recorded;
    EXPECT(softshadow_record(engine, scene, NULL, &recorded), SOFTSHADOW_ERROR_NULL);
    softshadow_embedded_frame frame = {0};
    EXPECT(softshadow_record(engine, scene, &frame, &recorded), SOFTSHADOW_ERROR_NULL); /* depth image 0 */
    frame.depth.image = 1;
    frame.depth.format = 126; /* VK_FORMAT_D32_SFLOAT */
    frame.depth.width = frame.depth.height = 16;
    EXPECT(softshadow_record(engine, scene, &frame, &recorded), SOFTSHADOW_ERROR_INVALID); /* no command buffer */
    frame.command_buffer = (void *)1;
    frame.depth.format = 37; /* VK_FORMAT_R8G8B8A8_UNORM is no depth format */
    EXPECT(softshadow_record(engine, scene, &frame, &recorded), SOFTSHADOW_ERROR_INVALID);
    EXPECT(softshadow_discard_recorded(NULL), SOFTSHADOW_ERROR_NULL);
    EXPECT_SAYING(softshadow_discard_recorded(engine), SOFTSHADOW_ERROR_INVALID, "no frame to discard"); /* none recorded */

    /* The message is truncated to the room given and terminated; its full length returned. */
    char tiny[4];
    size_t full = softshadow_last_error(tiny, sizeof tiny);
    if (full <= 3 || strlen(tiny) != 3) {
        printf("FAIL a truncated message: %zu, \"%s\"\n", full, tiny);
        failures++;
    }

    EXPECT(softshadow_engine_destroy(engine), SOFTSHADOW_OK);
    EXPECT(softshadow_scene_destroy(scene), SOFTSHADOW_OK);
    printf("%d call(s) misbehaved\n", failures);
    return failures;
}
