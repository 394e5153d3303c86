/* Turntable device interface: home, move to an angle, read position and status. */
#ifndef HAL_TURNTABLE_H
#define HAL_TURNTABLE_H

#include <stdint.h>

struct hal_turntable_status {
    int32_t position_mdeg; /**< current angle in millidegrees */
    int busy;              /**< a move or homing is under way */
    int homed;             /**< the reference position is known */
    uint16_t alarm_code;   /**< 0 when there is no alarm */
};

struct hal_turntable_ops {
    /** Find the reference position and wait until done. @retval 0 ok @retval -ETIMEDOUT @retval
     * -EIO */
    int (*home)(void *priv);
    /** Move to an absolute angle and wait until in position.
     *  @retval 0 ok @retval -ETIMEDOUT not idle in time @retval -EIO alarm or wrong position */
    int (*move_to)(void *priv, int32_t angle_mdeg);
    /** @retval 0 ok, *status filled @retval -ETIMEDOUT no reply @retval -EIO bad reply */
    int (*get_status)(void *priv, struct hal_turntable_status *status);
    /** Stop any motion. Required. */
    int (*safe_state)(void *priv);
    /** Optional: clear the controller's alarm (a stall, a move before homing), which blocks
     *  motion until cleared; only once the operator has fixed its cause. @retval 0 ok */
    int (*clear_alarm)(void *priv);
};

struct hal_turntable {
    const struct hal_turntable_ops *ops;
    void *priv;
};

/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_table_home(const struct hal_turntable *table);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_table_move_to(const struct hal_turntable *table, int32_t angle_mdeg);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_table_get_status(const struct hal_turntable *table, struct hal_turntable_status *status);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_table_clear_alarm(const struct hal_turntable *table);

#endif
