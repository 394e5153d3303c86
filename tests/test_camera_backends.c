/* The appliance's camera backends without a camera: conversion, control choice, missing devices. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <linux/videodev2.h>

#include "camera_v4l2.h"
#include "hal_limits.h"
#include "v4l2_frame.h"
#ifdef HAVE_LIBCAMERA
#include "camera_libcamera.h"
#endif

/* Open file descriptors of this process: a failed open must leave none behind. */
static int open_fds(void)
{
    int n = 0;
    DIR *d = opendir("/proc/self/fd");
    while (d != NULL && readdir(d) != NULL)
        n++;
    if (d != NULL)
        closedir(d);
    return n;
}

/* BT.601 limited range: black, white, and the primaries as a UVC camera codes them. */
static void test_yuyv_to_rgb(void **state)
{
    (void)state;
    /* two pixels per 4 bytes: Y0 U Y1 V */
    const uint8_t yuyv[] = {16, 128, 235, 128, 81, 90, 81, 240, 145, 54, 145, 34, 41, 240, 41, 110};
    uint8_t rgb[8 * 3];
    assert_int_equal(
        v4l2_to_rgb(V4L2_PIX_FMT_YUYV, yuyv, sizeof(yuyv), 0, 4, 2, 1, rgb, sizeof(rgb)), 0);
    const uint8_t want[8][3] = {{0, 0, 0},   {255, 255, 255}, {255, 0, 0}, {255, 0, 0},
                                {0, 255, 1}, {0, 255, 1},     {0, 0, 255}, {0, 0, 255}};
    for (int p = 0; p < 8; p++)
        for (int k = 0; k < 3; k++)
            assert_true(abs((int)rgb[3 * p + k] - (int)want[p][k]) <= 2);
}

static void test_rows_with_padding_and_grey(void **state)
{
    (void)state;
    /* 2 x 2 RGB24 with 8 bytes per line (2 of padding), then GREY with 4 per line */
    const uint8_t rgb_src[16] = {1, 2, 3, 4, 5, 6, 99, 99, 7, 8, 9, 10, 11, 12, 99, 99};
    uint8_t out[12];
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_RGB24, rgb_src, 14, 8, 2, 2, 1, out, sizeof(out)), 0);
    const uint8_t want[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    assert_memory_equal(out, want, sizeof(want));
    const uint8_t grey[8] = {10, 20, 0, 0, 30, 40, 0, 0};
    assert_int_equal(
        v4l2_to_rgb(V4L2_PIX_FMT_GREY, grey, sizeof(grey), 4, 2, 2, 1, out, sizeof(out)), 0);
    assert_int_equal(out[0], 10);
    assert_int_equal(out[2], 10);
    assert_int_equal(out[9], 40);
    assert_int_equal(out[11], 40);
}

/* [camera] binning: a sensor frame twice the compiled frame limit each way, binned 2 x 2 into
 * a frame the firmware takes, each pixel the rounded mean of its block; YUYV binned equals the
 * unbinned conversion averaged; a binning above the limit or a short sensor frame refused. */
