/* The board: which backends fill the HAL. Exactly one implementation is linked, chosen at build
 * time (HAL=sim: host_sim/board_sim.c, HAL=linux: hal/linux/board_linux.c). */
#ifndef BOARD_H
#define BOARD_H

#include "config.h"
#include "hal.h"

/** "sim" or "linux". */
const char *board_name(void);

/** Fill every device of @p hal from the config; log and stop_requested stay as the caller set.
 *  @retval 0 ok @retval -errno with @p err saying which device and why; nothing stays requested */
int board_init(struct hal *hal, const struct app_config *cfg, const struct scan_calib *calib,
               char *err, size_t err_len);

/** Extra files for a whole scan (the simulator writes its true mesh). @retval 0 or -errno */
int board_write_scan_extras(const struct hal *hal, const char *scan_dir);

/** Extra files for a finished view (the simulator writes its ground truth). @retval 0 or -errno */
int board_write_view_extras(const struct hal *hal, const char *view_dir);

/** Safe state, then release every device. */
void board_shutdown(struct hal *hal);

#endif
