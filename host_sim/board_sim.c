/* The simulator board: every HAL device backed by the simulated rig, plus its ground truth. */
#define _POSIX_C_SOURCE 200809L
#include "board.h"

#include "gray.h"
#include "image_io.h"
#include "sim_devices.h"
#include "storage_posix.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static struct {
    struct sim_rig rig;
    struct gpio_sim gpio;
    struct clock_sim clock;
    struct camera_sim camera;
    int ready;
} sim;

const char *board_name(void)
{
    return "sim";
}

int board_init(struct hal *hal, const struct app_config *cfg, const struct scan_calib *calib,
               char *err, size_t err_len)
{
    if (strcmp(cfg->camera_backend, "sim") != 0) {
        snprintf(err, err_len,
                 "%s: [camera] backend = %s is not built in: this scanner was built with HAL=sim "
                 "(rebuild with 'make HAL=linux' for real hardware)",
                 cfg->path, cfg->camera_backend);
        return -ENODEV;
    }
    char dir_buf[HAL_MAX_PATH];
    snprintf(dir_buf, sizeof(dir_buf), "%s", cfg->path);
    int rc = sim_rig_init(&sim.rig, &cfg->sim, calib, dirname(dir_buf), err, err_len);
    if (rc != 0)
        return rc;
    gpio_sim_init(&sim.gpio, gray_pattern_count(gray_bits_for_width(calib->proj_width)),
                  &hal->gpio);
    clock_sim_init(&sim.clock, &hal->clock);
    camera_sim_init(&sim.camera, &sim.rig, &sim.gpio, calib->light_count, &hal->camera);
    storage_posix_init(&hal->storage);
    hal->turntable.ops = NULL; /* the multi-view issue brings the Modbus turntable */
    hal->turntable.priv = NULL;
    sim.ready = 1;
    return 0;
}

static int write_truth(const struct hal *hal, const char *dir)
{
    struct sim_rig *rig = &sim.rig;
    const struct sim_truth *t = &rig->truth;
    size_t n = (size_t)rig->width * rig->height;
    char path[HAL_MAX_PATH + 64];
    int rc = -ENOMEM;
    float *depth = malloc(n * sizeof(float));
    uint8_t *img8 = malloc(n * 3);
    if (depth == NULL || img8 == NULL)
        goto out_free;
    sim_rig_update(rig);
    for (size_t i = 0; i < n; i++) {
        depth[i] = t->hit[i] ? t->pos_cam[3 * i + 2] : NAN;
        for (int k = 0; k < 3; k++)
            img8[3 * i + (size_t)k] = (uint8_t)lround(255.0 * t->albedo[3 * i + (size_t)k]);
    }
    snprintf(path, sizeof(path), "%s/truth_depth_mm.pfm", dir);
    rc = image_write_pfm(&hal->storage, path, depth, rig->width, rig->height, 1);
    if (rc != 0)
        goto out_free;
    snprintf(path, sizeof(path), "%s/truth_normal_cam.pfm", dir);
    rc = image_write_pfm(&hal->storage, path, t->normal_cam, rig->width, rig->height, 3);
    if (rc != 0)
        goto out_free;
    snprintf(path, sizeof(path), "%s/truth_albedo.png", dir);
    rc = image_write_png(&hal->storage, path, img8, rig->width, rig->height, 3);
    if (rc != 0)
        goto out_free;
    for (size_t i = 0; i < n; i++)
        img8[i] = (uint8_t)(t->proj_lit[i] ? 255 : 0);
    snprintf(path, sizeof(path), "%s/truth_projector_lit.png", dir);
    rc = image_write_png(&hal->storage, path, img8, rig->width, rig->height, 1);
out_free:
    free(depth);
    free(img8);
    return rc;
}

int board_write_view_extras(const struct hal *hal, const char *view_dir)
{
    return write_truth(hal, view_dir);
}

void board_shutdown(struct hal *hal)
{
    hal_safe_state(hal);
    if (sim.ready)
        sim_rig_free(&sim.rig);
    sim.ready = 0;
}

/* ---- test-side control (sim_ctl.h) ---- */

int sim_ctl_line(enum hal_gpio_line line)
{
    return (unsigned)line < HAL_GPIO_LINE_COUNT ? sim.gpio.line[line] : -1;
}

uint32_t sim_ctl_pattern_index(void)
{
    return sim.gpio.pattern_index;
}

void sim_ctl_inject_camera_fault(enum sim_cam_fault kind, uint64_t first_frame, uint32_t count)
{
    sim.camera.fault = kind;
    sim.camera.fault_first = first_frame;
    sim.camera.fault_count = count;
}

uint64_t sim_ctl_frames(void)
{
    return sim.camera.frames;
}

uint64_t sim_ctl_time_us(void)
{
    return sim.clock.now_us;
}

void sim_ctl_advance_us(uint64_t us)
{
    sim.clock.now_us += us;
}

struct sim_rig *sim_ctl_rig(void)
{
    return &sim.rig;
}
