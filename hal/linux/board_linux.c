/* The appliance board: libgpiod GPIO, POSIX clock and storage. Camera backends (V4L2, libcamera)
 * and the Modbus turntable arrive with their own issues; until then a config naming them gets a
 * clear error here, and no simulator is linked into this build. */
#define _POSIX_C_SOURCE 200809L
#include "board.h"

#include "clock_posix.h"
#include "gpio_gpiod.h"
#include "storage_posix.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

static struct gpio_gpiod gpio;

const char *board_name(void)
{
    return "linux";
}

/* V4L2 and libcamera backends come with the appliance issue; until then say so plainly. */
static int camera_init(struct hal_camera *cam, const struct app_config *cfg, char *err,
                       size_t err_len)
{
    cam->ops = NULL;
    cam->priv = NULL;
    snprintf(err, err_len, "%s: [camera] backend = %s: this build has no %s driver yet", cfg->path,
             cfg->camera_backend, cfg->camera_backend);
    return -ENOSYS;
}

int board_init(struct hal *hal, const struct app_config *cfg, const struct scan_calib *calib,
               char *err, size_t err_len)
{
    (void)calib;
    if (strcmp(cfg->camera_backend, "sim") == 0) {
        snprintf(err, err_len,
                 "%s: [camera] backend = sim is not built in: this scanner was built "
                 "with HAL=linux and drives real hardware only",
                 cfg->path);
        return -ENODEV;
    }
    /* Camera first: a camera that fails leaves no GPIO line requested. */
    int rc = camera_init(&hal->camera, cfg, err, err_len);
    if (rc != 0)
        return rc;
    rc = gpio_gpiod_open(&gpio, cfg->gpio.chip, cfg->gpio.line_offset, &hal->gpio, err, err_len);
    if (rc != 0)
        return rc;
    clock_posix_init(&hal->clock);
    storage_posix_init(&hal->storage);
    hal->turntable.ops = NULL;
    return 0;
}

int board_write_scan_extras(const struct hal *hal, const char *scan_dir)
{
    (void)hal;
    (void)scan_dir;
    return 0; /* real hardware has no ground truth to write */
}

int board_write_view_extras(const struct hal *hal, const char *view_dir)
{
    (void)hal;
    (void)view_dir;
    return 0; /* real hardware has no ground truth to write */
}

void board_shutdown(struct hal *hal)
{
    hal_safe_state(hal);
    gpio_gpiod_close(&gpio);
}
