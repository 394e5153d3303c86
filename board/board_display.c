/* The HDMI projector ([projector] backend = drm): the projector's three GPIO lines routed to the
 * display. Enable shows the current pattern (off: black), a reset pulse pattern 0, a trigger
 * pulse the next; each returns once the page flip is on screen. The lights stay on libgpiod.
 * The board draws the patterns: it knows the sequence (firmware/gray.h), the HAL does not. */
#include "board_display.h"

#include "gray.h"
#include "scan.h"

#include <errno.h>
#include <string.h>

#define FLIP_TIMEOUT_MS 1000u /* a vblank is 17 ms at 60 Hz: a second means no display */

/* XRGB8888 white where pattern @p pattern lights the projector pixel. */
static int render(void *ctx, uint32_t pattern, uint8_t *xrgb, uint32_t width, uint32_t height,
                  uint32_t pitch)
{
    const struct board_display *d = ctx;
    int is_row = 0, inverse;
    uint32_t k;
    if (gray_layout_pattern(&d->layout, pattern, &is_row, &k, &inverse) != 0)
        is_row = 0; /* white or black: the same on every row */
    for (uint32_t y = 0; y < height; y++) {
        uint32_t *row = (uint32_t *)(void *)(xrgb + (size_t)y * pitch);
        if (y > 0 && !is_row) { /* column patterns: every row as the first */
            memcpy(row, xrgb, (size_t)width * 4u);
            continue;
        }
        for (uint32_t x = 0; x < width; x++)
            row[x] = gray_layout_lit(&d->layout, pattern, x, y) ? 0x00FFFFFFu : 0u;
    }
    return 0;
}

static int show(struct board_display *d)
{
    uint32_t pattern = d->enabled ? d->pattern : PROJECTOR_DRM_BLACK;
    return projector_drm_show(&d->drm, pattern, FLIP_TIMEOUT_MS);
}

static int display_set(void *priv, enum hal_gpio_line line, int value)
{
    struct board_display *d = priv;
    switch (line) {
    case HAL_GPIO_PROJECTOR_ENABLE:
        d->enabled = value != 0;
        return show(d);
    case HAL_GPIO_PROJECTOR_RESET:
        if (!value)
            return 0; /* the rising edge acts, as on a projector's trigger input */
        d->pattern = 0;
        return show(d);
    case HAL_GPIO_PROJECTOR_TRIGGER:
        if (!value)
            return 0;
        d->pattern = d->pattern + 1u < gray_layout_count(&d->layout) ? d->pattern + 1u : 0u;
        return show(d);
    default:
        return hal_gpio_set(&d->lights, line, value);
    }
}

static int display_get(void *priv, enum hal_gpio_line line, int *value)
{
    struct board_display *d = priv;
    if (line == HAL_GPIO_PROJECTOR_ENABLE) {
        *value = d->enabled;
        return 0;
    }
    return hal_gpio_get(&d->lights, line, value);
}

static int display_safe_state(void *priv)
{
    struct board_display *d = priv;
    int rc = d->lights.ops->safe_state(d->lights.priv);
    d->enabled = 0;
    int rc_show = show(d);
    return rc != 0 ? rc : rc_show;
}

static const struct hal_gpio_ops display_ops = {
    .set = display_set,
    .get = display_get,
    .safe_state = display_safe_state,
};

int board_display_open(struct board_display *d, const char *device, const struct scan_params *scan,
                       const struct scan_calib *calib, const struct hal_gpio *lights,
                       struct hal_gpio *out, char *err, size_t err_len)
{
    memset(d, 0, sizeof(*d));
    d->lights = *lights;
    scan_layout(scan, calib, &d->layout);
    int rc = projector_drm_open(&d->drm, device, calib->proj_width, calib->proj_height, render, d,
                                err, err_len);
    if (rc != 0)
        return rc;
    out->ops = &display_ops;
    out->priv = d;
    return 0;
}

void board_display_close(struct board_display *d)
{
    projector_drm_close(&d->drm);
}
