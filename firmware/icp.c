/* Pairwise point-to-plane ICP with projective association, in static buffers. */
#include "icp.h"

#include "camray.h"
#include "vec3.h"

#include <string.h>

#define ICP_STRIDE 2u /* the reference view is kept at half resolution */
#define REF_W ((HAL_MAX_WIDTH + ICP_STRIDE - 1) / ICP_STRIDE)
#define REF_H ((HAL_MAX_HEIGHT + ICP_STRIDE - 1) / ICP_STRIDE)

static struct {
    float xyz[REF_W * REF_H * 3];
    float normal[REF_W * REF_H * 3];
    uint8_t rgb[REF_W * REF_H * 3];
    uint8_t valid[REF_W * REF_H];
    uint32_t w, h;
    struct frame_xform pose; /* its camera frame to the object frame */
    int present;
} ref;

void icp_reset(void)
{
    ref.present = 0;
}

static void keep_as_reference(const struct decode_maps *m, const struct tri_range *r,
                              const uint8_t *rgb, const struct frame_xform *pose)
{
    ref.w = (m->width + ICP_STRIDE - 1) / ICP_STRIDE;
    ref.h = (m->height + ICP_STRIDE - 1) / ICP_STRIDE;
    for (uint32_t y = 0; y < ref.h; y++) {
        for (uint32_t x = 0; x < ref.w; x++) {
            size_t i = (size_t)y * ICP_STRIDE * m->width + (size_t)x * ICP_STRIDE;
            size_t j = (size_t)y * ref.w + x;
            ref.valid[j] = m->reason[i] == SCAN_VALID;
            memcpy(&ref.xyz[3 * j], &r->xyz_mm[3 * i], 3 * sizeof(float));
            memcpy(&ref.normal[3 * j], &r->normal[3 * i], 3 * sizeof(float));
            memcpy(&ref.rgb[3 * j], &rgb[3 * i], 3);
        }
    }
    ref.pose = *pose;
    ref.present = 1;
}

/* Normal equations of the linearised point-to-plane error: x = (omega, t), residual
 * r = (p - q) . n + omega . (p x n) + t . n (Chen and Medioni; Low 2004). */
struct normal_eq {
    double a[6][6], b[6], sq;
    uint32_t overlap, coupled;
};

