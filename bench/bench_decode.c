/* The decode benchmark of make bench: on the same simulated frames (8-bit grey, columns and rows
 * with inverses), time (a) OpenCV's getProjPixel over every pixel, (b) the scanner's decoder
 * (every frame handed over, then the codes and reasons; the two apart) and (c) one plain read of
 * all the frames (the memory floor); check that both decoders agree on every pixel both call
 * valid, and that OpenCV's pattern set is ours. One core. */
#define _POSIX_C_SOURCE 200809L
#include "decode.h"
#include "gray.h"
#include "opencv_graycode.h"
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static char thread_line[512]; /* the rows of the threads' table, printed last */
static double thread_ms[5];   /* by thread count */

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

static int our_lit(void *ctx, unsigned index, unsigned column, unsigned row)
{
    return gray_layout_lit(ctx, index + GRAY_PATTERN_FIRST_BIT, column, row);
}

/* The memory floor: every byte of every frame read once (summed, so it cannot be skipped). */
static uint64_t read_all(const uint8_t *const *frames, uint32_t count, size_t n)
{
    uint64_t total = 0;
    for (uint32_t k = 0; k < count; k++) {
        uint32_t lane[64] = {0};
        const uint8_t *f = frames[k];
        for (size_t i = 0; i + 64 <= n; i += 64)
            for (int j = 0; j < 64; j++)
                lane[j] += f[i + (size_t)j];
        for (int j = 0; j < 64; j++)
            total += lane[j];
    }
    return total;
}

