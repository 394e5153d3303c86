/* Camera backend on libcamera (C++ inside, C outside): still frames at a fixed exposure. */
#ifndef CAMERA_LIBCAMERA_H
#define CAMERA_LIBCAMERA_H

#include "hal.h"

#ifdef __cplusplus
extern "C" {
#endif

struct camera_libcamera {
    void *impl; /* the C++ state, made by camera_libcamera_init */
    void (*log)(enum hal_log_level level, const char *fmt, ...);
    char error[400]; /* what went wrong last, naming the camera and the call */
};

/** Fill @p out with the libcamera ops on @p cam; open() starts libcamera's camera manager and
 *  takes the camera whose id is cfg->device (empty or "auto": the first one).
 *  @retval 0 @retval -ENOMEM */
int camera_libcamera_init(struct camera_libcamera *cam,
                          void (*log)(enum hal_log_level level, const char *fmt, ...),
                          struct hal_camera *out);
/** Close the camera and free what init made. */
void camera_libcamera_free(struct camera_libcamera *cam);

#ifdef __cplusplus
}
#endif

#endif
