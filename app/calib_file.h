/* calibration.ini, the rig's calibration (calib_file.c): read with every value checked, written
 * durably, documented from the same key table. */
#ifndef CALIB_FILE_H
#define CALIB_FILE_H

#include "hal.h"
#include "scan_types.h"

#include <stdint.h>
#include <stdio.h>

/** Parse and check a calibration file. @retval 0 ok, otherwise @p err says file, line and key */
int calib_load(struct scan_calib *calib, const char *path, uint32_t light_count, char *err,
               size_t err_len);

/** Write @p calib as a calibration file calib_load reads back, durably (temp, fsync, rename),
 *  under the comment lines @p comment (each line starts "; "; may be NULL).
 *  @retval 0 @retval -errno */
int calib_save(const struct hal_storage *st, const char *path, const struct scan_calib *calib,
               const char *comment);

/** The reprojection RMS scanner calibrate recorded in a calibration file's comment
 *  ("; quality: camera_rms_px = C, projector_rms_px = P", written by calib_solve.c), px; -1 for
 *  each when the file has none. */
void calib_read_quality(const char *path, double *camera_rms_px, double *projector_rms_px);

/** Why scanner calibrate flagged the file at @p path weak (its "; weak: " comment), into @p why.
 *  @retval 1 flagged @retval 0 not (or no such file) */
int calib_read_weak(const char *path, char *why, size_t why_len);

/** A file named after the calibration file @p cal_path, its ".ini" replaced by @p suffix
 *  ("CAL.ini" and "-captures": "CAL-captures"; ".report.txt": its report). */
void calib_path_beside(const char *cal_path, const char *suffix, char *buf, size_t len);

/** Markdown documentation of the calibration file's keys. */
void calib_print_doc(FILE *out);

#endif
