/* The V4L2 backend on a real kernel driver: run in the arm64 VM of tests/gpio_chip.sh against
 * vivid (the kernel's virtual video test driver). Prints one line per fact; the script checks
 * them. Usage: vivid-capture /dev/videoN */
#define _POSIX_C_SOURCE 200809L
#include "camera_v4l2.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#include <linux/videodev2.h>

#define W 640
#define H 480
#define FRAMES 6

static uint8_t rgb[W * H * 3];

static void log_line(enum hal_log_level level, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("log %d: ", (int)level);
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
}

static uint64_t now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u;
}

/* Set the driver control named @p name (vivid's test controls have no fixed ids). */
static int set_control_named(const char *device, const char *name, int32_t value)
{
    int fd = open(device, O_RDWR);
    if (fd < 0)
        return -errno;
    struct v4l2_queryctrl q = {.id = V4L2_CTRL_FLAG_NEXT_CTRL};
    int rc = -ENOENT;
    while (ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
        if (strcmp((const char *)q.name, name) == 0) {
            struct v4l2_control c = {.id = q.id, .value = value};
            rc = ioctl(fd, VIDIOC_S_CTRL, &c) == 0 ? 0 : -errno;
            break;
        }
        q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
    }
    close(fd);
    return rc;
}

/* Frames in a row: their sequence numbers, when they began against now, their content. */
static int capture_frames(const struct hal_camera *hc, uint32_t drop_frames)
{
    uint64_t last_seq = 0;
    uint32_t min_gap = 0xFFFFFFFFu, late = 0, blank = 0;
    for (int k = 0; k < FRAMES; k++) {
        struct hal_image img = {.rgb = rgb, .capacity = sizeof(rgb)};
        uint64_t before = now_us();
        int rc = hal_cam_capture(hc, &img);
        uint64_t after = now_us();
        if (rc != 0) {
            printf("capture %d: %s\n", k, strerror(-rc));
            return rc;
        }
        uint32_t lo = 255, hi = 0;
        for (size_t i = 0; i < (size_t)img.width * img.height * 3; i++) {
            lo = rgb[i] < lo ? rgb[i] : lo;
            hi = rgb[i] > hi ? rgb[i] : hi;
        }
        blank += hi - lo < 50; /* vivid draws a test pattern: colour bars */
        if (k > 0 && img.sequence - last_seq < min_gap)
            min_gap = (uint32_t)(img.sequence - last_seq);
        /* the frame began after the capture was asked for (the queued ones are dropped) and
         * before it came back */
        late += img.start_us == 0 || img.start_us > after || img.start_us + 500000u < before;
        printf("frame %d: %ux%u sequence %llu began %lld us before it returned, levels %u..%u\n", k,
               (unsigned)img.width, (unsigned)img.height, (unsigned long long)img.sequence,
               (long long)after - (long long)img.start_us, (unsigned)lo, (unsigned)hi);
        last_seq = img.sequence;
    }
    printf("frames: %d, smallest sequence step %u (drop_frames %u), timestamps %s, %s\n", FRAMES,
           (unsigned)min_gap, (unsigned)drop_frames, late ? "WRONG" : "ok",
           blank ? "BLANK" : "test pattern seen");
    return 0;
}

int main(int argc, char **argv)
{
    const char *device = argc > 1 ? argv[1] : "/dev/video0";
    static struct camera_v4l2 cam;
    struct hal_camera hc;
    camera_v4l2_init(&cam, log_line, &hc);
    struct hal_camera_config cfg = {.width = W,
                                    .height = H,
                                    .pixel_format = HAL_PIX_YUYV,
                                    .exposure_us = 10000,
                                    .gain_milli = 1000,
                                    .drop_frames = 2,
                                    .frame_timeout_ms = 2000,
                                    .binning = 1};
    snprintf(cfg.device, sizeof(cfg.device), "%s", device);
    int rc = hal_cam_open(&hc, &cfg);
    printf("open %ux%u yuyv: %s\n", (unsigned)cfg.width, (unsigned)cfg.height,
           rc == 0 ? "ok" : cam.error);
    if (rc == 0)
        rc = capture_frames(&hc, cfg.drop_frames);
    int exp_rc = hal_cam_set_exposure(&hc, 20000, 1000);
    printf("other exposure: %s\n", exp_rc == -ENOSYS ? "refused (no exposure control)"
                                   : exp_rc == 0     ? "accepted"
                                                     : strerror(-exp_rc));
    hal_cam_close(&hc);

    /* [camera] binning = 2: the driver streams 1280 x 960... it has 1280 x 720; 640 x 360 it is */
    struct hal_camera_config binned = cfg;
    binned.width = 640;
    binned.height = 360;
    binned.binning = 2;
    rc = hal_cam_open(&hc, &binned);
    printf("open 1280x720 binned to 640x360: %s\n", rc == 0 ? "ok" : cam.error);
    if (rc == 0) {
        struct hal_image img = {.rgb = rgb, .capacity = sizeof(rgb)};
        rc = hal_cam_capture(&hc, &img);
        printf("binned frame: %s %ux%u\n", rc == 0 ? "ok" : strerror(-rc), (unsigned)img.width,
               (unsigned)img.height);
    }
    hal_cam_close(&hc);

    /* Streaming stops (vivid drops every buffer): the capture gives up after the timeout. */
    cfg.frame_timeout_ms = 300;
    rc = hal_cam_open(&hc, &cfg);
    if (rc == 0) {
        int set = set_control_named(device, "Percentage of Dropped Buffers", 100);
        struct hal_image img = {.rgb = rgb, .capacity = sizeof(rgb)};
        uint64_t t0 = now_us();
        rc = hal_cam_capture(&hc, &img);
        printf("no frames (control %s): %s after %llu ms\n", set == 0 ? "set" : strerror(-set),
               rc == -ETIMEDOUT ? "timed out"
               : rc == 0        ? "A FRAME"
                                : strerror(-rc),
               (unsigned long long)(now_us() - t0) / 1000u);
        set_control_named(device, "Percentage of Dropped Buffers", 0);
    }
    hal_cam_close(&hc);
    printf("done\n");
    return 0;
}