static void solve6(double a[6][6], double b[6], double x[6])
{
    /* Gaussian elimination with partial pivoting; a and b are consumed. */
    for (int c = 0; c < 6; c++) {
        int piv = c;
        for (int r = c + 1; r < 6; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        for (int k = 0; k < 6; k++) {
            double t = a[c][k];
            a[c][k] = a[piv][k];
            a[piv][k] = t;
        }
        double t = b[c];
        b[c] = b[piv];
        b[piv] = t;
        if (fabs(a[c][c]) < 1e-12) {
            for (int k = 0; k < 6; k++)
                x[k] = 0.0;
            return;
        }
        for (int r = c + 1; r < 6; r++) {
            double f = a[r][c] / a[c][c];
            for (int k = c; k < 6; k++)
                a[r][k] -= f * a[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int r = 5; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < 6; k++)
            s -= a[r][k] * x[k];
        x[r] = s / a[r][r];
    }
}

/* Pair every sampled pixel of the new view, seen through @p to_ref (its camera frame to the
 * reference camera frame), with the reference pixel it projects onto. */
static void accumulate(const struct icp_params *prm, const struct scan_calib *c,
                       const struct decode_maps *m, const struct tri_range *r, const uint8_t *rgb,
                       const struct frame_xform *to_ref, struct normal_eq *eq)
{
    const double min_cos = cos(prm->max_normal_deg * M_PI / 180.0);
    memset(eq, 0, sizeof(*eq));
    for (uint32_t y = 0; y < m->height; y += prm->sample_stride) {
        for (uint32_t x = 0; x < m->width; x += prm->sample_stride) {
            size_t i = (size_t)y * m->width + x;
            if (m->reason[i] != SCAN_VALID)
                continue;
            vec3 p = frame_point(to_ref, v3(r->xyz_mm[3 * i], r->xyz_mm[3 * i + 1],
                                            r->xyz_mm[3 * i + 2]));
            vec3 n = frame_dir(to_ref, v3(r->normal[3 * i], r->normal[3 * i + 1],
                                          r->normal[3 * i + 2]));
            if (p.z <= 1.0)
                continue;
            double fu, fv;
            camray_project(c, p, &fu, &fv);
            long u = lround(fu / ICP_STRIDE), v = lround(fv / ICP_STRIDE);
            if (u < 0 || v < 0 || u >= (long)ref.w || v >= (long)ref.h)
                continue;
            size_t j = (size_t)v * ref.w + (size_t)u;
            if (!ref.valid[j])
                continue;
            eq->overlap++;
            vec3 q = v3(ref.xyz[3 * j], ref.xyz[3 * j + 1], ref.xyz[3 * j + 2]);
            vec3 nq = v3(ref.normal[3 * j], ref.normal[3 * j + 1], ref.normal[3 * j + 2]);
            if (v3_len(v3_sub(p, q)) > prm->max_pair_mm || v3_dot(n, nq) < min_cos)
                continue;
            int colour_ok = 1;
            for (int k = 0; k < 3 && prm->use_colour; k++)
                colour_ok &= fabs((double)rgb[3 * i + (size_t)k] - ref.rgb[3 * j + (size_t)k]) <=
                             prm->max_colour_dn;
            if (!colour_ok)
                continue;
            eq->coupled++;
            vec3 pxn = v3_cross(p, nq);
            double jac[6] = {pxn.x, pxn.y, pxn.z, nq.x, nq.y, nq.z};
            double res = v3_dot(v3_sub(p, q), nq);
            for (int a = 0; a < 6; a++) {
                for (int b = 0; b < 6; b++)
                    eq->a[a][b] += jac[a] * jac[b];
                eq->b[a] += jac[a] * res;
            }
            eq->sq += res * res;
        }
    }
}

/* The rigid motion of a small rotation vector omega and translation t, as a frame_xform. */
static void small_motion(const double x[6], struct frame_xform *d)
{
    vec3 w = v3(x[0], x[1], x[2]);
    double th = v3_len(w);
    vec3 k = th > 0.0 ? v3_scale(w, 1.0 / th) : v3(1, 0, 0);
    double s = sin(th), c1 = 1.0 - cos(th);
    /* Rodrigues: R = I + sin(th) K + (1 - cos(th)) K^2 */
    double kx[9] = {0, -k.z, k.y, k.z, 0, -k.x, -k.y, k.x, 0}, kk[9];
    for (int r = 0; r < 3; r++)
        for (int q = 0; q < 3; q++)
            kk[r * 3 + q] = kx[r * 3] * kx[q] + kx[r * 3 + 1] * kx[3 + q] + kx[r * 3 + 2] * kx[6 + q];
    for (int e = 0; e < 9; e++)
        d->rot[e] = (e % 4 == 0 ? 1.0 : 0.0) + s * kx[e] + c1 * kk[e];
    /* p' = R p + t = R (p - origin) with origin = -R^T t */
    d->origin = v3_scale(m3_tmul(d->rot, v3(x[3], x[4], x[5])), -1.0);
}

static void pose_difference(const struct frame_xform *a, const struct frame_xform *b,
                            double *mm, double *deg)
{
    /* how far b moves the points of a: compare where they send the camera centre and axes */
    vec3 pa = frame_point(a, v3(0, 0, 600)), pb = frame_point(b, v3(0, 0, 600));
    *mm = v3_len(v3_sub(pa, pb));
    double tr = 0.0;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 3; k++)
            tr += a->rot[r * 3 + k] * b->rot[r * 3 + k];
    double cang = 0.5 * (tr - 1.0);
    *deg = acos(cang > 1.0 ? 1.0 : cang < -1.0 ? -1.0 : cang) * 180.0 / M_PI;
}

int icp_register(const struct icp_params *prm, const struct scan_calib *c,
                 const struct decode_maps *m, const struct tri_range *r, const uint8_t *rgb,
                 struct frame_xform *pose, struct icp_report *rep)
{
    memset(rep, 0, sizeof(*rep));
    if (ref.present && prm->sample_stride > 0) {
        struct frame_xform ref_inv, to_ref, best = *pose;
        struct normal_eq eq;
        frame_invert(&ref.pose, &ref_inv);
        frame_compose(&ref_inv, pose, &to_ref);
        accumulate(prm, c, m, r, rgb, &to_ref, &eq);
        rep->has_pair = 1;
        rep->overlap_before = eq.overlap;
        rep->coupled_before = eq.coupled;
        rep->rms_before_mm = eq.coupled ? sqrt(eq.sq / eq.coupled) : 0.0;
        for (uint32_t it = 0; prm->enabled && it < prm->iterations && eq.coupled >= 6; it++) {
            double x[6], b[6];
            for (int k = 0; k < 6; k++)
                b[k] = -eq.b[k];
            solve6(eq.a, b, x);
            struct frame_xform step, moved;
            small_motion(x, &step);
            frame_compose(&step, &to_ref, &moved);
            to_ref = moved;
            accumulate(prm, c, m, r, rgb, &to_ref, &eq);
        }
        rep->overlap_after = eq.overlap;
        rep->coupled_after = eq.coupled;
        rep->rms_after_mm = eq.coupled ? sqrt(eq.sq / eq.coupled) : 0.0;
        frame_compose(&ref.pose, &to_ref, &best);
        pose_difference(pose, &best, &rep->correction_mm, &rep->correction_deg);
        rep->accepted = prm->enabled && rep->coupled_after >= rep->coupled_before &&
                        rep->correction_mm <= prm->max_correction_mm &&
                        rep->correction_deg <= prm->max_correction_deg;
        if (rep->accepted)
            *pose = best;
    }
    keep_as_reference(m, r, rgb, pose);
    return 0;
}
