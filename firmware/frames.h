/* Coordinate frames: camera, turntable (axis = z, up) and object (turntable frame undone by angle).
 */
#ifndef FRAMES_H
#define FRAMES_H

#include "scan_types.h"
#include "vec3.h"

/** Rigid transform p_to = rot * (p_from - origin). */
struct frame_xform {
    double rot[9];
    vec3 origin;
};

/** Turntable frame from the calibration: origin on the axis at the table surface, z up the axis,
 *  x towards the camera (perpendicular to the axis), y = z cross x. Serves the firmware and the
 *  simulator, so both agree on what angle 0 means. */
void frame_table_from_camera(const struct scan_calib *calib, struct frame_xform *table_from_cam);

/** Object frame from camera frame for a view taken at turntable angle @p angle_mdeg. */
void frame_object_from_camera(const struct scan_calib *calib, int32_t angle_mdeg,
                              struct frame_xform *obj_from_cam);

/** The same for an angle in radians (a registered angle is not a whole millidegree). */
void frame_object_from_camera_rad(const struct scan_calib *calib, double angle_rad,
                                  struct frame_xform *obj_from_cam);

/** The rigid motion p' = R p + t of a small rotation vector x[0..2] (rad) and translation
 *  x[3..5]: the step of a linearised point-to-plane solve (Low 2004). */
void frame_from_small_motion(const double x[6], struct frame_xform *out);

/** Apply to a point. */
static inline vec3 frame_point(const struct frame_xform *x, vec3 p)
{
    return m3_mul(x->rot, v3_sub(p, x->origin));
}
/** Apply to a direction. */
static inline vec3 frame_dir(const struct frame_xform *x, vec3 d)
{
    return m3_mul(x->rot, d);
}
/** Inverse, to a point: p_from = rot^T p_to + origin. */
static inline vec3 frame_point_inv(const struct frame_xform *x, vec3 p)
{
    return v3_add(m3_tmul(x->rot, p), x->origin);
}
/** Inverse, to a direction. */
static inline vec3 frame_dir_inv(const struct frame_xform *x, vec3 d)
{
    return m3_tmul(x->rot, d);
}

/** out(p) = a(b(p)). @p out may alias neither input. */
void frame_compose(const struct frame_xform *a, const struct frame_xform *b,
                   struct frame_xform *out);
/** out = a^-1. */
void frame_invert(const struct frame_xform *a, struct frame_xform *out);

#endif
