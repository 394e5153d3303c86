/* The HDMI projector on a real KMS device: run in the arm64 VM of tests/gpio_chip.sh against
 * virtio-gpu. Drives the board's projector lines as a scan does (enable, a reset pulse, trigger
 * pulses) and says when each pattern is on screen, then waits, so that the host can take qemu's
 * screendump of what the display shows. Usage: drm-show /dev/dri/cardN */
#define _POSIX_C_SOURCE 200809L
#include "board_display.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* The lights: lines nobody has here. */
static int lights_set(void *priv, enum hal_gpio_line line, int value)
{
    (void)priv;
    (void)line;
    (void)value;
    return 0;
}

static int lights_safe(void *priv)
{
    (void)priv;
    return 0;
}

static const struct hal_gpio_ops lights_ops = {.set = lights_set, .safe_state = lights_safe};

static void hold(const char *what, uint32_t pattern, const struct board_display *d)
{
    printf("shown %s %u at %llu us\n", what, (unsigned)pattern, (unsigned long long)d->drm.flip_us);
    fflush(stdout);
    struct timespec ts = {2, 0}; /* the host's screendump */
    nanosleep(&ts, NULL);
}

int main(int argc, char **argv)
{
    const char *device = argc > 1 ? argv[1] : "/dev/dri/card0";
    struct scan_params scan;
    struct scan_calib calib;
    memset(&scan, 0, sizeof(scan));
    memset(&calib, 0, sizeof(calib));
    calib.proj_width = 1024;
    calib.proj_height = 768;
    static struct board_display d;
    struct hal_gpio lights = {&lights_ops, NULL}, gpio;
    char err[512];
    int rc = board_display_open(&d, device, &scan, &calib, &lights, &gpio, err, sizeof(err));
    printf("open %ux%u: %s\n", (unsigned)calib.proj_width, (unsigned)calib.proj_height,
           rc == 0 ? "ok" : err);
    if (rc != 0)
        return 1;
    /* as a scan: on, reset to pattern 0, then a trigger pulse per pattern */
    rc = hal_gpio_set(&gpio, HAL_GPIO_PROJECTOR_ENABLE, 1);
    if (rc == 0)
        rc = hal_gpio_set(&gpio, HAL_GPIO_PROJECTOR_RESET, 1);
    if (rc == 0)
        rc = hal_gpio_set(&gpio, HAL_GPIO_PROJECTOR_RESET, 0);
    uint32_t count = gray_layout_count(&d.layout), shots[] = {0, 1, 2, 3, 12, 21};
    uint32_t next = 0;
    for (uint32_t p = 0; p < count && rc == 0; p++) {
        if (p > 0) {
            rc = hal_gpio_set(&gpio, HAL_GPIO_PROJECTOR_TRIGGER, 1);
            if (rc == 0)
                rc = hal_gpio_set(&gpio, HAL_GPIO_PROJECTOR_TRIGGER, 0);
        }
        if (rc == 0 && next < sizeof(shots) / sizeof(shots[0]) && shots[next] == p) {
            hold("pattern", p, &d);
            next++;
        }
    }
    if (rc == 0)
        rc = hal_gpio_set(&gpio, HAL_GPIO_PROJECTOR_ENABLE, 0);
    if (rc == 0)
        hold("off", 0, &d);
    printf("sequence: %s (%u patterns)\n", rc == 0 ? "ok" : d.drm.error, (unsigned)count);
    board_display_close(&d);
    printf("done\n");
    return rc == 0 ? 0 : 1;
}
