/* V4L2 without a device: pixel formats, conversion to the firmware's RGB24, control choice. */
#ifndef V4L2_FRAME_H
#define V4L2_FRAME_H

#include "hal_camera.h"

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus /* the libcamera backend converts its frames with it too */
extern "C" {
#endif

/** The V4L2 fourcc the camera is asked for. @retval 0 for an unknown format */
uint32_t v4l2_fourcc_of(enum hal_pixel_format format);

/** "YUYV", "RGB3", ... for messages. @p buf holds at least 5 bytes. */
const char *v4l2_fourcc_text(uint32_t fourcc, char *buf);

/** Convert one frame of @p fourcc (rows @p bytes_per_line apart, @p used bytes delivered) into
 *  packed RGB24. YUYV is BT.601 limited range, as UVC cameras send it; GREY is replicated.
 *  @param width, height  the frame delivered to the firmware
 *  @param binning  1, or the sensor frame is @p binning times as wide and high and each
 *                  binning x binning block becomes one pixel, their mean ([camera] binning:
 *                  a sensor above the compiled frame size, with less noise per pixel)
 *  @retval 0 ok @retval -EIO short frame (fewer bytes than the mode needs)
 *  @retval -ENOSPC @p rgb_cap too small @retval -EINVAL unknown format, odd YUYV width or a
 *  binning outside 1..HAL_MAX_BINNING */
int v4l2_to_rgb(uint32_t fourcc, const uint8_t *src, size_t used, uint32_t bytes_per_line,
                uint32_t width, uint32_t height, uint32_t binning, uint8_t *rgb, size_t rgb_cap);

/** When the exposure of a dequeued frame began, in microseconds of CLOCK_MONOTONIC (the HAL
 *  clock), from its timestamp. A start-of-exposure stamp is taken as it is; an end-of-frame
 *  stamp goes back by the exposure and by @p frame_us (the readout of a rolling shutter takes
 *  up to one frame interval), so that the answer is never later than the truth.
 *  @param flags the buffer's flags (timestamp type and source)
 *  @param frame_us one frame interval (VIDIOC_G_PARM), 0 when the driver does not say
 *  @retval 0 when the stamp is not from CLOCK_MONOTONIC: the start cannot be compared */
uint64_t v4l2_frame_start_us(uint32_t flags, int64_t sec, int64_t usec, uint32_t exposure_us,
                             uint32_t frame_us);

/** A frame whose metadata say how long it was exposed (libcamera's ExposureTime), against what
 *  was asked for: sensors take a change of exposure a few frames late, so a frame of the old
 *  one must be taken again (its signal is scaled wrong: the colour frames', the HDR patterns'). */
enum v4l2_exposure {
    V4L2_EXPOSURE_AS_ASKED, /**< within 2% (at least 100 us: the sensor's line time) */
    V4L2_EXPOSURE_BEFORE,   /**< the exposure before the last change: not applied yet */
    V4L2_EXPOSURE_OTHER,    /**< neither (the sensor's limits at its frame rate, say) */
};
/** The exposure of a frame exposed @p actual_us when @p wanted_us was asked for, and
 *  @p before_us until the last change (equal to @p wanted_us when none since). */
enum v4l2_exposure v4l2_frame_exposure(uint32_t wanted_us, uint32_t before_us, uint32_t actual_us);

/** What the driver said of one control (VIDIOC_QUERYCTRL). */
struct v4l2_ctrl_info {
    uint32_t id;
    int present; /**< 0: the driver has no such control */
    int32_t minimum, maximum, step, default_value;
};

/** One control to set (VIDIOC_S_CTRL). */
struct v4l2_ctrl_value {
    uint32_t id;
    int32_t value;
    const char *name; /**< for messages */
};

#define V4L2_PLAN_MAX 6

/** The controls that give repeatable frames: auto exposure, auto gain and auto white balance
 *  off where the driver has them, manual exposure (V4L2_CID_EXPOSURE_ABSOLUTE, 100 us units)
 *  and the gain (analogue gain if present, else gain; @p gain_milli 1000 = the driver's
 *  default), in the order they must be set. A device with no exposure control at all (neither
 *  manual nor automatic: a test pattern generator, a fixed-exposure module) is usable at its
 *  own fixed exposure; one with only an automatic exposure is not.
 *  @param info  what the driver has, looked up by id (v4l2_plan_ids() lists the ids to query)
 *  @param exposure_fixed  out: 1 when the device has no exposure control (exposure_us unused)
 *  @retval 0 ok @retval -ENOTSUP an automatic exposure without a manual one
 *  @retval -ERANGE exposure or gain out of the driver's range; @p err says which and the range */
int v4l2_plan_controls(const struct v4l2_ctrl_info *info, size_t info_count, uint32_t exposure_us,
                       uint32_t gain_milli, struct v4l2_ctrl_value out[V4L2_PLAN_MAX],
                       size_t *out_count, int *exposure_fixed, char *err, size_t err_len);

/** The control ids v4l2_plan_controls() looks at. @retval their count */
size_t v4l2_plan_ids(const uint32_t **ids);

#ifdef __cplusplus
}
#endif

#endif
