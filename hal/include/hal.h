/* The whole hardware abstraction: one struct of devices handed to the firmware. */
#ifndef HAL_H
#define HAL_H

#include "hal_camera.h"
#include "hal_clock.h"
#include "hal_gpio.h"
#include "hal_limits.h"
#include "hal_storage.h"
#include "hal_thread.h"
#include "hal_turntable.h"

enum hal_log_level { HAL_LOG_ERROR = 0, HAL_LOG_WARN, HAL_LOG_INFO, HAL_LOG_DEBUG };

/** Every device of the rig. A device whose ops pointer is NULL is absent. */
struct hal {
    struct hal_camera camera;
    struct hal_gpio gpio;
    struct hal_turntable turntable;
    struct hal_clock clock;
    struct hal_storage storage;
    struct hal_thread thread; /**< the cores beside the rig's thread (optional: one thread) */
    /** printf-style logger (required). */
    void (*log)(enum hal_log_level level, const char *fmt, ...)
        __attribute__((format(printf, 2, 3)));
    /** Non-zero once SIGINT/SIGTERM (or a test) asked the scan to stop (optional). */
    int (*stop_requested)(void);
};

/** Drive every device to its safe state: lights and projector off, table stopped, camera idle.
 *  Runs every device's op even when one fails. @retval 0 or the first error */
int hal_safe_state(const struct hal *hal);

/** @retval non-zero when a stop was requested */
int hal_should_stop(const struct hal *hal);

#endif