static void test_binning_a_sensor_above_the_limit(void **state)
{
    (void)state;
    const uint32_t w = HAL_MAX_WIDTH, h = 3, sw = 2 * w, sh = 2 * h;
    uint8_t *grey = malloc((size_t)sw * sh), *out = malloc((size_t)w * h * 3);
    assert_non_null(grey);
    assert_non_null(out);
    for (uint32_t y = 0; y < sh; y++)
        for (uint32_t x = 0; x < sw; x++)
            grey[(size_t)y * sw + x] = (uint8_t)((x * 7u + y * 31u) & 0xFFu);
    assert_int_equal(
        v4l2_to_rgb(V4L2_PIX_FMT_GREY, grey, (size_t)sw * sh, sw, w, h, 2, out, (size_t)w * h * 3),
        0);
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            uint32_t sum = 0;
            for (uint32_t dy = 0; dy < 2; dy++)
                for (uint32_t dx = 0; dx < 2; dx++)
                    sum += grey[(size_t)(2 * y + dy) * sw + 2 * x + dx];
            for (int c = 0; c < 3; c++)
                assert_int_equal(out[3 * ((size_t)y * w + x) + (size_t)c], (sum + 2) / 4);
        }
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_GREY, grey, (size_t)sw * sh - 1, sw, w, h, 2, out,
                                 (size_t)w * h * 3),
                     -EIO);
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_GREY, grey, (size_t)sw * sh, sw, w / 4, h / 3,
                                 HAL_MAX_BINNING + 1, out, (size_t)w * h * 3),
                     -EINVAL);
    /* YUYV, 8 x 4 sensor pixels to 4 x 2 */
    uint8_t yuyv[8 * 4 * 2], full[8 * 4 * 3], binned[4 * 2 * 3];
    for (size_t k = 0; k < sizeof(yuyv); k++)
        yuyv[k] = (uint8_t)(40 + (k * 37u) % 180u);
    assert_int_equal(
        v4l2_to_rgb(V4L2_PIX_FMT_YUYV, yuyv, sizeof(yuyv), 16, 8, 4, 1, full, sizeof(full)), 0);
    assert_int_equal(
        v4l2_to_rgb(V4L2_PIX_FMT_YUYV, yuyv, sizeof(yuyv), 16, 4, 2, 2, binned, sizeof(binned)), 0);
    for (uint32_t y = 0; y < 2; y++)
        for (uint32_t x = 0; x < 4; x++)
            for (uint32_t c = 0; c < 3; c++) {
                uint32_t sum = 0;
                for (uint32_t dy = 0; dy < 2; dy++)
                    for (uint32_t dx = 0; dx < 2; dx++)
                        sum += full[3 * ((2 * y + dy) * 8 + 2 * x + dx) + c];
                assert_int_equal(binned[3 * (y * 4 + x) + c], (sum + 2) / 4);
            }
    free(grey);
    free(out);
}

static void test_short_frame_and_small_buffer(void **state)
{
    (void)state;
    uint8_t src[64] = {0}, out[48];
    /* 4 x 4 YUYV needs 32 bytes; one byte short is a corrupt frame */
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_YUYV, src, 31, 8, 4, 4, 1, out, sizeof(out)), -EIO);
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_YUYV, src, 32, 8, 4, 4, 1, out, sizeof(out)), 0);
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_YUYV, src, 32, 8, 4, 4, 1, out, 47), -ENOSPC);
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_MJPEG, src, 64, 0, 4, 4, 1, out, sizeof(out)),
                     -EINVAL);
    assert_int_equal(v4l2_to_rgb(V4L2_PIX_FMT_YUYV, src, 64, 0, 3, 2, 1, out, sizeof(out)),
                     -EINVAL);
    char text[5];
    assert_string_equal(v4l2_fourcc_text(v4l2_fourcc_of(HAL_PIX_YUYV), text), "YUYV");
}

/* A UVC webcam's controls: auto exposure as a menu, exposure in 100 us, gain, AWB. */
static const struct v4l2_ctrl_info uvc[] = {
    {V4L2_CID_EXPOSURE_AUTO, 1, 0, 3, 1, 3},      {V4L2_CID_AUTOGAIN, 0, 0, 0, 0, 0},
    {V4L2_CID_AUTO_WHITE_BALANCE, 1, 0, 1, 1, 1}, {V4L2_CID_EXPOSURE_ABSOLUTE, 1, 3, 2047, 1, 250},
    {V4L2_CID_ANALOGUE_GAIN, 0, 0, 0, 0, 0},      {V4L2_CID_GAIN, 1, 0, 255, 1, 64},
};

static void test_controls_turn_automatics_off_first(void **state)
{
    (void)state;
    struct v4l2_ctrl_value plan[V4L2_PLAN_MAX];
    size_t n;
    int fixed;
    char err[160];
    assert_int_equal(v4l2_plan_controls(uvc, 6, 10000, 2000, plan, &n, &fixed, err, sizeof(err)),
                     0);
    assert_int_equal(n, 4);
    assert_int_equal(plan[0].id, V4L2_CID_EXPOSURE_AUTO);
    assert_int_equal(plan[0].value, V4L2_EXPOSURE_MANUAL);
    assert_int_equal(plan[1].id, V4L2_CID_AUTO_WHITE_BALANCE);
    assert_int_equal(plan[1].value, 0);
    assert_int_equal(plan[2].id, V4L2_CID_EXPOSURE_ABSOLUTE);
    assert_int_equal(plan[2].value, 100); /* 10 ms in 100 us units */
    assert_int_equal(plan[3].id, V4L2_CID_GAIN);
    assert_int_equal(plan[3].value, 128); /* twice the default gain */
}

