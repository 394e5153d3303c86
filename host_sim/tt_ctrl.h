/* Simulated stepper turntable controller: the state machine behind the Modbus register map.
 * Pure: time is passed in, so it runs on virtual time in process and real time standalone. */
#ifndef TT_CTRL_H
#define TT_CTRL_H

#include "tt_regs.h"

#include <stdint.h>

struct tt_ctrl {
    uint16_t regs[TT_REG_COUNT];
    int homed;
    int homing;
    uint16_t alarm;
    uint16_t last_id;
    /* current motion: a trapezoidal profile from start to target */
    int moving;
    double start_mdeg, target_mdeg, pos_mdeg;
    uint64_t start_us;
    double speed_mdeg_s, accel_mdeg_s2, duration_s;
    /* fault injection (tests): the table blocks at this position (INT32_MIN: never) */
    int32_t stall_at_mdeg;
    /* An open-loop stepper reports where it was told to go; the table itself ends up to this far
     * off after each move (backlash, missed microsteps), deterministically per move. */
    int32_t angle_error_mdeg;
    uint32_t moves;
    double physical_offset_mdeg;
    /* fault injection (tests): a controller that acts on a command only this long after it
     * came, reporting idle and the previous LAST_ID meanwhile (0: at once) */
    uint32_t command_delay_us;
    int pending; /* a command received, not yet executed */
    uint16_t pending_cmd, pending_id;
    uint64_t pending_due_us;
};

/** Power-on state: not homed, at a random-ish position @p power_on_mdeg, idle. */
void tt_ctrl_init(struct tt_ctrl *c, int32_t power_on_mdeg, uint64_t now_us);
/** Advance the motion to @p now_us and refresh the read-only registers. */
void tt_ctrl_update(struct tt_ctrl *c, uint64_t now_us);
/** A write of @p count registers from @p addr has been stored in regs[]; act on it.
 *  @retval 0 ok, or a Modbus exception code (2: illegal data address) */
int tt_ctrl_check_write(const struct tt_ctrl *c, int addr, int count);
void tt_ctrl_after_write(struct tt_ctrl *c, uint64_t now_us);
/** Current position in millidegrees, as the controller reports it. */
int32_t tt_ctrl_position(const struct tt_ctrl *c);
/** Where the table really is (reported position plus the mechanical error). */
double tt_ctrl_physical_mdeg(const struct tt_ctrl *c);

#endif
