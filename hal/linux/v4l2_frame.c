/* V4L2 without a device: pixel formats, conversion to the firmware's RGB24, control choice. */
#define _POSIX_C_SOURCE 200809L
#include "v4l2_frame.h"

#include "hal_limits.h"

#include <errno.h>
#include <time.h> /* struct timespec, which videodev2.h uses */
#include <linux/videodev2.h>
#include <stdio.h>
#include <string.h>

uint32_t v4l2_fourcc_of(enum hal_pixel_format format)
{
    switch (format) {
    case HAL_PIX_RGB24:
        return V4L2_PIX_FMT_RGB24;
    case HAL_PIX_YUYV:
        return V4L2_PIX_FMT_YUYV;
    case HAL_PIX_GREY:
        return V4L2_PIX_FMT_GREY;
    }
    return 0;
}

const char *v4l2_fourcc_text(uint32_t fourcc, char *buf)
{
    for (int k = 0; k < 4; k++) {
        char c = (char)((fourcc >> (8 * k)) & 0xFFu);
        buf[k] = c >= 32 && c < 127 ? c : '?';
    }
    buf[4] = '\0';
    return buf;
}

uint64_t v4l2_frame_start_us(uint32_t flags, int64_t sec, int64_t usec, uint32_t exposure_us,
                             uint32_t frame_us)
{
    if ((flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) != V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC || sec < 0 ||
        usec < 0)
        return 0;
    uint64_t stamp_us = (uint64_t)sec * 1000000u + (uint64_t)usec;
    uint64_t back_us = 0;
    if ((flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) != V4L2_BUF_FLAG_TSTAMP_SRC_SOE)
        back_us = (uint64_t)exposure_us + frame_us;
    return stamp_us > back_us ? stamp_us - back_us : 1u; /* 0 means "cannot tell" */
}

/* |a - b| within 2% of @p of (at least 100 us) */
static int exposure_near(uint32_t a, uint32_t b, uint32_t of)
{
    uint32_t diff = a > b ? a - b : b - a, tol = of / 50u > 100u ? of / 50u : 100u;
    return diff <= tol;
}

enum v4l2_exposure v4l2_frame_exposure(uint32_t wanted_us, uint32_t before_us, uint32_t actual_us)
{
    if (exposure_near(actual_us, wanted_us, wanted_us))
        return V4L2_EXPOSURE_AS_ASKED;
    return exposure_near(actual_us, before_us, before_us) ? V4L2_EXPOSURE_BEFORE
                                                          : V4L2_EXPOSURE_OTHER;
}

static uint8_t clamp_u8(int32_t v)
{
    return (uint8_t)(v < 0 ? 0 : v > 255 ? 255 : v);
}

/* BT.601, limited range (Y 16..235, Cb Cr 16..240), in 8.8 fixed point: ITU-R BT.601 as
 * Microsoft's YUV-to-RGB note writes it (298 = 255/219 x 256, and so on). */
static void yuv_to_rgb(int32_t y, int32_t u, int32_t v, uint8_t *rgb)
{
    int32_t c = 298 * (y - 16) + 128, d = u - 128, e = v - 128;
    rgb[0] = clamp_u8((c + 409 * e) >> 8);
    rgb[1] = clamp_u8((c - 100 * d - 208 * e) >> 8);
    rgb[2] = clamp_u8((c + 516 * d) >> 8);
}

static uint32_t bytes_per_pixel(uint32_t fourcc)
{
    return fourcc == V4L2_PIX_FMT_RGB24 ? 3u : fourcc == V4L2_PIX_FMT_YUYV ? 2u : 1u;
}

/* One row of @p width pixels of @p fourcc into RGB24. */
static void row_to_rgb(uint32_t fourcc, const uint8_t *s, uint32_t width, uint8_t *d)
{
    if (fourcc == V4L2_PIX_FMT_RGB24) {
        memcpy(d, s, (size_t)width * 3u);
    } else if (fourcc == V4L2_PIX_FMT_GREY) {
        for (uint32_t x = 0; x < width; x++)
            d[3 * x] = d[3 * x + 1] = d[3 * x + 2] = s[x];
    } else {
        for (uint32_t x = 0; x < width; x += 2, s += 4, d += 6) { /* Y0 U Y1 V */
            yuv_to_rgb(s[0], s[1], s[3], d);
            yuv_to_rgb(s[2], s[1], s[3], d + 3);
        }
    }
}

/* Binning: one sensor row in RGB, and the sums of the binned row being built. */
static uint8_t bin_row[HAL_MAX_WIDTH * HAL_MAX_BINNING * 3];
static uint32_t bin_sum[HAL_MAX_WIDTH * 3];

