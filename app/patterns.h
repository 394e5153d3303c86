/* scanner patterns: the projector's stored sequence as image files, for a projector with its own
 * pattern memory (a DLP evaluation module's flash, a pattern-sequencer's SD card). */
#ifndef PATTERNS_H
#define PATTERNS_H

#include "config.h"
#include "hal_storage.h"
#include "scan_types.h"

/** Write every pattern of the stored sequence at the projector's resolution as 8-bit grey PNGs
 *  (pattern_00.png ... : 0 black, 255 white) and patterns.txt, which says what each is and which
 *  ones a scan and a calibration step through. The sequence is the calibration's (column and row
 *  bits): a scan steps through its first part only (columns), so one stored sequence serves
 *  both.
 *  @param dir  created if missing
 *  @retval 0 ok @retval -ENOMEM @retval -errno from storage (said on stderr) */
int patterns_write(const struct hal_storage *st, const struct app_config *cfg,
                   const struct scan_calib *calib, const char *dir);

#endif
