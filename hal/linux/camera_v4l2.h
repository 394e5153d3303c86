/* Camera backend on the V4L2 ioctls: fixed exposure, mmap streaming, frames as RGB24. */
#ifndef CAMERA_V4L2_H
#define CAMERA_V4L2_H

#include "hal.h"

#include <stddef.h>
#include <stdint.h>

#define CAMERA_V4L2_RING 4u /* buffers the driver fills while one is converted */

struct camera_v4l2 {
    int fd; /* -1 when closed */
    int streaming;
    struct hal_camera_config cfg;
    uint32_t fourcc, bytes_per_line;
    uint32_t frame_us;  /* one frame interval (VIDIOC_G_PARM); 0: the driver does not say */
    int exposure_fixed; /* the device has no exposure control: its own exposure is used */
    void *buf[CAMERA_V4L2_RING];
    size_t buf_len[CAMERA_V4L2_RING];
    uint32_t buf_count;
    void (*log)(enum hal_log_level level, const char *fmt, ...);
    char error[400]; /* what went wrong last, naming the device and the ioctl */
};

/** Fill @p out with the V4L2 ops on @p cam (closed); open() then opens cfg->device. */
void camera_v4l2_init(struct camera_v4l2 *cam,
                      void (*log)(enum hal_log_level level, const char *fmt, ...),
                      struct hal_camera *out);

#endif
