/* The simulated controller: trapezoidal moves, homing, alarms, commands applied once per id. */
#include "tt_ctrl.h"

#include <math.h>
#include <string.h>

static void put32(uint16_t *regs, int hi, int32_t v)
{
    regs[hi] = (uint16_t)((uint32_t)v >> 16);
    regs[hi + 1] = (uint16_t)((uint32_t)v & 0xFFFFu);
}

static int32_t get32(const uint16_t *regs, int hi)
{
    return (int32_t)(((uint32_t)regs[hi] << 16) | regs[hi + 1]);
}

void tt_ctrl_init(struct tt_ctrl *c, int32_t power_on_mdeg, uint64_t now_us)
{
    memset(c, 0, sizeof(*c));
    c->pos_mdeg = power_on_mdeg;
    c->stall_at_mdeg = INT32_MIN;
    c->regs[TT_REG_SPEED] = 300;
    c->regs[TT_REG_ACCEL] = 600;
    c->regs[TT_REG_DEVICE_ID] = TT_DEVICE_ID;
    put32(c->regs, TT_REG_TARGET_HI, power_on_mdeg);
    tt_ctrl_update(c, now_us);
}

/* Distance covered after t seconds of a trapezoidal profile over distance d. */
static double profile(double d, double v, double a, double t)
{
    double t_acc = v / a, d_acc = 0.5 * v * t_acc;
    if (2.0 * d_acc > d) { /* triangular: never reaches full speed */
        double t_half = sqrt(d / a);
        if (t <= t_half)
            return 0.5 * a * t * t;
        double td = fmin(t - t_half, t_half);
        return 0.5 * d + a * t_half * td - 0.5 * a * td * td;
    }
    double t_cruise = (d - 2.0 * d_acc) / v;
    if (t <= t_acc)
        return 0.5 * a * t * t;
    if (t <= t_acc + t_cruise)
        return d_acc + v * (t - t_acc);
    double td = fmin(t - t_acc - t_cruise, t_acc);
    return d - d_acc + v * td - 0.5 * a * td * td;
}

static void start_move(struct tt_ctrl *c, double target, uint64_t now_us)
{
    double v = c->regs[TT_REG_SPEED] * 100.0, a = c->regs[TT_REG_ACCEL] * 100.0; /* mdeg */
    if (v <= 0.0 || a <= 0.0) {
        c->alarm = TT_ALARM_BAD_COMMAND;
        return;
    }
    double d = fabs(target - c->pos_mdeg);
    c->start_mdeg = c->pos_mdeg;
    c->target_mdeg = target;
    c->start_us = now_us;
    c->speed_mdeg_s = v;
    c->accel_mdeg_s2 = a;
    c->duration_s = 2.0 * (v / a) * 0.5 * v > d ? 2.0 * sqrt(d / a) : d / v + v / a;
    c->moving = 1;
}

static void execute(struct tt_ctrl *c, uint16_t cmd, uint64_t now_us);

void tt_ctrl_update(struct tt_ctrl *c, uint64_t now_us)
{
    if (c->pending && now_us >= c->pending_due_us) { /* a slow controller gets round to it */
        c->pending = 0;
        c->last_id = c->pending_id;
        execute(c, c->pending_cmd, c->pending_due_us);
    }
    if (c->moving) {
        double t = (double)(now_us - c->start_us) / 1e6;
        double d = fabs(c->target_mdeg - c->start_mdeg);
        double dir = c->target_mdeg >= c->start_mdeg ? 1.0 : -1.0;
        double next = t >= c->duration_s
                          ? c->target_mdeg
                          : c->start_mdeg + dir * profile(d, c->speed_mdeg_s, c->accel_mdeg_s2, t);
        double stall = c->stall_at_mdeg;
        if (c->stall_at_mdeg != INT32_MIN && ((c->pos_mdeg - stall) * (next - stall) <= 0.0) &&
            next != c->pos_mdeg) {
            next = stall; /* blocked: the following error trips the drive */
            c->moving = 0;
            c->alarm = TT_ALARM_STALL;
        }
        c->pos_mdeg = next;
        if (t >= c->duration_s)
            c->moving = 0;
        if (!c->moving && c->homing) {
            c->homing = 0;
            c->homed = c->alarm == TT_ALARM_NONE;
        }
    }
    uint16_t status = 0;
    int32_t pos = tt_ctrl_position(c);
    if (c->moving)
        status |= TT_STATUS_BUSY;
    if (!c->moving && pos == get32(c->regs, TT_REG_TARGET_HI))
        status |= TT_STATUS_IN_POSITION;
    if (c->homed)
        status |= TT_STATUS_HOMED;
    if (c->alarm != TT_ALARM_NONE)
        status |= TT_STATUS_ALARM;
    put32(c->regs, TT_REG_ACTUAL_HI, pos);
    c->regs[TT_REG_STATUS] = status;
    c->regs[TT_REG_ALARM] = c->alarm;
    c->regs[TT_REG_LAST_ID] = c->last_id;
}

