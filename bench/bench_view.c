/* Time per view, split: rendering the 22 frames (the simulator, standing in for the camera) and
 * the firmware's processing of them (decode, refine, triangulate, normals, PLY). make bench. */
#define _POSIX_C_SOURCE 200809L
#include "decode.h"
#include "gray.h"
#include "refine.h"
#include "test_util.h"
#include "tri.h"
#include "frames.h"
#include "fusion.h"
#include "reg.h"
#include "scan.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define REPEAT 5

static struct reg_ctx reg;          /* the registration the view is kept for */
static struct fusion_volume volume; /* and the volume it is fused in */
static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* One view's processing from camera frames to fused volume and PLY, timing each stage in s[].
 * Not inlined: `make bench-callgrind` counts the instructions of this function alone. */
__attribute__((noinline)) void process_view_once(struct test_rig *t, const uint8_t *frames,
                                                 size_t frame_bytes, uint32_t count, double s[9])
{
    struct gray_layout layout;
    scan_layout(&t->cfg.scan, &t->calib, &layout);
    s[0] = now_ms();
    struct scan_ctx *sc = t->scan;
    decode_begin(&sc->decode, &sc->planes.decoding, &t->cfg.scan, &layout, t->calib.proj_width,
                 t->calib.proj_height);
    double convert_ms = 0.0; /* the grey conversion apart: each frame's bit is the decode's */
    for (uint32_t i = 0; i < count; i++) {
        double c0 = now_ms();
        decode_rgb_to_grey(frames + frame_bytes * i, decode_frame_slot(&sc->decode, i),
                           frame_bytes / 3, t->cfg.scan.saturation_dn);
        convert_ms += now_ms() - c0;
        decode_frame(&sc->decode, i, decode_frame_slot(&sc->decode, i));
    }
    s[1] = s[0] + convert_ms; /* s[2] - s[1]: reading the frames' bits, then decode_finish */
    /* the stages one by one, as scan_finish_view runs them (no colour: grey zero) */
    static uint8_t reason[HAL_MAX_PIXELS], rgb[HAL_MAX_PIXELS * 3];
    static float confidence[HAL_MAX_PIXELS];
    struct scan_view view = {.width = t->cfg.scan.width,
                             .height = t->cfg.scan.height,
                             .rgb = rgb,
                             .confidence = confidence};
    decode_finish(&sc->decode, NULL, reason, &view.maps); /* one thread: the stage's own cost */
    s[2] = now_ms();
    refine_columns(&view.maps, NULL, (int)t->cfg.scan.refine, sc->column);
    view.column = sc->column;
    s[3] = now_ms();
    tri_range_image(&t->calib, NULL, &sc->planes.tri, view.width, view.height, view.column, reason,
                    &view.range);
    s[4] = now_ms();
    tri_normals(&sc->planes.tri, NULL, &view.range, reason, t->cfg.scan.normal_radius_px,
                t->cfg.scan.max_depth_jump_mm);
    s[5] = now_ms();
    /* the joint registration keeps each view's samples now and solves once at the end */
    scan_keep_for_registration(&reg, 0, &view);
    s[6] = now_ms();
    struct frame_xform pose;
    frame_object_from_camera(&t->calib, view.angle_mdeg, &pose);
    scan_fuse_view(&volume, NULL, &t->calib, &view, &pose);
    s[7] = now_ms();
    scan_save_cloud_at_turntable_pose(t, &view, "build/bench_view.ply");
    s[8] = now_ms();
}

int main(int argc, char **argv)
{
    static struct test_rig t;
    if (test_rig_load(&t, argc > 1 ? argv[1] : "config/sim.ini") != 0 || test_rig_start(&t) != 0)
        return 1;
    struct sim_rig *rig = sim_ctl_rig();
    uint32_t count = gray_pattern_count(gray_bits_for_width(t.calib.proj_width));
    size_t frame_bytes = (size_t)rig->width * rig->height * 3;
    uint8_t *frames = malloc(frame_bytes * count);
    if (frames == NULL)
        return 1;
    double t0 = now_ms();
    sim_rig_update(rig);
    double t_geometry = now_ms() - t0;
    t0 = now_ms();
    for (uint32_t i = 0; i < count; i++) {
        struct sim_sources src = {.projector_on = 1,
                                  .pattern_index = i,
                                  .exposure_us = t.cfg.camera.exposure_us,
                                  .gain_milli = 1000};
        sim_rig_render(rig, &src, i, frames + frame_bytes * i);
    }
    double t_render = now_ms() - t0;
    double best[8] = {1e9, 1e9, 1e9, 1e9, 1e9, 1e9, 1e9, 1e9};
    if (fusion_begin(&volume, &t.cfg.fusion) != 0 ||
        reg_begin(&reg, &t.cfg.registration, &t.calib, t.cfg.views, 1, rig->width, rig->height) !=
            0)
        return 1;
    int repeat = getenv("BENCH_REPEAT") ? atoi(getenv("BENCH_REPEAT")) : REPEAT;
    for (int r = 0; r < repeat; r++) {
        double s[9];
        process_view_once(&t, frames, frame_bytes, count, s);
        for (int k = 0; k < 8; k++)
            best[k] = s[k + 1] - s[k] < best[k] ? s[k + 1] - s[k] : best[k];
    }
    printf("view %ux%u, %u frames, object '%s' (best of %d runs, one core)\n", (unsigned)rig->width,
           (unsigned)rig->height, (unsigned)count, t.cfg.sim.object, REPEAT);
    printf("| stage | ms |\n|---|---|\n");
    printf("| simulator: ray casting (once per angle) | %.1f |\n", t_geometry);
    printf("| simulator: rendering %u frames | %.1f |\n", (unsigned)count, t_render);
    const char *names[8] = {"camera RGB to grey (22 frames; a mono camera skips it)",
                            "decode (each frame's bit as it comes, then codes, checks)",
                            "sub-stripe refinement",
                            "triangulation",
                            "normals",
                            "registration (samples kept)",
                            "fusion (TSDF)",
                            "point cloud PLY write"};
    double total = 0.0;
    for (int k = 0; k < 8; k++) {
        printf("| firmware: %s | %.1f |\n", names[k], best[k]);
        total += k > 0 ? best[k] : 0.0;
    }
    printf("| **firmware processing per view (decode to PLY)** | **%.1f** |\n", total);
    free(frames);
    test_rig_stop(&t);
    return 0;
}
