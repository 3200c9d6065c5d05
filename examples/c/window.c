/* A C program that owns its X11 window, made with Xlib or with xcb, and hands it to softshadow
 * as a softshadow_native_window: the engine presents frames of a scene file into it at the
 * window's size, following the window when the program resizes it, and the last frame's
 * per-pass GPU times are printed.
 *
 *   cc examples/c/window.c -Iinclude -Ltarget/debug -lsoftshadow -lX11 -lxcb -o window
 *   ./window xlib scenes/default.toml
 *   ./window xcb scenes/default.toml
 *
 * tests/window.rs compiles it and runs it both ways under its Xvfb, with validation on. */

#include <X11/Xlib.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xcb/xcb.h>

#include "softshadow.h"
#include "check.h"

#define FRAMES 30

/* The window, made by one of the two X11 client libraries. */
typedef struct {
    Display *display;          /* Xlib */
    xcb_connection_t *xcb;     /* xcb */
    uint64_t window;
} x11_window;

static x11_window open_window(const char *library, uint16_t width, uint16_t height) {
    x11_window w = {0};
    if (strcmp(library, "xlib") == 0) {
        w.display = XOpenDisplay(NULL);
        if (!w.display) {
            fprintf(stderr, "cannot open the X display\n");
            exit(1);
        }
        Window window = XCreateSimpleWindow(w.display, DefaultRootWindow(w.display), 0, 0, width, height, 0, 0, 0);
        XMapWindow(w.display, window);
        XSync(w.display, False);
        w.window = window;
    } else {
        w.xcb = xcb_connect(NULL, NULL);
        if (xcb_connection_has_error(w.xcb)) {
            fprintf(stderr, "cannot connect to the X server\n");
            exit(1);
        }
        xcb_screen_t *screen = xcb_setup_roots_iterator(xcb_get_setup(w.xcb)).data;
        xcb_window_t window = xcb_generate_id(w.xcb);
        xcb_create_window(w.xcb, XCB_COPY_FROM_PARENT, window, screen->root, 0, 0, width, height, 0,
                          XCB_WINDOW_CLASS_INPUT_OUTPUT, screen->root_visual, 0, NULL);
        xcb_map_window(w.xcb, window);
        w.window = window;
    }
    return w;
}

/* Waits until the server has handled every request sent so far. */
static void sync_window(const x11_window *w) {
    if (w->display) {
        XSync(w->display, False);
    } else {
        free(xcb_get_input_focus_reply(w->xcb, xcb_get_input_focus(w->xcb), NULL));
    }
}

static void resize_window(const x11_window *w, uint32_t width, uint32_t height) {
    if (w->display) {
        XResizeWindow(w->display, (Window)w->window, width, height);
    } else {
        const uint32_t size[2] = {width, height};
        xcb_configure_window(w->xcb, (xcb_window_t)w->window, XCB_CONFIG_WINDOW_WIDTH | XCB_CONFIG_WINDOW_HEIGHT, size);
    }
    sync_window(w);
}

static void close_window(const x11_window *w) {
    if (w->display) {
        XDestroyWindow(w->display, (Window)w->window);
        XCloseDisplay(w->display);
    } else {
        xcb_destroy_window(w->xcb, (xcb_window_t)w->window);
        xcb_disconnect(w->xcb);
    }
}

/* Presents FRAMES frames; prints how many reached the window, and at what size. */
static void present(softshadow_engine *engine, softshadow_scene *scene, const char *window) {
    int shown_frames = 0;
    for (int frame = 0; frame < FRAMES; frame++) {
        uint32_t shown = 0;
        CHECK(softshadow_present(engine, scene, &shown));
        shown_frames += (int)shown;
    }
    uint32_t width = 0, height = 0;
    CHECK(softshadow_window_size(engine, &width, &height));
    printf("window %s: %d of %d frames presented at %ux%u\n", window, shown_frames, FRAMES, width, height);
}

int main(int argc, char **argv) {
    if (argc != 3 || (strcmp(argv[1], "xlib") != 0 && strcmp(argv[1], "xcb") != 0)) {
        fprintf(stderr, "usage: %s xlib|xcb SCENE.toml\n", argv[0]);
        return 2;
    }
    x11_window w = open_window(argv[1], 96, 64);
    sync_window(&w);
    softshadow_native_window native = {.window = w.window};
    if (w.display) {
        native.kind = SOFTSHADOW_WINDOW_XLIB;
        native.display = w.display;
    } else {
        native.kind = SOFTSHADOW_WINDOW_XCB;
        native.display = w.xcb;
    }

    softshadow_scene *scene = NULL;
    CHECK(softshadow_scene_load(argv[2], strlen(argv[2]) + 1, &scene));
    softshadow_engine *engine = NULL;
    CHECK(softshadow_engine_create_window(&native, 1, &engine));
    present(engine, scene, "96x64");
    resize_window(&w, 48, 32);
    present(engine, scene, "48x32");

    softshadow_pass_time passes[32];
    size_t count = 0;
    CHECK(softshadow_last_timings(engine, passes, 32, &count));
    for (size_t i = 0; i < count; i++) printf("pass %s %.4f ms\n", passes[i].name, passes[i].gpu_ms);
    CHECK(softshadow_engine_destroy(engine));
    CHECK(softshadow_scene_destroy(scene));
    close_window(&w);
    return 0;
}
