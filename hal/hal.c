/* Thin public wrappers over each device's ops: a missing optional op answers -ENOSYS. */
#include "hal.h"

#include <errno.h>

/* Call dev->ops->op(args) or answer -ENOSYS when the device or the op is absent. */
#define HAL_CALL(dev, op, ...)                                                                     \
    (((dev) == NULL || (dev)->ops == NULL || (dev)->ops->op == NULL)                               \
         ? -ENOSYS                                                                                 \
         : (dev)->ops->op((dev)->priv, __VA_ARGS__))
#define HAL_CALL0(dev, op)                                                                         \
    (((dev) == NULL || (dev)->ops == NULL || (dev)->ops->op == NULL)                               \
         ? -ENOSYS                                                                                 \
         : (dev)->ops->op((dev)->priv))

int hal_cam_open(const struct hal_camera *cam, const struct hal_camera_config *cfg)
{
    return HAL_CALL(cam, open, cfg);
}

int hal_cam_capture(const struct hal_camera *cam, struct hal_image *img)
{
    return HAL_CALL(cam, capture, img);
}

int hal_cam_set_exposure(const struct hal_camera *cam, uint32_t exposure_us, uint32_t gain_milli)
{
    return HAL_CALL(cam, set_exposure, exposure_us, gain_milli);
}

int hal_cam_close(const struct hal_camera *cam)
{
    return HAL_CALL0(cam, close);
}

int hal_gpio_set(const struct hal_gpio *gpio, enum hal_gpio_line line, int value)
{
    return HAL_CALL(gpio, set, line, value);
}

int hal_gpio_get(const struct hal_gpio *gpio, enum hal_gpio_line line, int *value)
{
    return HAL_CALL(gpio, get, line, value);
}

int hal_gpio_pulse(const struct hal_gpio *gpio, const struct hal_clock *clock,
                   enum hal_gpio_line line, uint32_t width_us)
{
    int rc = hal_gpio_set(gpio, line, 1);
    if (rc == 0)
        rc = hal_clock_sleep_us(clock, width_us);
    /* The line goes low again even when the sleep was interrupted. */
    int rc_low = hal_gpio_set(gpio, line, 0);
    return rc != 0 ? rc : rc_low;
}

int hal_clock_now_us(const struct hal_clock *clock, uint64_t *now_us)
{
    return HAL_CALL(clock, now_us, now_us);
}

int hal_clock_sleep_us(const struct hal_clock *clock, uint64_t duration_us)
{
    return HAL_CALL(clock, sleep_us, duration_us);
}

int hal_table_home(const struct hal_turntable *table)
{
    return HAL_CALL0(table, home);
}

int hal_table_move_to(const struct hal_turntable *table, int32_t angle_mdeg)
{
    return HAL_CALL(table, move_to, angle_mdeg);
}

int hal_table_get_status(const struct hal_turntable *table, struct hal_turntable_status *status)
{
    return HAL_CALL(table, get_status, status);
}

int hal_table_clear_alarm(const struct hal_turntable *table)
{
    return HAL_CALL0(table, clear_alarm);
}

int hal_storage_mkdir_p(const struct hal_storage *st, const char *path)
{
    return HAL_CALL(st, mkdir_p, path);
}

int hal_storage_open(const struct hal_storage *st, struct hal_file *file, const char *path)
{
    return HAL_CALL(st, open_atomic, file, path);
}

int hal_storage_write(const struct hal_storage *st, struct hal_file *file, const void *data,
                      size_t len)
{
    return HAL_CALL(st, write, file, data, len);
}

int hal_storage_commit(const struct hal_storage *st, struct hal_file *file)
{
    return HAL_CALL(st, commit, file);
}

int hal_storage_sweep(const struct hal_storage *st, const char *dir)
{
    return HAL_CALL(st, sweep, dir);
}

void hal_storage_abort(const struct hal_storage *st, struct hal_file *file)
{
    if (st != NULL && st->ops != NULL && st->ops->abort != NULL)
        st->ops->abort(st->priv, file);
}

int hal_storage_write_file(const struct hal_storage *st, const char *path, const void *data,
                           size_t len)
{
    struct hal_file file;
    int rc = hal_storage_open(st, &file, path);
    if (rc != 0)
        return rc;
    rc = hal_storage_write(st, &file, data, len);
    if (rc != 0)
        goto out_abort;
    rc = hal_storage_commit(st, &file);
    if (rc != 0)
        goto out_abort;
    return 0;
out_abort:
    hal_storage_abort(st, &file);
    return rc;
}

/* Run one device's safe_state, keeping the first error but never skipping the next device. */
#define HAL_SAFE(dev, first_rc)                                                                    \
    do {                                                                                           \
        if ((dev).ops != NULL) {                                                                   \
            int rc_ = (dev).ops->safe_state != NULL ? (dev).ops->safe_state((dev).priv) : -ENOSYS; \
            if (rc_ != 0 && (first_rc) == 0)                                                       \
                (first_rc) = rc_;                                                                  \
        }                                                                                          \
    } while (0)

int hal_safe_state(const struct hal *hal)
{
    int first_rc = 0;
    /* Light and projector first: they are what a person at the rig would be dazzled by. */
    HAL_SAFE(hal->gpio, first_rc);
    HAL_SAFE(hal->turntable, first_rc);
    HAL_SAFE(hal->camera, first_rc);
    HAL_SAFE(hal->clock, first_rc);
    HAL_SAFE(hal->storage, first_rc);
    return first_rc;
}

int hal_should_stop(const struct hal *hal)
{
    return hal->stop_requested != NULL && hal->stop_requested();
}

/* Threads @p t may use: one when it is NULL or has no ops. */
static unsigned hal_thread_count(const struct hal_thread *t)
{
    if (t == NULL || t->ops == NULL || t->threads <= 1)
        return 1;
    return t->threads < HAL_MAX_THREADS ? t->threads : HAL_MAX_THREADS;
}

unsigned hal_thread_parts(const struct hal_thread *t, unsigned most)
{
    unsigned threads = hal_thread_count(t);
    if (threads <= 1)
        return 1;
    return HAL_PARTS_PER_THREAD * threads < most ? HAL_PARTS_PER_THREAD * threads : most;
}

void hal_thread_run(const struct hal_thread *t, unsigned count, hal_thread_fn fn, void *arg)
{
    unsigned threads = hal_thread_count(t);
    if (threads > 1 && count > 1) {
        t->ops->run(t->priv, threads, count, fn, arg);
        return;
    }
    for (unsigned k = 0; k < count; k++)
        fn(arg, k);
}
