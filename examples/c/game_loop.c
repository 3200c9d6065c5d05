/* A game loop in C over softshadow's C ABI: a scene built from C structs (a box over a ground
 * plane, seen from straight above), 200 frames moving the box from x = -1 to x = +1, the
 * technique switched half way, the last frame's V written as a 16-bit PGM and its color as a
 * PPM, and the last frame's per-pass GPU times printed.
 *
 *   cc examples/c/game_loop.c -Iinclude -Ltarget/debug -lsoftshadow -o game_loop
 *   ./game_loop OUT_DIR
 *
 * tests/c_abi.rs compiles and runs it and checks the shadow lands where physics puts it. */

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "softshadow.h"
#include "check.h"

#define SIDE 64
#define FRAMES 200

/* A unit cube about the origin: 8 corners, 12 triangles. */
static const float CUBE[8 * 3] = {
    -0.5f, -0.5f, -0.5f, 0.5f, -0.5f, -0.5f, 0.5f, 0.5f, -0.5f, -0.5f, 0.5f, -0.5f,
    -0.5f, -0.5f, 0.5f,  0.5f, -0.5f, 0.5f,  0.5f, 0.5f, 0.5f,  -0.5f, 0.5f, 0.5f,
};
static const uint32_t CUBE_INDICES[12 * 3] = {
    0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
    3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5,
};

static float box_x(int frame) { return -1.0f + 2.0f * (float)frame / (float)(FRAMES - 1); }

static void set_technique(softshadow_engine *engine, const char *name) {
    CHECK(softshadow_engine_set_technique(engine, name, strlen(name) + 1));
    printf("technique %s\n", name);
}

static void print_timings(softshadow_engine *engine, int frame) {
    softshadow_pass_time passes[32];
    size_t count = 0;
    CHECK(softshadow_last_timings(engine, passes, 32, &count));
    double total = 0.0;
    for (size_t i = 0; i < count; i++) {
        printf("frame %d pass %s %.4f ms\n", frame, passes[i].name, passes[i].gpu_ms);
        total += passes[i].gpu_ms;
    }
    printf("frame %d total %.4f ms over %zu passes\n", frame, total, count);
}

static int write_outputs(const char *dir, const uint16_t *v, const uint8_t *rgba) {
    char path[1024];
    snprintf(path, sizeof path, "%s/visibility.pgm", dir);
    FILE *f = fopen(path, "wb");
    if (!f) return 0;
    /* 16-bit PGM: big-endian samples, V = value / 65535, row 0 at the top. */
    fprintf(f, "P5\n%d %d\n65535\n", SIDE, SIDE);
    for (int i = 0; i < SIDE * SIDE; i++) {
        unsigned char be[2] = {(unsigned char)(v[i] >> 8), (unsigned char)(v[i] & 0xff)};
        fwrite(be, 1, 2, f);
    }
    fclose(f);
    snprintf(path, sizeof path, "%s/color.ppm", dir);
    f = fopen(path, "wb");
    if (!f) return 0;
    fprintf(f, "P6\n%d %d\n255\n", SIDE, SIDE);
    for (int i = 0; i < SIDE * SIDE; i++) fwrite(rgba + 4 * i, 1, 3, f);
    fclose(f);
    return 1;
}

int main(int argc, char **argv) {
    const char *out_dir = argc > 1 ? argv[1] : ".";
    printf("softshadow %s\n", softshadow_version());

    softshadow_object box = {
        .positions = CUBE,
        .vertex_count = 8,
        .indices = CUBE_INDICES,
        .index_count = 36,
        .transform = {.position = {box_x(0), 0.5f, 0.0f}, .rotation_deg = {0, 0, 0}, .scale = {1, 1, 1}},
        .color = {0.8f, 0.3f, 0.2f},
        .casts = 1,
        .receives = 1,
    };
    /* Straight down, orthographic: image x = world x, rows = world z, 3 m each way. */
    softshadow_scene_desc desc = {
        .camera = {.position = {0, 12, 0}, .target = {0, 0, 0}, .up = {0, 0, -1}, .fov_y_deg = 0, .ortho_half_height = 3},
        .light = {.position = {4, 8, 0}, .radius = 0.2f},
        .has_ground = 1,
        .ground_height = 0,
        .ground_half_size = 10,
        .objects = &box,
        .object_count = 1,
    };
    softshadow_scene *scene = NULL;
    CHECK(softshadow_scene_create(&desc, &scene));
    softshadow_engine *engine = NULL;
    CHECK(softshadow_engine_create_headless(0, &engine));
    CHECK(softshadow_engine_set_size(engine, SIDE, SIDE));
    set_technique(engine, "shadow-map");

    static uint16_t visibility[SIDE * SIDE];
    static uint8_t color[SIDE * SIDE * 4];
    for (int frame = 0; frame < FRAMES; frame++) {
        if (frame == FRAMES / 2) {
            print_timings(engine, frame - 1);
            set_technique(engine, "pcss");
        }
        box.transform.position[0] = box_x(frame);
        CHECK(softshadow_scene_set_transform(scene, 0, &box.transform));
        if (frame == FRAMES - 1) {
            CHECK(softshadow_capture(engine, scene, color, sizeof color, visibility, SIDE * SIDE));
        } else {
            CHECK(softshadow_render(engine, scene));
        }
    }
    print_timings(engine, FRAMES - 1);
    if (!write_outputs(out_dir, visibility, color)) {
        fprintf(stderr, "cannot write into %s\n", out_dir);
        return 1;
    }
    printf("box at x = %.3f; wrote %s/visibility.pgm (16-bit V) and %s/color.ppm\n", box_x(FRAMES - 1), out_dir, out_dir);
    CHECK(softshadow_engine_destroy(engine));
    CHECK(softshadow_scene_destroy(scene));
    return 0;
}
