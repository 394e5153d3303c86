/* Camera-ray / projector-plane triangulation and range-image normals, into the caller's maps. */
#include "tri.h"

#include "camray.h"
#include "lens.h"
#include "vec3.h"

#include <errno.h>

/* Depth s along camera ray d (z = 1) where the projector's distorted column is @p col_n
 * (normalised: (u - cx) / fx). The point s d lands at q = s R d + t in the projector frame, at
 * normalised (q.x / q.z, q.y / q.z), distorted by lens_distort; Newton's method on s from the
 * pinhole plane's answer @p s0. This is the "distorted column surface": only the column is
 * needed, so the refined sub-pixel columns keep their precision and no rows are decoded.
 * @retval 1 converged to s > 0 @retval 0 not */
static int distorted_column_depth(const struct scan_calib *c, vec3 d, double col_n, double s0,
                                  double *s_out)
{
    const vec3 a = m3_mul(c->proj_rot, d), t = v3_from(c->proj_trans_mm);
    double s = s0;
    for (int it = 0; it < 12; it++) {
        vec3 q = v3_add(v3_scale(a, s), t);
        if (q.z <= 0.0)
            return 0;
        double xn = q.x / q.z, yn = q.y / q.z, xd, yd, j[4];
        lens_distort(c->proj_dist, xn, yn, &xd, &yd);
        lens_jacobian(c->proj_dist, xn, yn, j);
        double dxn = (a.x * q.z - q.x * a.z) / (q.z * q.z),
               dyn = (a.y * q.z - q.y * a.z) / (q.z * q.z);
        double deriv = j[0] * dxn + j[1] * dyn;
        if (deriv == 0.0)
            return 0;
        double step = (xd - col_n) / deriv;
        s -= step;
        if (fabs(step) < 1e-7) { /* mm */
            *s_out = s;
            return s > 0.0;
        }
    }
    return 0;
}

/* A ray table is made when at least 1 in this many pixels is to be triangulated. */
#define TRI_TABLE_SHARE 32u

/* @retval 1 enough of the @p n pixels are to be triangulated for a ray table to pay (counted
 * only as far as that: a scan's view reaches it within its first rows) */
static int worth_a_table(const uint8_t *reason, size_t n)
{
    size_t valid = 0;
    for (size_t i = 0; i < n; i++)
        if (reason[i] == SCAN_VALID && ++valid >= n / TRI_TABLE_SHARE)
            return 1;
    return 0;
}

int tri_range_image(const struct scan_calib *c, struct tri_maps *maps, uint32_t width,
                    uint32_t height, const float *column, uint8_t *reason, struct tri_range *range)
{
    if (width != c->cam_width || height != c->cam_height)
        return -EINVAL;
    /* The ray table costs a lens inversion a pixel: with few pixels to triangulate (the
     * calibration's depth-error prediction triangulates every 16th pixel for each of 64 drawn
     * calibrations, and spent a quarter of its time tabulating rays it never read) they are
     * inverted one by one instead (camray_ray without a table), a lens that folds over at one
     * of them refused as the table refuses it anywhere in the image. */
    struct camray rays = camray_lookup(c);
    if (rays.xy == NULL && !lens_is_pinhole(c->cam_dist) &&
        worth_a_table(reason, (size_t)width * height)) {
        int rc = camray_prepare(c, &rays);
        if (rc != 0)
            return rc;
    }
    const int proj_pinhole = lens_is_pinhole(c->proj_dist);
    /* Plane of projector column u: n_p = e_x - a e_z with a = (u - cx) / fx, through the
     * projector centre. n_p . (R p + t) = 0  <=>  (R^T n_p) . p + n_p . t = 0, and R^T n_p is
     * linear in a: R^T e_x - a R^T e_z. */
    const vec3 rt_ex = m3_tmul(c->proj_rot, v3(1, 0, 0)), rt_ez = m3_tmul(c->proj_rot, v3(0, 0, 1));
    const vec3 t = v3_from(c->proj_trans_mm);
    float *xyz_map = maps->xyz_mm;
    range->xyz_mm = maps->xyz_mm;
    range->normal = maps->normal;
    range->width = width;
    range->height = height;
    range->valid_count = 0;
    for (uint32_t y = 0; y < height; y++) {
        for (uint32_t x = 0; x < width; x++) {
            size_t i = (size_t)y * width + x;
            if (reason[i] != SCAN_VALID)
                continue;
            vec3 ray;
            if (camray_ray(c, rays, x, y, &ray) != 0)
                return -EDOM;
            double a = ((double)column[i] - c->proj_cx_px) / c->proj_fx_px;
            vec3 normal = v3_sub(rt_ex, v3_scale(rt_ez, a));
            double denom = v3_dot(normal, ray);
            double s = denom != 0.0 ? -(t.x - a * t.z) / denom : -1.0;
            /* A grazing plane (|denom| tiny) would put the point at infinity. */
            if (s <= 0.0 || denom * denom < 1e-12 * v3_dot(ray, ray) ||
                (!proj_pinhole && !distorted_column_depth(c, ray, a, s, &s))) {
                reason[i] = SCAN_INCONSISTENT;
                continue;
            }
            xyz_map[3 * i + 0] = (float)(ray.x * s);
            xyz_map[3 * i + 1] = (float)(ray.y * s);
            xyz_map[3 * i + 2] = (float)s;
            range->valid_count++;
        }
    }
    return 0;
}

