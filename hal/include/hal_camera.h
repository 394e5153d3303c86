/* Camera device interface: fixed-exposure frame capture into caller-owned buffers. */
#ifndef HAL_CAMERA_H
#define HAL_CAMERA_H

#include <stddef.h>
#include <stdint.h>

/** Pixel formats a backend may deliver; the firmware always receives RGB888. */
enum hal_pixel_format {
    HAL_PIX_RGB24 = 0, /**< 3 bytes per pixel, R G B */
    HAL_PIX_YUYV = 1,  /**< 4:2:2 packed, converted to RGB24 by the backend */
    HAL_PIX_GREY = 2,  /**< 1 byte per pixel, replicated to RGB24 by the backend */
};

/** Everything a camera needs to produce repeatable frames: no auto exposure, no AWB. */
struct hal_camera_config {
    char device[128];                   /**< device path or camera id; unused by the simulator */
    uint32_t width;                     /**< frame width in pixels */
    uint32_t height;                    /**< frame height in pixels */
    enum hal_pixel_format pixel_format; /**< format requested from the device */
    uint32_t exposure_us;               /**< fixed exposure time */
    uint32_t gain_milli;                /**< fixed analogue gain, 1000 = unity */
    uint32_t drop_frames;      /**< stale frames to discard after a light or pattern change */
    uint32_t frame_timeout_ms; /**< a capture with no frame after this fails with -ETIMEDOUT */
    uint32_t red_gain_milli;   /**< fixed white-balance gain of red, 1000 = 1 (libcamera) */
    uint32_t blue_gain_milli;  /**< fixed white-balance gain of blue, 1000 = 1 (libcamera) */
    uint32_t binning; /**< 1, or the sensor runs at binning x the frame's size, binned down */
};

/** One RGB24 frame in a caller-owned buffer of at least width * height * 3 bytes. */
struct hal_image {
    uint8_t *rgb;      /**< caller-owned pixel buffer */
    size_t capacity;   /**< size of @c rgb in bytes */
    uint32_t width;    /**< filled in by capture */
    uint32_t height;   /**< filled in by capture */
    uint64_t sequence; /**< frame counter of the device, filled in by capture */
    /** When the exposure of the frame's first row began, on the HAL clock (CLOCK_MONOTONIC on
     *  Linux), or earlier when the device only says roughly; 0 when it cannot tell. The
     *  firmware discards a frame that began before the last light or pattern change had
     *  settled: it would show the old pattern. */
    uint64_t start_us;
};

struct hal_camera_ops {
    /** @retval 0 ok @retval -ENODEV no such device @retval -EINVAL mode not supported */
    int (*open)(void *priv, const struct hal_camera_config *cfg);
    /** Capture one frame showing the current light/projector state.
     *  @retval 0 ok @retval -ETIMEDOUT no frame in time @retval -EIO corrupt or short frame
     *  @retval -ENOSPC buffer too small @retval -EAGAIN a frame the device says was taken
     *  before the last change had reached the sensor (an exposure not yet applied): said, and
     *  to be taken again as a stale one is */
    int (*capture)(void *priv, struct hal_image *img);
    /** Optional: change the fixed exposure and gain for the frames that follow (colour frames
     *  under different lights). @retval 0 ok @retval -EINVAL out of the device's range */
    int (*set_exposure)(void *priv, uint32_t exposure_us, uint32_t gain_milli);
    /** @retval 0 ok (closing a closed camera is fine) */
    int (*close)(void *priv);
    /** Stop streaming; must be callable at any time, including from a shutdown path. */
    int (*safe_state)(void *priv);
};

struct hal_camera {
    const struct hal_camera_ops *ops;
    void *priv;
};

/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_cam_open(const struct hal_camera *cam, const struct hal_camera_config *cfg);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_cam_capture(const struct hal_camera *cam, struct hal_image *img);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_cam_set_exposure(const struct hal_camera *cam, uint32_t exposure_us, uint32_t gain_milli);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_cam_close(const struct hal_camera *cam);

#endif
