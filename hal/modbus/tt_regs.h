/* Register map of the Modbus stepper turntable controller (docs/turntable-modbus.md), shared by
 * the scanner's client and the simulated controller. Holding registers, 16 bit; 32-bit values are
 * two registers, high word first (as Leadshine and JVL drives do). */
#ifndef TT_REGS_H
#define TT_REGS_H

enum tt_reg {
    TT_REG_TARGET_HI = 0, /**< target position, int32 millidegrees (RW) */
    TT_REG_TARGET_LO = 1,
    TT_REG_ACTUAL_HI = 2, /**< actual position, int32 millidegrees (RO) */
    TT_REG_ACTUAL_LO = 3,
    TT_REG_SPEED = 4,      /**< profile speed, 0.1 deg/s (RW) */
    TT_REG_ACCEL = 5,      /**< profile acceleration and deceleration, 0.1 deg/s^2 (RW) */
    TT_REG_COMMAND = 6,    /**< enum tt_command, executed when COMMAND_ID changes (RW) */
    TT_REG_COMMAND_ID = 7, /**< client's command counter (RW) */
    TT_REG_STATUS = 8,     /**< TT_STATUS_* bits (RO) */
    TT_REG_ALARM = 9,      /**< enum tt_alarm (RO) */
    TT_REG_LAST_ID = 10,   /**< COMMAND_ID of the last command executed (RO) */
    TT_REG_DEVICE_ID = 11, /**< TT_DEVICE_ID, to recognise the controller (RO) */
    TT_REG_COUNT = 12
};

#define TT_DEVICE_ID 0x5454u /* "TT" */

enum tt_command {
    TT_CMD_NONE = 0,
    TT_CMD_MOVE = 1,        /**< move to TARGET with SPEED and ACCEL */
    TT_CMD_HOME = 2,        /**< find the reference; position becomes 0 */
    TT_CMD_STOP = 3,        /**< decelerate to a stop */
    TT_CMD_CLEAR_ALARM = 4, /**< clear the alarm if its cause is gone */
};

#define TT_STATUS_BUSY 0x0001u        /* a move or homing is under way */
#define TT_STATUS_IN_POSITION 0x0002u /* idle at TARGET (within one step) */
#define TT_STATUS_HOMED 0x0004u       /* the reference is known */
#define TT_STATUS_ALARM 0x0008u       /* ALARM holds a code; motion is refused */

enum tt_alarm {
    TT_ALARM_NONE = 0,
    TT_ALARM_STALL = 1,       /**< following error: the motor did not follow (blocked table) */
    TT_ALARM_NOT_HOMED = 2,   /**< MOVE before HOME */
    TT_ALARM_BAD_COMMAND = 3, /**< unknown command, or speed/acceleration 0 */
    TT_ALARM_OVERHEAT = 4,    /**< driver over temperature */
};

/** Registers a client may write; writing any other is answered with exception 2. */
static inline int tt_reg_writable(int addr)
{
    return addr == TT_REG_TARGET_HI || addr == TT_REG_TARGET_LO || addr == TT_REG_SPEED ||
           addr == TT_REG_ACCEL || addr == TT_REG_COMMAND || addr == TT_REG_COMMAND_ID;
}

/** Text of an alarm code, for errors a person reads. */
static inline const char *tt_alarm_text(unsigned code)
{
    switch (code) {
    case TT_ALARM_NONE:
        return "no alarm";
    case TT_ALARM_STALL:
        return "stall (following error)";
    case TT_ALARM_NOT_HOMED:
        return "move before homing";
    case TT_ALARM_BAD_COMMAND:
        return "bad command or profile";
    case TT_ALARM_OVERHEAT:
        return "driver over temperature";
    default:
        return "unknown alarm";
    }
}

#endif
