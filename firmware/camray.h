/* The camera's pixel rays and projection with its lens distortion: one ray per pixel from a
 * table in static memory, computed once per calibration. */
#ifndef CAMRAY_H
#define CAMRAY_H

#include "scan_types.h"
#include "vec3.h"

/** The rays of one calibration, as camray_prepare or camray_lookup hands them out: the table's
 *  rows when it is that calibration's (by content, not by where the calibration is kept), or
 *  NULL: each ray computed. */
struct camray {
    const float *xy; /**< x/z, y/z of each pixel, or NULL */
};

/** Make the ray table for @p calib (nothing to do for a pinhole camera, or when the table is
 *  already this calibration's). @param out  the rays to pass to camray_at
 *  @retval 0 @retval -EINVAL the image is larger than the compiled limit
 *  @retval -EDOM the distortion folds over inside the image (not a lens a calibration gives) */
int camray_prepare(const struct scan_calib *calib, struct camray *out);

/** The rays of @p calib without making a table: the table's when one was made for a calibration
 *  equal to it, else computed ray by ray. */
struct camray camray_lookup(const struct scan_calib *calib);

/** The ray through pixel (x, y), scaled to z = 1 (camera frame), from @p rays (camray_prepare
 *  or camray_lookup of the same @p calib). */
vec3 camray_at(const struct scan_calib *calib, struct camray rays, uint32_t x, uint32_t y);

/** The same, saying whether the lens could be inverted there: without a table the ray is
 *  computed here, and a lens that folds over at (x, y) has none (what camray_prepare says of the
 *  whole image). @param ray  out @retval 0 @retval -EDOM the lens folds over at (x, y) */
int camray_ray(const struct scan_calib *calib, struct camray rays, uint32_t x, uint32_t y,
               vec3 *ray);

/** Where the camera-frame point @p p (z > 0) is seen: continuous pixel coordinates, pixel centres
 *  at integers. */
void camray_project(const struct scan_calib *calib, vec3 p, double *u, double *v);

/** Where camera-frame point @p p falls in the projector's image (its pose, pinhole, distortion:
 *  the model tri_range_image inverts), pixel centres at integers. @retval 1 @retval 0 behind
 *  the projector (@p u, @p v untouched) */
int camray_project_projector(const struct scan_calib *calib, vec3 p, double *u, double *v);

#endif