static vec3 point_at(const float *xyz_map, size_t i)
{
    return v3(xyz_map[3 * i], xyz_map[3 * i + 1], xyz_map[3 * i + 2]);
}

/* How far (in steps of @p step, at most @p max_steps) the surface continues from pixel i: every
 * pixel on the way must be valid and no depth step may exceed max_jump. */
static uint32_t reach(const float *xyz_map, const uint8_t *reason, size_t i, long step,
                      uint32_t max_steps, double max_jump)
{
    uint32_t k = 0;
    size_t cur = i;
    while (k < max_steps) {
        size_t next = (size_t)((long)cur + step);
        if (reason[next] != SCAN_VALID ||
            fabs(xyz_map[3 * next + 2] - xyz_map[3 * cur + 2]) > max_jump)
            break;
        cur = next;
        k++;
    }
    return k;
}

/* Tangent along one image axis between the farthest continuous neighbours on either side.
 * Column quantisation makes the range image a staircase; a wide stencil averages it out.
 * @p before / @p after: how many steps exist in the image on each side. Returns 0 if none. */
static int tangent(const float *xyz_map, const uint8_t *reason, size_t i, uint32_t before,
                   uint32_t after, long step, uint32_t radius, double max_jump, vec3 *out)
{
    uint32_t back = reach(xyz_map, reason, i, -step, before < radius ? before : radius, max_jump);
    uint32_t fwd = reach(xyz_map, reason, i, step, after < radius ? after : radius, max_jump);
    if (back + fwd == 0)
        return 0;
    *out = v3_sub(point_at(xyz_map, (size_t)((long)i + step * (long)fwd)),
                  point_at(xyz_map, (size_t)((long)i - step * (long)back)));
    return 1;
}

int tri_normals(struct tri_maps *maps, struct tri_range *range, uint8_t *reason, uint32_t radius_px,
                double max_depth_jump_mm)
{
    const uint32_t w = range->width, h = range->height;
    const float *xyz_map = maps->xyz_mm;
    float *normal_map = maps->normal;
    uint32_t valid = 0;
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            if (reason[i] != SCAN_VALID)
                continue;
            vec3 du, dv;
            if (!tangent(xyz_map, reason, i, x, w - 1 - x, 1, radius_px, max_depth_jump_mm, &du) ||
                !tangent(xyz_map, reason, i, y, h - 1 - y, (long)w, radius_px, max_depth_jump_mm,
                         &dv)) {
                reason[i] = SCAN_INCONSISTENT;
                continue;
            }
            vec3 n = v3_norm(v3_cross(du, dv));
            if (v3_dot(n, point_at(xyz_map, i)) > 0.0) /* face the camera */
                n = v3_scale(n, -1.0);
            normal_map[3 * i + 0] = (float)n.x;
            normal_map[3 * i + 1] = (float)n.y;
            normal_map[3 * i + 2] = (float)n.z;
            valid++;
        }
    }
    range->valid_count = valid;
    return 0;
}

int tri_restore(const struct tri_maps *maps, uint32_t width, uint32_t height, uint32_t valid_count,
                struct tri_range *range)
{
    if ((uint64_t)width * height > HAL_MAX_PIXELS)
        return -E2BIG;
    *range = (struct tri_range){.xyz_mm = maps->xyz_mm,
                                .normal = maps->normal,
                                .width = width,
                                .height = height,
                                .valid_count = valid_count};
    return 0;
}