static int run(uint32_t width, uint32_t height)
{
    static struct test_rig t;
    if (test_rig_load(&t, "config/sim.ini") != 0)
        return 1;
    /* the same rig with a sensor of width x height (the HQ camera's binned mode is 2028x1520) */
    double s = (double)width / t.calib.cam_width;
    t.calib.cam_fx_px *= s;
    t.calib.cam_fy_px *= s;
    t.calib.cam_cx_px = (width - 1) / 2.0;
    t.calib.cam_cy_px = (height - 1) / 2.0;
    t.calib.cam_width = t.cfg.camera.width = t.cfg.scan.width = width;
    t.calib.cam_height = t.cfg.camera.height = t.cfg.scan.height = height;
    t.cfg.scan.decode_rows = 1;
    if (test_rig_start(&t) != 0)
        return 1;
    struct scan_view view;
    struct scan_view_info info;
    size_t n = (size_t)width * height;
    struct test_frames kept = {.pixels = n, .saturation_dn = t.cfg.scan.saturation_dn};
    struct scan_frame_sink keep = test_frames_sink(&kept);
    if (scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, 0, &keep, &view, &info) != 0)
        return 1;
    struct gray_layout layout;
    scan_layout(&t.cfg.scan, &t.calib, &layout);
    uint32_t count = gray_layout_count(&layout), patterns = count - GRAY_PATTERN_FIRST_BIT;
    const uint8_t *frames[DECODE_MAX_PATTERNS];
    for (uint32_t p = 0; p < count; p++)
        if ((frames[p] = kept.grey[p]) == NULL)
            return 1;

    int cv_count = 0;
    long bad = opencv_graycode_pattern_mismatches((int)t.calib.proj_width, (int)t.calib.proj_height,
                                                  &cv_count, our_lit, &layout);
    uint8_t *reason = malloc(n);
    struct decode_maps maps;
    if (reason == NULL)
        return 1;
    double floor_ms = 1e9, ours_ms = 1e9, ours_full_ms = 1e9, fed_ms = 0.0;
    volatile uint64_t sink = 0;
    for (int r = 0; r < 5; r++) {
        double t0 = now_ms();
        sink += read_all(frames + GRAY_PATTERN_FIRST_BIT, patterns, n);
        double floor_now = now_ms() - t0;
        /* each frame read into the pixels as it is handed over (put in its slot first, as the
         * camera or the frame reader does, untimed), then the codes and reasons */
        double fed = 0.0;
        scan_begin_view(t.scan, &t.cfg.scan, &t.calib);
        for (uint32_t p = 0; p < count; p++) {
            uint8_t *slot = decode_frame_slot(&t.scan->decode, p);
            memcpy(slot, frames[p], n);
            double f0 = now_ms();
            decode_frame(&t.scan->decode, p, slot);
            fed += now_ms() - f0;
        }
        double p0 = now_ms();
        decode_pixels(&t.scan->decode, NULL, reason, &maps);
        double ours_now = fed + now_ms() - p0;
        double q0 = now_ms();
        decode_finish(&t.scan->decode, NULL, reason, &maps);
        double full_now = fed + now_ms() - q0;
        floor_ms = floor_now < floor_ms ? floor_now : floor_ms;
        if (ours_now < ours_ms) /* of the best run: its frames and its pixels */
            ours_ms = ours_now, fed_ms = fed;
        ours_full_ms = full_now < ours_full_ms ? full_now : ours_full_ms;
    }
    /* what follows the last frame (codes, reasons, the neighbour checks: decode_finish) on 1, 2,
     * 4 threads, best of 5 each; each frame's bit is read into the pixels as it comes */
    for (unsigned threads = 1; threads <= 4; threads *= 2) {
        struct hal_thread cores = t.hal.thread;
        cores.threads = threads;
        double best = 1e9;
        for (int r = 0; r < 5; r++) {
            double t0 = now_ms();
            decode_finish(&t.scan->decode, &cores, reason, &maps);
            double dt = now_ms() - t0;
            best = dt < best ? dt : best;
        }
        thread_ms[threads] = best;
    }
    decode_pixels(&t.scan->decode, NULL, reason,
                  &maps); /* maps without the neighbour check, as OpenCV's */
    uint16_t *cv_col = malloc(n * 2), *cv_row = malloc(n * 2);
    uint8_t *cv_ok = malloc(n);
    double cv_ms =
        opencv_graycode_decode(frames + GRAY_PATTERN_FIRST_BIT, (int)patterns, (int)width,
                               (int)height, (int)t.calib.proj_width, (int)t.calib.proj_height,
                               (int)t.cfg.scan.min_bit_diff_dn + 1, cv_col, cv_row, cv_ok);
    const struct decode_maps *m = &maps;
    size_t both = 0, differ = 0, ours_valid = 0, cv_valid = 0;
    for (size_t i = 0; i < n; i++) {
        int mine = m->reason[i] == SCAN_VALID;
        ours_valid += (size_t)mine;
        cv_valid += cv_ok[i];
        if (!mine || !cv_ok[i])
            continue;
        both++;
        differ += m->column[i] != cv_col[i] || m->row[i] != cv_row[i];
    }
    snprintf(thread_line + strlen(thread_line), sizeof(thread_line) - strlen(thread_line),
             "| %ux%u | %.2f | %.2f (%.2fx) | %.2f (%.2fx) |\n", (unsigned)width, (unsigned)height,
             thread_ms[1], thread_ms[2], thread_ms[1] / thread_ms[2], thread_ms[4],
             thread_ms[1] / thread_ms[4]);
    printf("| %ux%u | %u | %.1f | %.2f (%.2f + %.2f) | %.2f | %.2f | **%.1fx** | **%.2fx** | %zu | "
           "%zu | %zu | %zu | %ld |\n",
           (unsigned)width, (unsigned)height, (unsigned)patterns, cv_ms, ours_ms, fed_ms,
           ours_ms - fed_ms, ours_full_ms, floor_ms, cv_ms / ours_ms, ours_ms / floor_ms, cv_valid,
           ours_valid, both, differ, bad);
    free(cv_col);
    free(cv_row);
    free(cv_ok);
    free(reason);
    test_rig_stop(&t);
    test_frames_free(&kept);
    (void)sink;
    return differ != 0 || bad != 0 || cv_count != (int)patterns;
}

int main(void)
{
    printf("Gray-code decoding of one view, one core (best of 5 for (b) and (c); (a) once)\n\n"
           "| frames | patterns | (a) OpenCV getProjPixel ms | (b) ours ms (frames + pixels) | "
           "ours + neighbour "
           "check ms | (c) memory floor ms | (a)/(b) | (b)/(c) | OpenCV valid px | our valid px "
           "| both valid | disagree | pattern pixels that differ |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    int rc = run(1280, 960);
    rc |= run(2028, 1520);
    if (HAL_MAX_PIXELS >= 4896u * 3264u) /* make LIMITS=large: a DSLR's frames, unbinned */
        rc |= run(4896, 3264);
    printf("\nWhat follows the last frame (codes, reasons, neighbour checks: decode_finish) split "
           "across threads (hal_thread; "
           "this machine has %ld cores online: more threads than cores share them), best of 5 "
           "ms and the speed-up over one:\n\n| frames | 1 thread | 2 threads | 4 threads "
           "|\n|---|---|---|---|\n%s",
           sysconf(_SC_NPROCESSORS_ONLN), thread_line);
    return rc;
}