static void test_controls_out_of_range_are_named(void **state)
{
    (void)state;
    struct v4l2_ctrl_value plan[V4L2_PLAN_MAX];
    size_t n;
    int fixed;
    char err[160];
    assert_int_equal(v4l2_plan_controls(uvc, 6, 300000, 1000, plan, &n, &fixed, err, sizeof(err)),
                     -ERANGE);
    assert_non_null(strstr(err, "exposure 300000 us is outside the camera's 300..204700 us"));
    assert_int_equal(v4l2_plan_controls(uvc, 6, 10000, 8000, plan, &n, &fixed, err, sizeof(err)),
                     -ERANGE);
    assert_non_null(strstr(err, "gain"));
    /* an automatic exposure with no manual one: not a camera the scanner can use */
    assert_int_equal(v4l2_plan_controls(uvc, 3, 10000, 1000, plan, &n, &fixed, err, sizeof(err)),
                     -ENOTSUP);
    assert_non_null(strstr(err, "no manual exposure"));
    /* no exposure control at all (vivid, a fixed-exposure module): its own, fixed */
    assert_int_equal(
        v4l2_plan_controls(uvc + 1, 2, 10000, 1000, plan, &n, &fixed, err, sizeof(err)), 0);
    assert_int_equal(fixed, 1);
    assert_int_equal(n, 1); /* white balance off; no exposure, no gain to set */
    assert_int_equal(plan[0].id, V4L2_CID_AUTO_WHITE_BALANCE);
}

/* The start of exposure, which the firmware compares with when a pattern had settled: never
 * later than the truth, and 0 when the stamp's clock is not the HAL's. */
static void test_frame_start_from_timestamp(void **state)
{
    (void)state;
    const uint32_t mono = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    /* start-of-exposure stamp: taken as it is */
    assert_int_equal(
        v4l2_frame_start_us(mono | V4L2_BUF_FLAG_TSTAMP_SRC_SOE, 12, 345678, 10000, 33333),
        12345678u);
    /* end-of-frame stamp: back by the exposure and one frame's readout */
    assert_int_equal(
        v4l2_frame_start_us(mono | V4L2_BUF_FLAG_TSTAMP_SRC_EOF, 12, 345678, 10000, 33333),
        12345678u - 10000u - 33333u);
    assert_int_equal(v4l2_frame_start_us(mono, 0, 500, 10000, 0), 1u); /* not "unknown" */
    /* stamps from another clock cannot be compared with the HAL clock */
    assert_int_equal(v4l2_frame_start_us(V4L2_BUF_FLAG_TIMESTAMP_COPY, 12, 0, 10000, 0), 0u);
    assert_int_equal(v4l2_frame_start_us(V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN, 12, 0, 10000, 0), 0u);
}

static struct hal_camera_config camera_config(const char *device)
{
    struct hal_camera_config c;
    memset(&c, 0, sizeof(c));
    snprintf(c.device, sizeof(c.device), "%s", device);
    c.width = 640;
    c.height = 480;
    c.pixel_format = HAL_PIX_YUYV;
    c.exposure_us = 10000;
    c.gain_milli = 1000;
    c.frame_timeout_ms = 100;
    c.red_gain_milli = c.blue_gain_milli = 1000;
    return c;
}

