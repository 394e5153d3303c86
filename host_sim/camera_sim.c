/* Simulated camera: renders the rig in its current light state, with injectable faults. */

#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <string.h>
#include <time.h>

#include "sim_devices.h"

static int camera_sim_open(void *priv, const struct hal_camera_config *cfg)
{
    struct camera_sim *cam = priv;
    if (cfg->width != cam->rig->width || cfg->height != cam->rig->height)
        return -EINVAL; /* the simulated sensor has the calibrated size only */
    if (cfg->pixel_format != HAL_PIX_RGB24 || cfg->exposure_us == 0 || cfg->gain_milli == 0)
        return -EINVAL;
    cam->cfg = *cfg;
    cam->is_open = 1;
    cam->frames = 0;
    cam->has_shown = 0;
    return 0;
}

/* The noise of a frame depends on what it shows (table angle, projector pattern, lights,
 * exposure) and on how many frames in a row showed the same, not on how many came before: a
 * scan resumed after an interruption sees the frames an uninterrupted one would. A frame not
 * @p counted (one in flight, which the scan discards) is not one of that row: the noise of
 * those after it is what it would have been without it. */
static uint64_t noise_id(struct camera_sim *cam, const struct sim_sources *src, int counted)
{
    const uint64_t part[] = {(uint64_t)src->projector_on,
                             src->pattern_index,
                             src->lights_mask,
                             src->exposure_us,
                             src->gain_milli,
                             (uint32_t)cam->rig->table_angle_mdeg};
    uint64_t key = 1469598103934665603ull; /* FNV-1a over the parts */
    for (size_t k = 0; k < sizeof(part) / sizeof(part[0]); k++)
        key = (key ^ part[k]) * 1099511628211ull;
    uint32_t repeat = key == cam->last_key ? cam->repeat + 1 : 0;
    if (counted)
        cam->repeat = repeat, cam->last_key = key;
    return key + repeat;
}

/* A stale frame: one the camera exposed before the last light or pattern change (it had it
 * in flight), showing what the previous frame showed, stamped with when that began. */
static int stale(struct camera_sim *cam, struct sim_sources *src, uint64_t *start_us)
{
    if (!cam->has_shown)
        return 0; /* nothing was exposed before the first frame */
    *src = cam->shown;
    *start_us = cam->shown_start_us;
    cam->rig->table_angle_mdeg = cam->shown_angle_mdeg;
    return 1;
}

static double thread_cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

/* When the frame delivered for a capture asked for at @p now_us began, and when it arrives. A
 * streaming sensor starts a frame every period (1 / frame_rate_hz, longer when the exposure
 * is). As the V4L2 backend does, the capture gives back the frames already filled and lets
 * [camera] drop_frames go by, the first of them the frame being exposed when it was asked for
 * (it began before: during the light or pattern change the capture follows; one that begins
 * just then is not), then takes the next, which arrives after its period and the readout. So
 * with drop_frames = 1 a capture waits for the frame in flight and one period more; with 0 it
 * is handed the frame in flight, stamped with its start, which the scan discards as stale.
 * Without a frame rate, a frame takes its exposure from the request on. */
static void frame_times(const struct camera_sim *cam, uint64_t now_us, uint64_t *start_us,
                        uint64_t *arrive_us)
{
    if (cam->frame_rate_hz <= 0.0) {
        *start_us = now_us;
        *arrive_us = now_us + cam->cfg.exposure_us;
        return;
    }
    double period = fmax(1e6 / cam->frame_rate_hz, (double)cam->cfg.exposure_us);
    double next = ceil((double)now_us / period) * period; /* the first start at or after now */
    /* within a microsecond of now it begins now: the times are whole microseconds, so a
     * capture asked for as the frame before arrived (a retry) sees it so */
    double in_flight = next >= (double)now_us + 1.0 ? next - period : next;
    *start_us = (uint64_t)(in_flight + cam->cfg.drop_frames * period);
    *arrive_us = (uint64_t)(in_flight + (cam->cfg.drop_frames + 1u) * period) + cam->readout_us;
}

static int camera_sim_capture(void *priv, struct hal_image *img)
{
    struct camera_sim *cam = priv;
    if (!cam->is_open)
        return -EBADF;
    uint64_t frame = cam->frames++;
    int faulty = cam->fault != SIM_FAULT_NONE && frame >= cam->fault_first &&
                 frame < cam->fault_first + cam->fault_count;
    if (faulty && cam->fault != SIM_FAULT_STALE) {
        static const int code[] = {0, -ETIMEDOUT, -EIO, -ENODEV};
        return code[cam->fault];
    }
    size_t need = (size_t)cam->rig->width * cam->rig->height * 3;
    if (img->capacity < need)
        return -ENOSPC;
    if (cam->table_angle != NULL)
        cam->rig->table_angle_mdeg = cam->table_angle(cam->table_priv);
    struct sim_sources src;
    gpio_sim_sources(cam->gpio, cam->light_count, &src);
    src.exposure_us = cam->cfg.exposure_us;
    src.gain_milli = cam->cfg.gain_milli;
    uint64_t start_us, arrive_us, asked_us = clock_sim_now(cam->clock);
    frame_times(cam, asked_us, &start_us, &arrive_us);
    int in_flight = start_us < asked_us; /* exposed during the change: the old light on it */
    if (in_flight) {
        if (cam->has_shown) { /* its start stays its own: the scan tells it by that */
            src = cam->shown;
            cam->rig->table_angle_mdeg = cam->shown_angle_mdeg;
        }
    } else if (!(faulty && stale(cam, &src, &start_us))) {
        cam->shown = src;
        cam->shown_start_us = start_us;
        cam->shown_angle_mdeg = cam->rig->table_angle_mdeg;
        cam->has_shown = 1;
    }
    double t0 = thread_cpu_s();
    sim_rig_render(cam->rig, &src, noise_id(cam, &src, !in_flight), img->rgb);
    cam->render_cpu_s += thread_cpu_s() - t0;
    uint64_t now_us = clock_sim_now(cam->clock);
    if (arrive_us > now_us)
        atomic_fetch_add(&cam->clock->now_us, arrive_us - now_us);
    img->width = cam->rig->width;
    img->height = cam->rig->height;
    img->sequence = frame;
    img->start_us = start_us;
    return 0;
}

static int camera_sim_set_exposure(void *priv, uint32_t exposure_us, uint32_t gain_milli)
{
    struct camera_sim *cam = priv;
    if (exposure_us == 0 || gain_milli == 0)
        return -EINVAL;
    cam->cfg.exposure_us = exposure_us;
    cam->cfg.gain_milli = gain_milli;
    return 0;
}

static int camera_sim_close(void *priv)
{
    ((struct camera_sim *)priv)->is_open = 0;
    return 0;
}

static int camera_sim_safe_state(void *priv)
{
    (void)priv; /* a simulated sensor has nothing to stop */
    return 0;
}

static const struct hal_camera_ops camera_sim_ops = {
    .open = camera_sim_open,
    .set_exposure = camera_sim_set_exposure,
    .capture = camera_sim_capture,
    .close = camera_sim_close,
    .safe_state = camera_sim_safe_state,
};

void camera_sim_init(struct camera_sim *cam, struct sim_rig *rig, const struct gpio_sim *gpio,
                     struct clock_sim *clock, uint32_t light_count, struct hal_camera *out)
{
    memset(cam, 0, sizeof(*cam));
    cam->rig = rig;
    cam->gpio = gpio;
    cam->clock = clock;
    cam->light_count = light_count;
    out->ops = &camera_sim_ops;
    out->priv = cam;
}
