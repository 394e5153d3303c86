/* Test-side control of the simulated rig (like Zephyr's gpio_emul): read back outputs, inject
 * faults, advance virtual time. Only the simulator board provides these. */
#ifndef SIM_CTL_H
#define SIM_CTL_H

#include "hal.h"
#include "sim_rig.h"

enum sim_cam_fault {
    SIM_FAULT_NONE = 0,
    SIM_FAULT_TIMEOUT,   /**< capture answers -ETIMEDOUT */
    SIM_FAULT_CORRUPT,   /**< capture answers -EIO (short or corrupt frame) */
    SIM_FAULT_NO_DEVICE, /**< capture answers -ENODEV (camera unplugged) */
    SIM_FAULT_STALE,     /**< capture delivers a frame exposed before the last change: what
                              the previous frame showed, with its start time */
};

/** Driven value of a GPIO line (0/1). */
int sim_ctl_line(enum hal_gpio_line line);
/** Pattern the virtual projector currently shows. */
uint32_t sim_ctl_pattern_index(void);
/** Make captures number @p first_frame .. first_frame + count - 1 (counted from camera open)
 *  fail with @p kind. */
void sim_ctl_inject_camera_fault(enum sim_cam_fault kind, uint64_t first_frame, uint32_t count);
/** Captures attempted since the camera was opened. */
uint64_t sim_ctl_frames(void);
/** Virtual time in microseconds; sleeping through the HAL advances it. */
uint64_t sim_ctl_time_us(void);
void sim_ctl_advance_us(uint64_t us);
/** The simulated turntable controller (its state: ->ctrl under ->lock). */
struct tt_server *sim_ctl_turntable(void);
/** The pty pair between client and controller when the transport is RTU. */
struct pty_link *sim_ctl_serial_link(void);
/** The scanner's Modbus client (retry counters). */
struct tt_client *sim_ctl_turntable_client(void);
/** The renderer and its ground truth. */
struct sim_rig *sim_ctl_rig(void);

#endif
