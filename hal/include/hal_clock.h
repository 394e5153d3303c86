/* Clock device interface: monotonic time and sleeping; the simulator's clock is virtual. */
#ifndef HAL_CLOCK_H
#define HAL_CLOCK_H

#include <stdint.h>

struct hal_clock_ops {
    /** Monotonic time. @retval 0 ok, *now_us set */
    int (*now_us)(void *priv, uint64_t *now_us);
    /** Sleep at least @p duration_us. @retval 0 ok @retval -EINTR interrupted by a stop request */
    int (*sleep_us)(void *priv, uint64_t duration_us);
    /** Nothing to make safe for a clock; present so that every device has the op. */
    int (*safe_state)(void *priv);
};

struct hal_clock {
    const struct hal_clock_ops *ops;
    void *priv;
};

/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_clock_now_us(const struct hal_clock *clock, uint64_t *now_us);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_clock_sleep_us(const struct hal_clock *clock, uint64_t duration_us);

#endif
