/* Camera-ray / projector-plane triangulation and range-image normals, into the caller's maps. */
#include "tri.h"

#include "camray.h"
#include "hal_thread.h"
#include "lens.h"
#include "vec3.h"

#include <errno.h>
#include <math.h>
#include <string.h>

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

/* What every part of a range image shares: the calibration, its rays, the projector planes'
 * constants, the maps; each part's count of points and what it met. */
struct range_parts {
    const struct scan_calib *c;
    struct camray rays;
    int proj_pinhole;
    vec3 rt_ex, rt_ez, t;
    float *xyz_map;
    const float *column;
    uint8_t *reason;
    uint32_t width, height;
    unsigned parts;
    uint32_t valid[HAL_MAX_PARTS];
    int rc[HAL_MAX_PARTS];
};

/* Part @p k of the rows: each valid pixel's point, or SCAN_INCONSISTENT (its own pixel only). */
static void range_rows(void *arg, unsigned k)
{
    struct range_parts *p = arg;
    const struct scan_calib *c = p->c;
    uint32_t valid = 0; /* counted here: the parts' counts share a cache line */
    p->rc[k] = 0;
    for (uint32_t y = p->height * k / p->parts; y < p->height * (k + 1u) / p->parts; y++) {
        for (uint32_t x = 0; x < p->width; x++) {
            size_t i = (size_t)y * p->width + x;
            if (p->reason[i] != SCAN_VALID)
                continue;
            vec3 ray;
            if (camray_ray(c, p->rays, x, y, &ray) != 0) {
                p->rc[k] = -EDOM;
                return;
            }
            double a = ((double)p->column[i] - c->proj_cx_px) / c->proj_fx_px;
            vec3 normal = v3_sub(p->rt_ex, v3_scale(p->rt_ez, a));
            double denom = v3_dot(normal, ray);
            double s = denom != 0.0 ? -(p->t.x - a * p->t.z) / denom : -1.0;
            /* A grazing plane (|denom| tiny) would put the point at infinity. */
            if (s <= 0.0 || denom * denom < 1e-12 * v3_dot(ray, ray) ||
                (!p->proj_pinhole && !distorted_column_depth(c, ray, a, s, &s))) {
                p->reason[i] = SCAN_INCONSISTENT;
                continue;
            }
            p->xyz_map[3 * i + 0] = (float)(ray.x * s);
            p->xyz_map[3 * i + 1] = (float)(ray.y * s);
            p->xyz_map[3 * i + 2] = (float)s;
            valid++;
        }
    }
    p->valid[k] = valid;
}

int tri_range_image(const struct scan_calib *c, const struct hal_thread *threads,
                    struct tri_maps *maps, uint32_t width, uint32_t height, const float *column,
                    uint8_t *reason, struct tri_range *range)
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
    /* Plane of projector column u: n_p = e_x - a e_z with a = (u - cx) / fx, through the
     * projector centre. n_p . (R p + t) = 0  <=>  (R^T n_p) . p + n_p . t = 0, and R^T n_p is
     * linear in a: R^T e_x - a R^T e_z. */
    struct range_parts p = {.c = c,
                            .rays = rays,
                            .proj_pinhole = lens_is_pinhole(c->proj_dist),
                            .rt_ex = m3_tmul(c->proj_rot, v3(1, 0, 0)),
                            .rt_ez = m3_tmul(c->proj_rot, v3(0, 0, 1)),
                            .t = v3_from(c->proj_trans_mm),
                            .xyz_map = maps->xyz_mm,
                            .column = column,
                            .reason = reason,
                            .width = width,
                            .height = height,
                            .parts = hal_thread_parts(threads, HAL_MAX_PARTS)};
    hal_thread_run(threads, p.parts, range_rows, &p);
    range->xyz_mm = maps->xyz_mm;
    range->normal = maps->normal;
    range->width = width;
    range->height = height;
    range->valid_count = 0;
    for (unsigned k = 0; k < p.parts; k++) {
        if (p.rc[k] != 0)
            return p.rc[k];
        range->valid_count += p.valid[k];
    }
    return 0;
}

