/* Turntable and object frames derived from the calibration. */
#include "frames.h"

void frame_table_from_camera(const struct scan_calib *calib, struct frame_xform *t)
{
    vec3 origin = v3_from(calib->axis_point_mm);
    vec3 ez = v3_norm(v3_from(calib->axis_dir));
    /* The camera centre is the camera frame's origin: x points from the axis towards it. */
    vec3 to_cam = v3_scale(origin, -1.0);
    vec3 ex = v3_norm(v3_sub(to_cam, v3_scale(ez, v3_dot(to_cam, ez))));
    vec3 ey = v3_cross(ez, ex);
    double rows[9] = {ex.x, ex.y, ex.z, ey.x, ey.y, ey.z, ez.x, ez.y, ez.z};
    for (int i = 0; i < 9; i++)
        t->rot[i] = rows[i];
    t->origin = origin;
}

void frame_object_from_camera(const struct scan_calib *calib, int32_t angle_mdeg,
                              struct frame_xform *o)
{
    frame_object_from_camera_rad(calib, (double)angle_mdeg * (M_PI / 180000.0), o);
}

void frame_object_from_camera_rad(const struct scan_calib *calib, double angle_rad,
                                  struct frame_xform *o)
{
    struct frame_xform t;
    frame_table_from_camera(calib, &t);
    /* The table turned the object by +angle; undo it: Rz(-angle) * table_from_cam. */
    double c = cos(angle_rad), s = sin(angle_rad);
    double rz[9] = {c, s, 0, -s, c, 0, 0, 0, 1};
    m3_mul_m3(rz, t.rot, o->rot);
    o->origin = t.origin;
}

void frame_from_small_motion(const double x[6], struct frame_xform *d)
{
    vec3 w = v3(x[0], x[1], x[2]);
    double th = v3_len(w);
    vec3 k = th > 0.0 ? v3_scale(w, 1.0 / th) : v3(1, 0, 0);
    double s = sin(th), c1 = 1.0 - cos(th);
    /* Rodrigues: R = I + sin(th) K + (1 - cos(th)) K^2 */
    double kx[9] = {0, -k.z, k.y, k.z, 0, -k.x, -k.y, k.x, 0}, kk[9];
    m3_mul_m3(kx, kx, kk);
    for (int e = 0; e < 9; e++)
        d->rot[e] = (e % 4 == 0 ? 1.0 : 0.0) + s * kx[e] + c1 * kk[e];
    /* p' = R p + t = R (p - origin) with origin = -R^T t */
    d->origin = v3_scale(m3_tmul(d->rot, v3(x[3], x[4], x[5])), -1.0);
}

void frame_compose(const struct frame_xform *a, const struct frame_xform *b,
                   struct frame_xform *out)
{
    /* a(b(p)) = Ra (Rb (p - ob) - oa) = Ra Rb (p - (ob + Rb^T oa)) */
    m3_mul_m3(a->rot, b->rot, out->rot);
    out->origin = v3_add(b->origin, m3_tmul(b->rot, a->origin));
}

void frame_invert(const struct frame_xform *a, struct frame_xform *out)
{
    /* q = Ra (p - oa)  <=>  p = Ra^T q + oa = Ra^T (q - (-Ra oa)) */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            out->rot[r * 3 + c] = a->rot[c * 3 + r];
    out->origin = v3_scale(m3_mul(a->rot, a->origin), -1.0);
}
