/* The appliance board: a V4L2 or libcamera camera, libgpiod lines, the Modbus turntable (RTU on
 * a serial port or TCP), POSIX clock and storage. No simulator is linked into this build. */
#define _POSIX_C_SOURCE 200809L
#include "board.h"
#include "board_display.h"

#include "camera_v4l2.h"
#include "clock_posix.h"
#include "gpio_gpiod.h"
#include "storage_posix.h"
#include "thread_posix.h"
#include "turntable_modbus.h"
#ifdef HAVE_LIBCAMERA
#include "camera_libcamera.h"
#endif

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static struct {
    struct camera_v4l2 v4l2;
#ifdef HAVE_LIBCAMERA
    struct camera_libcamera libcamera;
#endif
    struct gpio_gpiod gpio;
    struct board_display display; /* [projector] backend = drm */
    int display_open;
    struct tt_client turntable;
    const char *camera_error; /* the backend's last message */
} board;

const char *board_name(void)
{
    return "linux";
}

/* The camera backend's ops (not opened yet: scan_open does that). */
static int camera_init(struct hal *hal, const struct board_config *cfg, char *err, size_t err_len)
{
    if (strcmp(cfg->camera_backend, "v4l2") == 0) {
        camera_v4l2_init(&board.v4l2, hal->log, &hal->camera);
        board.camera_error = board.v4l2.error;
        return 0;
    }
#ifdef HAVE_LIBCAMERA
    if (strcmp(cfg->camera_backend, "libcamera") == 0) {
        int rc = camera_libcamera_init(&board.libcamera, hal->log, &hal->camera);
        if (rc != 0)
            snprintf(err, err_len, "camera: libcamera: %s", strerror(-rc));
        board.camera_error = board.libcamera.error;
        return rc;
    }
#endif
    if (strcmp(cfg->camera_backend, "sim") == 0)
        snprintf(err, err_len,
                 "%s: [camera] backend = sim is not built in: this scanner was built with "
                 "HAL=linux and drives real hardware only",
                 cfg->config_path);
    else
        snprintf(err, err_len,
                 "%s: [camera] backend = %s: this scanner was built without it (libcamera "
                 "was not found at build time; install libcamera-dev and rebuild)",
                 cfg->config_path, cfg->camera_backend);
    return -ENODEV;
}

static void camera_free(void)
{
#ifdef HAVE_LIBCAMERA
    camera_libcamera_free(&board.libcamera);
#endif
}

int board_init(struct hal *hal, const struct board_config *cfg, const struct scan_calib *calib,
               char *err, size_t err_len)
{
    clock_posix_init(&hal->clock);
    storage_posix_init(&hal->storage);
    thread_posix_init(&hal->thread, 0); /* [scan] threads limits it */
    /* Camera first: a camera that fails leaves no GPIO line requested. */
    int rc = camera_init(hal, cfg, err, err_len);
    if (rc != 0)
        goto out_camera;
    rc = gpio_gpiod_open(&board.gpio, cfg->gpio->chip, cfg->gpio->line, &hal->gpio, err, err_len);
    if (rc != 0)
        goto out_camera;
    if (cfg->projector_backend != NULL && strcmp(cfg->projector_backend, "drm") == 0) {
        struct hal_gpio lights = hal->gpio;
        rc = board_display_open(&board.display, cfg->projector_device, cfg->scan, calib, &lights,
                                &hal->gpio, err, err_len);
        if (rc != 0)
            goto out_gpio;
        board.display_open = 1;
    }
    rc = tt_client_open(&board.turntable, cfg->turntable, &hal->clock, hal->log, &hal->turntable,
                        err, err_len);
    if (rc != 0)
        goto out_display;
    return 0;
out_display:
    if (board.display_open)
        board_display_close(&board.display);
    board.display_open = 0;
out_gpio:
    gpio_gpiod_close(&board.gpio);
out_camera:
    camera_free();
    hal->camera.ops = NULL;
    hal->gpio.ops = NULL;
    hal->turntable.ops = NULL;
    return rc;
}