static vec3 point_at(const float *xyz_map, size_t i)
{
    return v3(xyz_map[3 * i], xyz_map[3 * i + 1], xyz_map[3 * i + 2]);
}

/* In the reason map between the normals' two passes: valid, but found without a normal by the
 * first (a transient code, never left in the map). */
#define NORMAL_PENDING SCAN_REASON_COUNT

/* How far (in steps of @p step, at most @p max_steps) the surface continues from pixel i: every
 * pixel on the way must be valid (or have the reason @p also) and no depth step may exceed
 * max_jump. */
static inline uint32_t reach(const float *xyz_map, const uint8_t *reason, size_t i, long step,
                             uint32_t max_steps, double max_jump, uint8_t also)
{
    uint32_t k = 0;
    size_t cur = i;
    while (k < max_steps) {
        size_t next = (size_t)((long)cur + step);
        if ((reason[next] != SCAN_VALID && reason[next] != also) ||
            fabs(xyz_map[3 * next + 2] - xyz_map[3 * cur + 2]) > max_jump)
            break;
        cur = next;
        k++;
    }
    return k;
}

/* Tangent along one image axis between the farthest continuous neighbours on either side.
 * Column quantisation makes the range image a staircase; a wide stencil averages it out.
 * @p before / @p after: how many steps exist in the image on each side; @p ahead_also: a reason
 * the steps ahead (to the right, down) may pass besides SCAN_VALID. Returns 0 if none. */
static inline int tangent(const float *xyz_map, const uint8_t *reason, size_t i, uint32_t before,
                          uint32_t after, long step, uint32_t radius, double max_jump,
                          uint8_t ahead_also, vec3 *out)
{
    uint32_t back =
        reach(xyz_map, reason, i, -step, before < radius ? before : radius, max_jump, SCAN_VALID);
    uint32_t fwd =
        reach(xyz_map, reason, i, step, after < radius ? after : radius, max_jump, ahead_also);
    if (back + fwd == 0)
        return 0;
    *out = v3_sub(point_at(xyz_map, (size_t)((long)i + step * (long)fwd)),
                  point_at(xyz_map, (size_t)((long)i - step * (long)back)));
    return 1;
}

/* What every part of the normals shares, and each part's count of normals. */
struct normal_parts {
    const float *xyz_map;
    float *normal_map;
    const uint8_t *reason;
    uint32_t width, height, radius_px;
    double max_depth_jump_mm;
    int again; /* the second pass */
    unsigned parts;
    uint32_t valid[HAL_MAX_PARTS];
};

/* The first pixel from @p i on (before @p end) that is SCAN_VALID (0: memchr finds it, many
 * bytes at a time, across the shadow and the background), or @p end. */
static inline size_t next_valid(const uint8_t *reason, size_t i, size_t end)
{
    const uint8_t *at = i < end ? memchr(reason + i, SCAN_VALID, end - i) : NULL;
    return at != NULL ? (size_t)(at - reason) : end;
}

/* A pixel within @p radius before pixel i (to its left, above it) the first pass left without
 * a normal: only then can the second pass find another. */
static int pending_before(const uint8_t *reason, size_t i, uint32_t x, uint32_t y, uint32_t w,
                          uint32_t radius)
{
    for (uint32_t d = 1; d <= radius; d++)
        if ((d <= x && reason[i - d] == NORMAL_PENDING) ||
            (d <= y && reason[i - (size_t)d * w] == NORMAL_PENDING))
            return 1;
    return 0;
}

/* Part @p k of the rows: each valid pixel's normal, or NaN where it has none (no neighbour on
 * its surface along an axis). The first pass reads the reasons as triangulated. The second
 * recomputes the pixels that have a pixel the first left without a normal just before them (to
 * the left, above), whose reach now stops there: the normals one pass in the image's order made
 * when it marked each pixel without a normal as it went (but that a pixel losing its normal in
 * the second pass stops no other's reach), and the same on any number of threads (the reasons
 * are only read during a pass). */
