/* The rig as a command brings it up and down (rig.c): one per process. */
#ifndef RIG_H
#define RIG_H

#include "config.h"
#include "hal.h"

/** The log of the commands: "scanner: LEVEL: message" on standard error (debug lines only with
 *  SCANNER_DEBUG set). */
void rig_log(enum hal_log_level level, const char *fmt, ...);
/** @retval 1 a stop was asked for (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGTSTP), or standard output
 *  can no longer be written (its reader went away) */
int rig_stop_requested(void);
/** The stop signals end a job between frames; fatal ones put the rig in its safe state first. */
void rig_install_signals(void);
/** A config, its calibration, and that they fit together. @retval 0 @retval -errno (said) */
int rig_load_all(const char *config_path, struct app_config *cfg, struct scan_calib *calib);
/** Devices up: logging, signals, the board, the camera; lights and projector off. rig_down
 *  must follow whatever this returns. @retval 0 @retval the error (said) */
int rig_up(const struct app_config *cfg, const struct scan_calib *calib);
/** Safe state, camera closed, board released (nothing to do when rig_up failed early). */
void rig_down(void);
/** The rig's HAL: what rig_up brought up (its log and stop request set even before). */
struct hal *rig_hal(void);

#endif
