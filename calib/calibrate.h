/* `scanner calibrate` (its own program, scanner-calibrate: the calib/ layer): lead a person
 * through capturing a board and a sphere on the turntable, keep every capture, and compute the
 * rig's calibration file from them (docs/calibration.md). */
#ifndef CALIBRATE_H
#define CALIBRATE_H

#include "config.h"
#include "hal.h"
#include "scan_types.h"

#include <stddef.h>
#include <stdint.h>

#define CALIB_SPHERE_MAX_RMS_SHARE 0.1 /**< a ball capture fits its sphere within this x radius */
#define CALIB_LIGHT_MAX_MM 5000.0      /**< no light of a rig is farther from its table */

/** The scan parameters every calibration capture is taken and decoded with (rows as well as
 *  columns; every light's frame): the projector must store this sequence. */
void calib_capture_params(const struct app_config *cfg, struct scan_params *p);

/** A first guess of the rig for the captures when no calibration file exists: the camera's
 *  size from [camera], the projector's from [calibrate], nominal optics and pose. */
void calibrate_guess(const struct app_config *cfg, struct scan_calib *guess);

/** Capture every step into @p dir (new, or an unfinished calibration directory: the steps
 *  already there are kept), telling the person what to do; the simulator places the targets.
 *  @param json  1: the steps, captures and live pictures as events on stdout (docs/api.md), the
 *  answers on stdin (scanner serve) @retval 0 @retval -EINTR stopped (captures kept)
 *  @retval -errno (said) */
int calibrate_capture(struct hal *hal, const struct app_config *cfg, const struct scan_calib *guess,
                      const char *dir, int json);

/** Compute the calibration from the captures in @p dir (and @p added, NULL for none: captures of
 *  placements added later, e.g. those a weak calibration asked for) and write @p out_path (an
 *  existing file is kept beside it) with its report. @param cfg  the config (board, limits,
 *  light count) @param json  1: the result as one JSON object on stdout instead of the report
 *  (calib_json_write) @retval 0 @retval -EINVAL refused (said why) @retval -errno */
int calibrate_solve(const struct hal_storage *st, const struct app_config *cfg, const char *dir,
                    const char *added, const char *out_path, int json);

/** Rewrite captures made with OpenCV's GrayCodePattern (@p src: a folder a board pose, each with
 *  its PNG images in OpenCV's order: column bits and inverses, row bits and inverses, white,
 *  black) as the calibration directory @p dst (made new) that calibrate_solve reads; the
 *  projector's size from the config's calibration file or [calibrate].
 *  @retval 0 @retval -EINVAL a pose's image count is not the sequence's @retval -errno (said) */
int calibrate_import_opencv(const struct hal_storage *st, const struct app_config *cfg,
                            const char *src, const char *dst);

/** Scan the sphere of [calibrate] sphere_diameter_mm once and print the diameter error and the
 *  sphere fit's RMS, with the calibration's reprojection RMS. @param json  1: as one event
 *  (calib_verify) on stdout @retval 0 @retval -errno */
int calibrate_verify(struct hal *hal, const struct app_config *cfg, const struct scan_calib *calib,
                     int json);

/** Write the board to print: PNG at 300 dpi and SVG at true size (@p base.png, @p base.svg).
 *  @retval 0 @retval -errno */
int calibrate_print_board(const struct hal_storage *st, const struct app_config *cfg,
                          const char *base);

#endif
