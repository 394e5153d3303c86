/* The HDMI projector ([projector] backend = drm): the GPIO interface's projector lines drive a
 * DRM/KMS display, the lights stay on their GPIO backend. */
#ifndef BOARD_DISPLAY_H
#define BOARD_DISPLAY_H

#include "gray.h"
#include "hal.h"
#include "projector_drm.h"
#include "scan_types.h"

struct board_display {
    struct projector_drm drm;
    struct hal_gpio lights;    /* every line but the projector's */
    struct gray_layout layout; /* the sequence the patterns are drawn from */
    uint32_t pattern;          /* the pattern the sequence is at */
    int enabled;               /* projector "on": the pattern shows; off: black */
};

/** Take the display at the calibration's projector size, showing black, and give a GPIO
 *  interface whose projector lines drive it and whose other lines go to @p lights.
 *  @retval 0 ok @retval -errno with @p err saying why (no display, no such mode) */
int board_display_open(struct board_display *d, const char *device, const struct scan_params *scan,
                       const struct scan_calib *calib, const struct hal_gpio *lights,
                       struct hal_gpio *out, char *err, size_t err_len);

/** Black, the display given back. */
void board_display_close(struct board_display *d);

#endif
