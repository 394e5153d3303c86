/* The camera's pixel rays and projection with its lens distortion: one ray per pixel from a
 * table in static memory, computed once per calibration. */
#ifndef CAMRAY_H
#define CAMRAY_H

#include "scan_types.h"
#include "vec3.h"

/** Make the ray table for @p calib (nothing to do for a pinhole camera, or when the table is
 *  already this calibration's).
 *  @retval 0 @retval -EINVAL the image is larger than the compiled limit
 *  @retval -EDOM the distortion folds over inside the image (not a lens a calibration gives) */
int camray_prepare(const struct scan_calib *calib);

/** The ray through pixel (x, y), scaled to z = 1 (camera frame): the table's when it is this
 *  calibration's, else computed. */
vec3 camray_at(const struct scan_calib *calib, uint32_t x, uint32_t y);

/** Where the camera-frame point @p p (z > 0) is seen: continuous pixel coordinates, pixel centres
 *  at integers. */
void camray_project(const struct scan_calib *calib, vec3 p, double *u, double *v);

#endif
