/* Triangulation of decoded columns into a range image, and normals from that range image. */
#ifndef TRI_H
#define TRI_H

#include "decode.h"
#include "scan_types.h"

/** Read-only view of the range image (camera frame, millimetres), row-major. */
struct tri_range {
    const float *xyz_mm; /**< 3 floats per pixel, meaningful where the reason is SCAN_VALID */
    const float *normal; /**< unit normal per pixel, facing the camera */
    uint32_t width, height;
    uint32_t valid_count; /**< pixels left valid after triangulation and normals */
};

/** Intersect every valid pixel's camera ray with its projector column plane (the plane through
 *  the projector centre and column u_p, x_p / z_p = (u_p - cx_p) / fx_p in the projector frame).
 *  Pixels whose ray misses (parallel, behind a device) become SCAN_INCONSISTENT.
 *  @param column  continuous projector column per pixel (see refine.h)
 *  @retval 0 ok @retval -EINVAL calibration does not match the frame size */
int tri_range_image(const struct scan_calib *calib, const struct decode_maps *maps,
                    const float *column);

/** Normals from differences across up to @p radius_px pixels each side along both image axes,
 *  stopping where the surface breaks (a depth step above @p max_depth_jump_mm between
 *  neighbours). Pixels with no neighbour on their surface along an axis become SCAN_INCONSISTENT.
 *  @retval 0 */
int tri_normals(const struct decode_maps *maps, uint32_t radius_px, double max_depth_jump_mm);

/** The range image of the last view. */
const struct tri_range *tri_get_range(void);

#endif
