/* Triangulation of decoded columns into a range image, and normals from that range image. */
#ifndef TRI_H
#define TRI_H

#include "decode.h"
#include "scan_types.h"

struct hal_thread;

/** Read-only view of the range image (camera frame, millimetres), row-major. */
struct tri_range {
    const float *xyz_mm; /**< 3 floats per pixel, meaningful where the reason is SCAN_VALID */
    const float *normal; /**< unit normal per pixel, facing the camera */
    uint32_t width, height;
    uint32_t valid_count; /**< pixels left valid after triangulation and normals */
};

/** Where a range image is kept (several MB at the compiled limits: static in its owner, a
 *  struct scan_ctx). */
struct tri_maps {
    float xyz_mm[HAL_MAX_PIXELS * 3]; /**< 3 floats per pixel */
    float normal[HAL_MAX_PIXELS * 3]; /**< 3 floats per pixel */
};

/** Intersect every valid pixel's camera ray (camray.h: through the camera's lens model) with
 *  its projector column: for a pinhole projector the plane through the projector centre and
 *  column u_p, x_p / z_p = (u_p - cx_p) / fx_p in the projector frame; with projector distortion
 *  the surface of points whose distorted column is u_p (found along the ray by Newton's method).
 *  @param maps  where the points go
 *  @param threads  the cores the rows are split across (NULL: this thread); the same points on any
 *  @param width, height  the frame's size (must be the calibration's)
 *  @param column  continuous projector column per pixel (see refine.h)
 *  @param reason  in/out: pixels whose ray misses (parallel, behind a device) become
 *                 SCAN_INCONSISTENT; only SCAN_VALID pixels are triangulated
 *  @param range   out: the points (in @p maps), valid_count
 *  @retval 0 ok @retval -EINVAL calibration does not match the frame size
 *  @retval -EDOM the camera's distortion folds over inside the image */
int tri_range_image(const struct scan_calib *calib, const struct hal_thread *threads,
                    struct tri_maps *maps, uint32_t width, uint32_t height, const float *column,
                    uint8_t *reason, struct tri_range *range);
/** Normals from differences across up to @p radius_px pixels each side along both image axes,
 *  stopping where the surface breaks (a depth step above @p max_depth_jump_mm between
 *  neighbours); a pixel found without a normal stops the reach of the pixels after it in the
 *  image (to its right, below it). Two passes, each reading the reasons as the one before left
 *  them, so that the rows can be split across threads with the same result.
 *  @param maps    the maps tri_range_image filled; the normals go there
 *  @param threads the cores the rows are split across (NULL: this thread)
 *  @param range   in/out: the points of tri_range_image; their normals and valid_count are set
 *  @param reason  in/out: pixels with no neighbour on their surface along an axis become
 *                 SCAN_INCONSISTENT
 *  @retval 0 */
int tri_normals(struct tri_maps *maps, const struct hal_thread *threads, struct tri_range *range,
                uint8_t *reason, uint32_t radius_px, double max_depth_jump_mm);

/** A range image kept earlier (a view restored from its scan directory), filled into @p maps
 *  by the caller instead of triangulated. @param range  out: points to @p maps, with @p width,
 *  @p height and @p valid_count @retval 0 @retval -E2BIG larger than the compiled limit */
int tri_restore(const struct tri_maps *maps, uint32_t width, uint32_t height, uint32_t valid_count,
                struct tri_range *range);
#endif