int board_write_scan_extras(const struct hal *hal, const char *scan_dir)
{
    (void)hal;
    (void)scan_dir;
    return 0; /* real hardware has no ground truth to write */
}

double board_simulator_cpu_s(void)
{
    return 0.0; /* a real rig: no simulator in this process */
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
    tt_client_close(&board.turntable);
    if (board.display_open)
        board_display_close(&board.display);
    board.display_open = 0;
    gpio_gpiod_close(&board.gpio);
    camera_free();
}

/* ---- selftest: each device on its own, released before the next ---- */

static int probe_camera(struct hal *hal, const struct board_config *cfg, char *detail, size_t len)
{
    int rc = camera_init(hal, cfg, detail, len);
    if (rc != 0)
        return rc;
    uint32_t w, h;
    rc = board_grab_frame(hal, cfg->camera, &w, &h);
    if (rc == 0)
        snprintf(detail, len, "%s frame %ux%u", cfg->camera_backend, (unsigned)w, (unsigned)h);
    else if (rc != -ENOMEM)
        snprintf(detail, len, "%s", board.camera_error);
    camera_free();
    hal->camera.ops = NULL;
    return rc;
}

static int probe_gpio(struct hal *hal, const struct board_config *cfg, char *detail, size_t len)
{
    int rc =
        gpio_gpiod_open(&board.gpio, cfg->gpio->chip, cfg->gpio->line, &hal->gpio, detail, len);
    if (rc != 0)
        return rc;
    unsigned wired = 0;
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++)
        wired += board.gpio.line[i] != NULL;
    snprintf(detail, len, "%u lines requested and driven low", wired);
    gpio_gpiod_close(&board.gpio);
    hal->gpio.ops = NULL;
    return 0;
}

static int probe_turntable(struct hal *hal, const struct board_config *cfg, char *detail,
                           size_t len)
{
    struct hal_turntable_status st;
    int rc = tt_client_open(&board.turntable, cfg->turntable, &hal->clock, hal->log,
                            &hal->turntable, detail, len);
    if (rc != 0)
        return rc;
    rc = hal_table_get_status(&hal->turntable, &st);
    if (rc == 0)
        snprintf(detail, len, "answers: at %.3f deg, %s, %s, alarm %u", st.position_mdeg / 1000.0,
                 st.homed ? "homed" : "not homed", st.busy ? "busy" : "idle",
                 (unsigned)st.alarm_code);
    else
        snprintf(detail, len, "connected but status read failed: %s", strerror(-rc));
    tt_client_close(&board.turntable);
    hal->turntable.ops = NULL;
    return rc;
}

int board_selftest(struct hal *hal, const struct board_config *cfg, const struct scan_calib *calib,
                   board_selftest_row row, void *ctx)
{
    char detail[512], where[HAL_MAX_PATH];
    int failed = 0, rc;
    (void)calib;
    clock_posix_init(&hal->clock);
    storage_posix_init(&hal->storage);

    detail[0] = '\0';
    rc = probe_camera(hal, cfg, detail, sizeof(detail));
    row(ctx, "camera", cfg->camera->device, rc, detail);
    failed |= rc != 0;

    rc = probe_gpio(hal, cfg, detail, sizeof(detail));
    row(ctx, "gpio", cfg->gpio->chip, rc, detail);
    failed |= rc != 0;

    if (strcmp(cfg->turntable->transport, "tcp") == 0)
        snprintf(where, sizeof(where), "%s:%u", cfg->turntable->host,
                 (unsigned)cfg->turntable->port);
    else
        snprintf(where, sizeof(where), "%s", cfg->turntable->device);
    rc = probe_turntable(hal, cfg, detail, sizeof(detail));
    row(ctx, "turntable", where, rc, detail);
    failed |= rc != 0;
    return failed ? -ENODEV : 0;
}

int board_place_target(struct hal *hal, const struct board_target *t, char *err, size_t len)
{
    (void)hal;
    (void)t;
    (void)err;
    (void)len;
    return -ENOSYS; /* a person places it: the calibration asks them */
}