int tt_ctrl_check_write(const struct tt_ctrl *c, int addr, int count)
{
    (void)c;
    for (int a = addr; a < addr + count; a++)
        if (!tt_reg_writable(a))
            return 2; /* MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS */
    return 0;
}

static void execute(struct tt_ctrl *c, uint16_t cmd, uint64_t now_us)
{
    switch (cmd) {
    case TT_CMD_MOVE:
        if (c->alarm != TT_ALARM_NONE)
            break; /* an alarm blocks motion until cleared */
        if (!c->homed) {
            c->alarm = TT_ALARM_NOT_HOMED;
            break;
        }
        start_move(c, get32(c->regs, TT_REG_TARGET_HI), now_us);
        if (c->angle_error_mdeg != 0) { /* a fixed pseudo-random error per move, in +-max */
            uint32_t h = (++c->moves) * 2654435761u;
            h ^= h >> 15;
            c->physical_offset_mdeg = ((double)(h % 2001u) / 1000.0 - 1.0) * c->angle_error_mdeg;
        }
        break;
    case TT_CMD_HOME:
        if (c->alarm != TT_ALARM_NONE)
            break;
        /* The reference switch sits at the power-on zero: travel there, then call it 0. */
        start_move(c, 0.0, now_us);
        c->physical_offset_mdeg = 0.0; /* the reference switch is exact */
        put32(c->regs, TT_REG_TARGET_HI, 0);
        c->homing = c->moving;
        c->homed = !c->moving; /* already at the reference */
        break;
    case TT_CMD_STOP:
        if (c->moving) { /* stop where it is now (a real drive decelerates; close enough) */
            c->moving = 0;
            c->homing = 0;
            put32(c->regs, TT_REG_TARGET_HI, tt_ctrl_position(c));
        }
        break;
    case TT_CMD_CLEAR_ALARM:
        c->alarm = TT_ALARM_NONE;
        break;
    default:
        c->alarm = TT_ALARM_BAD_COMMAND;
        break;
    }
}

void tt_ctrl_after_write(struct tt_ctrl *c, uint64_t now_us)
{
    tt_ctrl_update(c, now_us);
    uint16_t id = c->regs[TT_REG_COMMAND_ID];
    if (c->command_delay_us != 0 && id != c->last_id && !(c->pending && id == c->pending_id)) {
        c->pending = 1; /* acted on later, in tt_ctrl_update */
        c->pending_cmd = c->regs[TT_REG_COMMAND];
        c->pending_id = id;
        c->pending_due_us = now_us + c->command_delay_us;
    } else if (c->command_delay_us == 0 && id != c->last_id) {
        /* a new command; the same id again is a repeat and does nothing */
        c->last_id = id;
        execute(c, c->regs[TT_REG_COMMAND], now_us);
    }
    tt_ctrl_update(c, now_us);
}

int32_t tt_ctrl_position(const struct tt_ctrl *c)
{
    return (int32_t)lround(c->pos_mdeg);
}

double tt_ctrl_physical_mdeg(const struct tt_ctrl *c)
{
    return c->pos_mdeg + c->physical_offset_mdeg;
}