static void test_v4l2_missing_device(void **state)
{
    (void)state;
    static struct camera_v4l2 cam;
    struct hal_camera hc;
    camera_v4l2_init(&cam, NULL, &hc);
    int fds = open_fds();
    struct hal_camera_config c = camera_config("/dev/video-does-not-exist");
    assert_int_equal(hal_cam_open(&hc, &c), -ENODEV);
    assert_string_equal(cam.error, "camera /dev/video-does-not-exist: open: No such device");
    assert_int_equal(cam.fd, -1);
    assert_int_equal(open_fds(), fds);
    /* a file that is not a V4L2 device: refused at VIDIOC_QUERYCAP, and closed again */
    c = camera_config("/dev/null");
    assert_int_equal(hal_cam_open(&hc, &c), -ENODEV);
    assert_non_null(strstr(cam.error, "camera /dev/null: VIDIOC_QUERYCAP: not a V4L2 device"));
    assert_int_equal(cam.fd, -1);
    assert_int_equal(open_fds(), fds);
    struct hal_image img = {.rgb = NULL};
    assert_int_equal(hal_cam_capture(&hc, &img), -ENODEV);
    assert_int_equal(hal_cam_close(&hc), 0);
}

/* A frame's exposure as its metadata say (libcamera): as asked within the sensor's line time,
 * the one before a change the sensor had not yet applied (taken again), or another. */
static void test_frame_exposure_against_the_change(void **state)
{
    (void)state;
    assert_int_equal(v4l2_frame_exposure(10000, 10000, 10000), V4L2_EXPOSURE_AS_ASKED);
    assert_int_equal(v4l2_frame_exposure(15000, 10000, 15020), V4L2_EXPOSURE_AS_ASKED);
    assert_int_equal(v4l2_frame_exposure(15000, 10000, 14700), V4L2_EXPOSURE_AS_ASKED);
    assert_int_equal(v4l2_frame_exposure(15000, 10000, 14650), V4L2_EXPOSURE_OTHER);
    assert_int_equal(v4l2_frame_exposure(100, 10000, 199), V4L2_EXPOSURE_AS_ASKED); /* 100 us */
    /* the colour frames' exposure asked for, the patterns' still in the frame; and back */
    assert_int_equal(v4l2_frame_exposure(15000, 10000, 10000), V4L2_EXPOSURE_BEFORE);
    assert_int_equal(v4l2_frame_exposure(15000, 10000, 9850), V4L2_EXPOSURE_BEFORE);
    assert_int_equal(v4l2_frame_exposure(10000, 15000, 15000), V4L2_EXPOSURE_BEFORE);
    /* HDR's 40 ms where a 30 fps frame holds 33 ms: neither */
    assert_int_equal(v4l2_frame_exposure(40000, 10000, 33000), V4L2_EXPOSURE_OTHER);
    /* no change since: a mismatch is another exposure, not a late one */
    assert_int_equal(v4l2_frame_exposure(40000, 40000, 33000), V4L2_EXPOSURE_OTHER);
}

#ifdef HAVE_LIBCAMERA
static void test_libcamera_missing_camera(void **state)
{
    (void)state;
    static struct camera_libcamera cam;
    struct hal_camera hc;
    assert_int_equal(camera_libcamera_init(&cam, NULL, &hc), 0);
    struct hal_camera_config c = camera_config("/base/soc/i2c0mux/i2c@1/imx477@1a");
    int rc = hal_cam_open(&hc, &c);
    print_message("libcamera: %s\n", cam.error);
    assert_true(rc == -ENODEV || rc < 0);
    assert_non_null(strstr(cam.error, "camera libcamera '/base/soc/i2c0mux/i2c@1/imx477@1a'"));
    struct hal_image img = {.rgb = NULL};
    assert_int_equal(hal_cam_capture(&hc, &img), -ENODEV);
    camera_libcamera_free(&cam);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_yuyv_to_rgb),
        cmocka_unit_test(test_rows_with_padding_and_grey),
        cmocka_unit_test(test_short_frame_and_small_buffer),
        cmocka_unit_test(test_binning_a_sensor_above_the_limit),
        cmocka_unit_test(test_controls_turn_automatics_off_first),
        cmocka_unit_test(test_controls_out_of_range_are_named),
        cmocka_unit_test(test_frame_start_from_timestamp),
        cmocka_unit_test(test_frame_exposure_against_the_change),
        cmocka_unit_test(test_v4l2_missing_device),
#ifdef HAVE_LIBCAMERA
        cmocka_unit_test(test_libcamera_missing_camera),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
