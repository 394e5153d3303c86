/* One view's processing (decode, refinement, triangulation, normals, colour, fusion) on 1, 2
 * and 4 threads: wall time and speed-up, and the cores this machine has (make bench).
 * BENCH_THREADS=N: up to N threads only (1 for callgrind's count of what runs outside the
 * parallel loops: valgrind --tool=callgrind --collect-atstart=no
 * --toggle-collect=scan_finish_view --toggle-collect=scan_fuse_view build/bench_threads). */
#define _POSIX_C_SOURCE 200809L
#include "frames.h"
#include "fusion.h"
#include "scan.h"
#include "test_util.h"
#include "thread_posix.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#define REPEAT 5

static struct fusion_volume volume;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* The view's pattern frames @p kept handed to its decoder again (untimed): a view is finished
 * once (scan.h: its range image takes the decoder's working planes). */
static int feed_again(struct test_rig *t, const struct test_frames *kept)
{
    struct scan_ctx *s = t->scan;
    struct gray_layout layout;
    scan_layout(&t->cfg.scan, &t->calib, &layout);
    int rc = decode_begin(&s->decode, &s->planes.decoding, &t->cfg.scan, &layout,
                          t->calib.proj_width, t->calib.proj_height);
    for (uint32_t p = 0; p < gray_layout_count(&layout) && rc == 0; p++)
        rc = kept->grey[p] != NULL ? decode_frame(&s->decode, p, kept->grey[p]) : -ENOENT;
    return rc;
}

/* Best of REPEAT: the view finished from its decoder's frames (scan_finish_view: every stage
 * after the last frame) and fused, on @p cores. @p finish_ms, @p fuse_ms: out */
static int time_view(struct test_rig *t, const struct test_frames *kept,
                     const struct hal_thread *cores, struct scan_view *view, double *finish_ms,
                     double *fuse_ms)
{
    struct scan_view_info info;
    struct frame_xform pose;
    frame_object_from_camera(&t->calib, view->angle_mdeg, &pose);
    *finish_ms = *fuse_ms = 1e9;
    for (int r = 0; r < REPEAT; r++) {
        if (feed_again(t, kept) != 0)
            return -1;
        double t0 = now_ms();
        if (scan_finish_view(t->scan, cores, &t->calib, view->angle_mdeg, view, &info) != 0)
            return -1;
        double t1 = now_ms();
        if (fusion_begin(&volume, &t->cfg.fusion) != 0)
            return -1;
        double t2 = now_ms();
        if (scan_fuse_view(&volume, cores, &t->calib, view, &pose) != 0)
            return -1;
        double t3 = now_ms();
        *finish_ms = t1 - t0 < *finish_ms ? t1 - t0 : *finish_ms;
        *fuse_ms = t3 - t2 < *fuse_ms ? t3 - t2 : *fuse_ms;
    }
    return 0;
}

int main(int argc, char **argv)
{
    static struct test_rig t;
    if (test_rig_load(&t, argc > 1 ? argv[1] : "config/sim.ini") != 0 || test_rig_start(&t) != 0)
        return 1;
    struct scan_view view;
    struct scan_view_info info;
    static struct test_frames kept;
    kept.pixels = (size_t)t.cfg.scan.width * t.cfg.scan.height;
    kept.saturation_dn = t.cfg.scan.saturation_dn;
    struct scan_frame_sink sink = test_frames_sink(&kept);
    if (scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, &sink, &view, &info) != 0)
        return 1;
    long cores_online = sysconf(_SC_NPROCESSORS_ONLN);
    printf("one view %ux%u of '%s', colour '%s', processed after its last frame (best of %d, "
           "wall time; this machine has %ld cores: more threads than that share them)\n",
           (unsigned)view.width, (unsigned)view.height, t.cfg.sim.object,
           t.cfg.scan.colour.method == COLOUR_MULTI ? "multi" : "other", REPEAT, cores_online);
    printf("| threads | finish (decode to colour) ms | fusion ms | total ms | speed-up |\n");
    printf("|---|---|---|---|---|\n");
    double one = 0.0;
    unsigned most = getenv("BENCH_THREADS") ? (unsigned)atoi(getenv("BENCH_THREADS")) : 4u;
    for (unsigned threads = 1; threads <= most; threads *= 2) {
        struct hal_thread cores;
        thread_posix_init(&cores, threads);
        double finish_ms, fuse_ms;
        if (time_view(&t, &kept, &cores, &view, &finish_ms, &fuse_ms) != 0)
            return 1;
        double total = finish_ms + fuse_ms;
        if (threads == 1)
            one = total;
        printf("| %u | %.1f | %.1f | %.1f | %.2fx |\n", threads, finish_ms, fuse_ms, total,
               one / total);
    }
    test_rig_stop(&t);
    test_frames_free(&kept);
    return 0;
}
