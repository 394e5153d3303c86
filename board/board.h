/* The board: which backends fill the HAL. Exactly one implementation is linked, chosen at build
 * time (HAL=sim: board/board_sim.c, HAL=linux: board/board_linux.c). The board is the
 * composition root below app/: it sees the HAL interfaces, the backends and the simulator, never
 * app/ (its settings come in a struct board_config that app/ fills from the config file). */
#ifndef BOARD_H
#define BOARD_H

#include "hal.h"
#include "scan_types.h"

struct sim_config;       /* host_sim/sim_config.h: read by the simulator board only */
struct tt_client_config; /* hal/modbus/turntable_modbus.h */

/** The devices' settings, as the config file gave them. */
struct board_config {
    const char *config_path;    /**< the config file: named in messages; the simulator resolves
                                     relative paths against its directory */
    const char *camera_backend; /**< sim | v4l2 | libcamera */
    const struct hal_camera_config *camera;
    const struct hal_gpio_config *gpio;
    const struct tt_client_config *turntable;
    const struct scan_params *scan; /**< the simulator shows the view's patterns */
    const char *projector_backend;  /**< gpio | drm */
    const char *projector_device;   /**< the DRM device (drm) */
    const struct sim_config *sim;
};

/** "sim" or "linux". */
const char *board_name(void);

/** Fill every device of @p hal from the config; log and stop_requested stay as the caller set.
 *  @retval 0 ok @retval -errno with @p err saying which device and why; nothing stays requested */
int board_init(struct hal *hal, const struct board_config *cfg, const struct scan_calib *calib,
               char *err, size_t err_len);

/** Extra files for a whole scan (the simulator writes its true mesh). @retval 0 or -errno */
int board_write_scan_extras(const struct hal *hal, const char *scan_dir);

/** Extra files for a finished view (the simulator writes its ground truth). @retval 0 or -errno */
int board_write_view_extras(const struct hal *hal, const char *view_dir);

/** CPU time this process spent being the simulated rig (rendering frames, writing its ground
 *  truth), in seconds: a scan's own CPU is its total less this. 0 on a real rig. */
double board_simulator_cpu_s(void);

/** What the person puts on the turntable for a calibration step. */
enum board_target_kind { BOARD_TARGET_OBJECT = 0, BOARD_TARGET_BOARD, BOARD_TARGET_SPHERE };
struct board_target {
    uint32_t kind;                      /**< enum board_target_kind */
    const uint8_t *sheet;               /**< board: the printed sheet, grey, row-major */
    uint32_t sheet_width, sheet_height; /**< pixels */
    double sheet_px_per_mm;
    double thickness_mm;   /**< board: the plate under the sheet */
    double tilt_deg;       /**< board: from upright (facing the camera), leaning back; 90 flat */
    double diameter_mm;    /**< sphere */
    double position_mm[2]; /**< on the table at angle 0 (x towards the camera, y to its right) */
    uint32_t pass;         /**< object: the scan's pass (1: as it stands; 2: laid another way,
                                which the simulator does by [sim] second_pass_pose) */
};

/** The person's part of a calibration step, or of a scan's second pass. The simulator places
 *  the target itself; on a rig the person must be asked. @retval 0 placed @retval -ENOSYS ask the
 * person
 *  @retval -errno (with @p err) */
int board_place_target(struct hal *hal, const struct board_target *target, char *err,
                       size_t err_len);

/** Safe state, then release every device. */
void board_shutdown(struct hal *hal);

/** Open the camera with @p cam, capture one frame into a buffer of the configured size, close
 *  it. @param width @param height  out: the frame's size (0 when none came)
 *  @retval 0 @retval -ENOMEM @retval what opening or capturing returned */
int board_grab_frame(const struct hal *hal, const struct hal_camera_config *cam, uint32_t *width,
                     uint32_t *height);

/** One line of the selftest: @p device ("camera", "gpio", "turntable") at @p where, 0 or the
 *  -errno it failed with, and what was seen or why it failed. */
typedef void (*board_selftest_row)(void *ctx, const char *device, const char *where, int rc,
                                   const char *detail);

/** First power-on of a rig: open and try each configured device on its own (a camera frame of
 *  the configured size, the GPIO lines requested, the turntable's status), releasing each
 *  before the next, so that nothing stays requested. Reports every device through @p row.
 *  @retval 0 all work @retval -ENODEV at least one does not */
int board_selftest(struct hal *hal, const struct board_config *cfg, const struct scan_calib *calib,
                   board_selftest_row row, void *ctx);

#endif