int v4l2_to_rgb(uint32_t fourcc, const uint8_t *src, size_t used, uint32_t bytes_per_line,
                uint32_t width, uint32_t height, uint32_t binning, uint8_t *rgb, size_t rgb_cap)
{
    if (fourcc != V4L2_PIX_FMT_RGB24 && fourcc != V4L2_PIX_FMT_YUYV && fourcc != V4L2_PIX_FMT_GREY)
        return -EINVAL;
    if (binning == 0 || binning > HAL_MAX_BINNING || (binning > 1 && width > HAL_MAX_WIDTH))
        return -EINVAL;
    const uint32_t sensor_w = width * binning, sensor_h = height * binning;
    if (fourcc == V4L2_PIX_FMT_YUYV && sensor_w % 2u != 0u)
        return -EINVAL;
    size_t row = (size_t)sensor_w * bytes_per_pixel(fourcc);
    size_t stride = bytes_per_line > row ? bytes_per_line : row;
    if ((size_t)width * height * 3u > rgb_cap)
        return -ENOSPC;
    if (height == 0 || used < stride * (sensor_h - 1u) + row)
        return -EIO; /* the last row must be complete */
    if (binning == 1) {
        for (uint32_t y = 0; y < height; y++)
            row_to_rgb(fourcc, src + stride * y, width, rgb + (size_t)width * 3u * y);
        return 0;
    }
    /* b x b sensor pixels to one: their mean, rounded (the noise falls by b). */
    const uint32_t count = binning * binning;
    for (uint32_t y = 0; y < height; y++) {
        memset(bin_sum, 0, (size_t)width * 3u * sizeof(bin_sum[0]));
        for (uint32_t r = 0; r < binning; r++) {
            row_to_rgb(fourcc, src + stride * ((size_t)y * binning + r), sensor_w, bin_row);
            for (uint32_t x = 0; x < sensor_w; x++)
                for (uint32_t c = 0; c < 3; c++)
                    bin_sum[3 * (x / binning) + c] += bin_row[3 * x + c];
        }
        uint8_t *d = rgb + (size_t)width * 3u * y;
        for (size_t k = 0; k < (size_t)width * 3u; k++)
            d[k] = (uint8_t)((bin_sum[k] + count / 2u) / count);
    }
    return 0;
}

static const uint32_t plan_ids[] = {
    V4L2_CID_EXPOSURE_AUTO,     V4L2_CID_AUTOGAIN,      V4L2_CID_AUTO_WHITE_BALANCE,
    V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_CID_ANALOGUE_GAIN, V4L2_CID_GAIN,
};

size_t v4l2_plan_ids(const uint32_t **ids)
{
    *ids = plan_ids;
    return sizeof(plan_ids) / sizeof(plan_ids[0]);
}

static const struct v4l2_ctrl_info *find(const struct v4l2_ctrl_info *info, size_t n, uint32_t id)
{
    for (size_t k = 0; k < n; k++)
        if (info[k].id == id && info[k].present)
            return &info[k];
    return NULL;
}

static void add(struct v4l2_ctrl_value *out, size_t *count, uint32_t id, int32_t value,
                const char *name)
{
    out[*count].id = id;
    out[*count].value = value;
    out[(*count)++].name = name;
}

int v4l2_plan_controls(const struct v4l2_ctrl_info *info, size_t info_count, uint32_t exposure_us,
                       uint32_t gain_milli, struct v4l2_ctrl_value out[V4L2_PLAN_MAX],
                       size_t *out_count, int *exposure_fixed, char *err, size_t err_len)
{
    const struct v4l2_ctrl_info *c;
    *out_count = 0;
    *exposure_fixed = 0;
    /* Automatics first: while auto exposure is on, most drivers refuse a manual exposure. */
    if ((c = find(info, info_count, V4L2_CID_EXPOSURE_AUTO)) != NULL)
        add(out, out_count, c->id, V4L2_EXPOSURE_MANUAL, "exposure_auto");
    if ((c = find(info, info_count, V4L2_CID_AUTOGAIN)) != NULL)
        add(out, out_count, c->id, 0, "autogain");
    if ((c = find(info, info_count, V4L2_CID_AUTO_WHITE_BALANCE)) != NULL)
        add(out, out_count, c->id, 0, "white_balance_automatic");
    c = find(info, info_count, V4L2_CID_EXPOSURE_ABSOLUTE);
    if (c == NULL && find(info, info_count, V4L2_CID_EXPOSURE_AUTO) != NULL) {
        snprintf(err, err_len, "no manual exposure control (exposure_time_absolute)");
        return -ENOTSUP; /* an automatic exposure that cannot be fixed would drift */
    }
    if (c == NULL) {
        *exposure_fixed = 1; /* no exposure control at all: the device's own, fixed */
    } else {
        int64_t units = ((int64_t)exposure_us + 50) / 100; /* the control counts 100 us */
        if (units < c->minimum || units > c->maximum) {
            snprintf(err, err_len, "exposure %u us is outside the camera's %d..%d us",
                     (unsigned)exposure_us, (int)c->minimum * 100, (int)c->maximum * 100);
            return -ERANGE;
        }
        add(out, out_count, c->id, (int32_t)units, "exposure_time_absolute");
    }
    c = find(info, info_count, V4L2_CID_ANALOGUE_GAIN);
    if (c == NULL)
        c = find(info, info_count, V4L2_CID_GAIN);
    if (c != NULL) {
        int64_t gain = ((int64_t)c->default_value * gain_milli + 500) / 1000;
        if (gain < c->minimum || gain > c->maximum) {
            snprintf(err, err_len,
                     "gain %u/1000 of the default (%d) is outside the camera's %d..%d",
                     (unsigned)gain_milli, (int)c->default_value, (int)c->minimum, (int)c->maximum);
            return -ERANGE;
        }
        add(out, out_count, c->id, (int32_t)gain,
            c->id == V4L2_CID_GAIN ? "gain" : "analogue_gain");
    } else if (gain_milli != 1000) {
        snprintf(err, err_len, "gain_milli = %u but the camera has no gain control",
                 (unsigned)gain_milli);
        return -ENOTSUP;
    }
    return 0;
}