static inline __attribute__((always_inline)) void normal_rows_of(struct normal_parts *p, unsigned k,
                                                                 const int again)
{
    const uint32_t w = p->width, h = p->height, radius = p->radius_px;
    const float *xyz_map = p->xyz_map;
    const uint8_t *reason = p->reason;
    float *normal_map = p->normal_map;
    const double jump = p->max_depth_jump_mm;
    const uint8_t ahead_also = again ? NORMAL_PENDING : SCAN_VALID;
    uint32_t valid = 0; /* counted here: the parts' counts share a cache line */
    for (uint32_t y = h * k / p->parts; y < h * (k + 1u) / p->parts; y++) {
        const uint8_t *row = reason + (size_t)y * w;
        for (uint32_t x = next_valid(row, 0, w); x < w; x = next_valid(row, x + 1, w)) {
            size_t i = (size_t)y * w + x;
            if (again && !pending_before(reason, i, x, y, w, radius)) {
                valid++; /* the first pass's normal stands */
                continue;
            }
            vec3 du, dv, n = v3(NAN, NAN, NAN);
            if (tangent(xyz_map, reason, i, x, w - 1 - x, 1, radius, jump, ahead_also, &du) &&
                tangent(xyz_map, reason, i, y, h - 1 - y, (long)w, radius, jump, ahead_also, &dv)) {
                n = v3_norm(v3_cross(du, dv));
                if (v3_dot(n, point_at(xyz_map, i)) > 0.0) /* face the camera */
                    n = v3_scale(n, -1.0);
                valid++;
            }
            normal_map[3 * i + 0] = (float)n.x;
            normal_map[3 * i + 1] = (float)n.y;
            normal_map[3 * i + 2] = (float)n.z;
        }
    }
    p->valid[k] = valid;
}

/* normal_rows_of for each pass, each its own copy (the pass a constant in it) */
static void normal_rows(void *arg, unsigned k)
{
    struct normal_parts *p = arg;
    if (p->again)
        normal_rows_of(p, k, 1);
    else
        normal_rows_of(p, k, 0);
}

/* Part @p k of the rows, once every part has read the reasons: after the first pass a valid
 * pixel without a normal becomes NORMAL_PENDING; after the second it and every other valid
 * pixel without one becomes SCAN_INCONSISTENT. */
static void normal_verdicts(void *arg, unsigned k)
{
    struct normal_parts *p = arg;
    uint8_t *reason = (uint8_t *)p->reason; /* the caller's map: read-only during a pass */
    const float *normal_map = p->normal_map;
    const size_t i0 = (size_t)p->width * (p->height * k / p->parts);
    const size_t i1 = (size_t)p->width * (p->height * (k + 1u) / p->parts);
    const uint8_t verdict = p->again ? SCAN_INCONSISTENT : NORMAL_PENDING;
    for (size_t i = next_valid(reason, i0, i1); i < i1; i = next_valid(reason, i + 1, i1))
        if (isnan(normal_map[3 * i]))
            reason[i] = verdict;
    if (!p->again)
        return;
    const uint8_t *at = reason + i0, *end = reason + i1;
    while ((at = memchr(at, NORMAL_PENDING, (size_t)(end - at))) != NULL)
        *(uint8_t *)at++ = SCAN_INCONSISTENT;
}

int tri_normals(struct tri_maps *maps, const struct hal_thread *threads, struct tri_range *range,
                uint8_t *reason, uint32_t radius_px, double max_depth_jump_mm)
{
    struct normal_parts p = {.xyz_map = maps->xyz_mm,
                             .normal_map = maps->normal,
                             .reason = reason,
                             .width = range->width,
                             .height = range->height,
                             .radius_px = radius_px,
                             .max_depth_jump_mm = max_depth_jump_mm,
                             .parts = hal_thread_parts(threads, HAL_MAX_PARTS)};
    for (p.again = 0; p.again <= 1; p.again++) {
        hal_thread_run(threads, p.parts, normal_rows, &p);
        hal_thread_run(threads, p.parts, normal_verdicts, &p);
    }
    range->valid_count = 0;
    for (unsigned k = 0; k < p.parts; k++)
        range->valid_count += p.valid[k];
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
