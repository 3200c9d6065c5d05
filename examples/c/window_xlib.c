/* A C program that owns its X11 window (Xlib) and hands it to softshadow: the engine presents
 * frames of a scene file into it at the window's size, following the window when the program
 * resizes it, and the last frame's per-pass GPU times are printed.
 *
 *   cc examples/c/window_xlib.c -Iinclude -Ltarget/debug -lsoftshadow -lX11 -o window_xlib
 *   ./window_xlib scenes/default.toml
 *
 * tests/window.rs compiles and runs it under its Xvfb, with validation on. */

#include <X11/Xlib.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "softshadow.h"
#include "check.h"

#define FRAMES 30

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
    if (argc != 2) {
        fprintf(stderr, "usage: %s SCENE.toml\n", argv[0]);
        return 2;
    }
    Display *display = XOpenDisplay(NULL);
    if (!display) {
        fprintf(stderr, "cannot open the X display\n");
        return 1;
    }
    Window window = XCreateSimpleWindow(display, DefaultRootWindow(display), 0, 0, 96, 64, 0, 0, 0);
    XMapWindow(display, window);
    XSync(display, False);

    softshadow_scene *scene = NULL;
    CHECK(softshadow_scene_load(argv[1], strlen(argv[1]) + 1, &scene));
    softshadow_engine *engine = NULL;
    CHECK(softshadow_engine_create_xlib(display, window, 1, &engine));
    present(engine, scene, "96x64");
    XResizeWindow(display, window, 48, 32);
    XSync(display, False);
    present(engine, scene, "48x32");

    softshadow_pass_time passes[32];
    size_t count = 0;
    CHECK(softshadow_last_timings(engine, passes, 32, &count));
    for (size_t i = 0; i < count; i++) printf("pass %s %.4f ms\n", passes[i].name, passes[i].gpu_ms);
    CHECK(softshadow_engine_destroy(engine));
    CHECK(softshadow_scene_destroy(scene));
    XDestroyWindow(display, window);
    XCloseDisplay(display);
    return 0;
}
