/* Joint registration of a turntable scan's views (reg.h), in the caller's struct reg_ctx.
 *
 * The camera stays put and the object turns, so view j sees view i's points turned about the
 * table axis (point a, unit direction d) by theta_j - theta_i:
 *     p' = a + R(d, theta_j - theta_i) (p - a).
 * The unknowns are each view's angle (view 0's fixes the gauge) and the axis (two shifts and two
 * tilts across d). Every ordered pair of neighbouring views contributes point-to-plane residuals
 * r = n_q . (p' - q) with q, n_q the point and normal of view j where p' projects (projective
 * association, Blais and Levine; Rusinkiewicz and Levoy 2001), and one Gauss-Newton step solves
 * for all unknowns together. Derivatives (R = R(d, delta), e a unit vector across d):
 *     dp'/dtheta_j = d x (p' - a) = -dp'/dtheta_i
 *     dp'/d(shift of a along e) = (I - R) e
 *     dp'/d(tilt of d about e)  = e x R (p - a) - R (e x (p - a))   (R' = Q R Q^T, Q about e). */
#include "reg.h"
#include "reg_priv.h"

#include "align.h"
#include "camray.h"
#include "lsq.h"
#include "mem.h"
#include "vec3.h"

#include <errno.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Whether two samples' colours let them pair (multi-feature matching). Intrinsic colours are the
 * surface's own: every channel within max_colour_dn. A raw colour is the surface's times its
 * shading, which changes with the angle to the light (a flat face seen 45 degrees apart differs
 * by a third in brightness): @p a is brought to @p b's brightness (white light scales the
 * channels alike, so the chromaticity is kept) and then compared; too dark to tell, they agree
 * (Jost et al.: colour helps registration once it is intrinsic). A cell no light coloured (each
 * shadowed there) agrees with any: with one light, half of each view has no colour, and a pair
 * across that half would otherwise never couple (a 4-view scan with one light failed, 4% of the
 * overlap coupled). */
static int colours_agree(const struct reg_params *p, const struct reg_cell *ca,
                         const struct reg_cell *cb)
{
    if (!p->use_colour || reg_cell_uncoloured(ca) || reg_cell_uncoloured(cb))
        return 1;
    const uint8_t *a = ca->rgb, *b = cb->rgb;
    double scale = 1.0;
    if (!p->colour_intrinsic) {
        double sa = (double)a[0] + a[1] + a[2], sb = (double)b[0] + b[1] + b[2];
        if (sa < REG_COLOUR_MIN_DN || sb < REG_COLOUR_MIN_DN)
            return 1;
        scale = sb / sa;
    }
    for (int c = 0; c < 3; c++)
        if (fabs(a[c] * scale - b[c]) > p->max_colour_dn)
            return 0;
    return 1;
}

/* The axis as calibrated: a point on it at the table (@p a0) and its unit direction (@p d0). */
static void calibrated_axis(const struct reg_ctx *r, vec3 *a0, vec3 *d0)
{
    *a0 = v3_from(r->calib.axis_point_mm);
    *d0 = v3_norm(v3_from(r->calib.axis_dir));
}

/* The calibration with the axis the unknowns have now (r->a, r->d) in place of the calibrated. */
static void calib_at_axis(const struct reg_ctx *r, struct scan_calib *c)
{
    *c = r->calib;
    c->axis_point_mm[0] = r->a.x, c->axis_point_mm[1] = r->a.y, c->axis_point_mm[2] = r->a.z;
    c->axis_dir[0] = r->d.x, c->axis_dir[1] = r->d.y, c->axis_dir[2] = r->d.z;
}

int reg_begin(struct reg_ctx *r, const struct reg_params *p, const struct scan_calib *c,
              uint32_t views, uint32_t passes, uint32_t width, uint32_t height)
{
    if (views == 0 || views > REG_MAX_VIEWS || width == 0 || height == 0 || passes == 0 ||
        passes > 2 || views % passes != 0)
        return -E2BIG;
    /* the solution and the views' bookkeeping; not the samples (each view writes its own) */
    mem_fill(&r->p, 0, sizeof(*r) - offsetof(struct reg_ctx, p));
    r->p = *p;
    r->calib = *c;
    r->views = views;
    r->passes = passes;
    r->per_pass = views / passes;
    r->stride = p->sample_stride > 0 ? p->sample_stride : 1;
    for (;;) {
        r->gw = (width + r->stride - 1) / r->stride;
        r->gh = (height + r->stride - 1) / r->stride;
        if ((uint64_t)r->gw * r->gh * views <= REG_MAX_CELLS)
            break;
        r->stride++; /* terminates: REG_MAX_CELLS / REG_MAX_VIEWS >= 64 (hal_limits.h) */
    }
    calibrated_axis(r, &r->a, &r->d);
    for (uint32_t v = 0; v < views; v++)
        r->group[v] = v >= r->per_pass; /* the second pass */
    return 0;
}

/* A cell without a colour (reg_cell_uncoloured). */
static void cell_uncoloured(struct reg_cell *cl)
{
    memset(cl->rgb, 0, sizeof(cl->rgb));
    cl->hue[0] = REG_NO_HUE, cl->hue[1] = REG_UNCOLOURED;
}

/* A cell's colour: the mean of the valid pixels over the stride's square centred on it (a box
 * filter of the stride's width: at an even stride the square's edge pixels weigh a half), not the
 * one pixel under it. A point sample puts a paint boundary at the cell where it is seen, half a
 * cell either side of where it is, and one boundary seen at one phase of the grid is seen there
 * every time: the colour search placed the views after a slip 0.2 to 0.6 mm off by it (measured
 * on the box of data/objects with exact poses: 0.5 mm at a stride of 4, 0.2 at 2, 0 at 1); the
 * box-filtered cell holds the share of each paint, which bilinear sampling (reg_place.c) turns
 * back into where the boundary is: 0.1 mm. */
static void cell_colour(const struct decode_maps *m, const uint8_t *rgb, const float *confidence,
                        uint32_t stride, uint32_t px, uint32_t py, struct reg_cell *cl)
{
    const int half = (int)stride / 2, even = stride % 2 == 0;
    double sum[3] = {0.0, 0.0, 0.0}, hue_sum[2] = {0.0, 0.0}, weight = 0.0;
    for (int dy = -half; dy <= half; dy++) {
        long y = (long)py + dy;
        if (y < 0 || y >= (long)m->height)
            continue;
        for (int dx = -half; dx <= half; dx++) {
            long x = (long)px + dx;
            size_t i = (size_t)y * m->width + (size_t)x;
            if (x < 0 || x >= (long)m->width || m->reason[i] != SCAN_VALID ||
                (confidence != NULL && confidence[i] < 0.0f))
                continue;
            double w = (even && (dy == -half || dy == half) ? 0.5 : 1.0) *
                       (even && (dx == -half || dx == half) ? 0.5 : 1.0);
            const double px_rgb[3] = {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]};
            double h[2];
            reg_hue_of(px_rgb, h); /* a pixel too dark for a hue counts as grey */
            for (int c = 0; c < 3; c++)
                sum[c] += w * px_rgb[c];
            hue_sum[0] += w * h[0], hue_sum[1] += w * h[1];
            weight += w;
        }
    }
    if (weight <= 0.0) { /* every light shadowed there: no colour to compare (colours_agree) */
        cell_uncoloured(cl);
        return;
    }
    double mean[3], h[2];
    for (int c = 0; c < 3; c++) {
        mean[c] = sum[c] / weight;
        cl->rgb[c] = (uint8_t)lround(mean[c]);
    }
    /* The hue of each pixel, averaged: a cell across a paint boundary holds each paint's hue by
     * its share of the cell, whatever their brightness, so that the boundary lies where the
     * shares are even in every view. The hue of the mean colour leans towards the brighter,
     * more saturated paint by a share of the cell's footprint on the object, which a view seeing
     * the surface obliquely stretches: measured on the box of data/objects slipped 30 mm, the
     * colour search placed the views after the slip 0.43 mm off along the faces. */
    if (!reg_hue_of(mean, h)) {
        cl->hue[0] = REG_NO_HUE, cl->hue[1] = 0;
        return;
    }
    for (int c = 0; c < 2; c++)
        cl->hue[c] = (int16_t)lround(32767.0 * fmax(-1.0, fmin(1.0, hue_sum[c] / weight)));
}

int reg_add_view(struct reg_ctx *r, uint32_t index, int32_t angle_mdeg, const struct decode_maps *m,
                 const struct tri_range *range, const uint8_t *rgb, const float *confidence)
{
    if (index >= r->views || (m->width + r->stride - 1) / r->stride != r->gw ||
        (m->height + r->stride - 1) / r->stride != r->gh)
        return -EINVAL;
    struct reg_cell *out = reg_view_cells(r, index);
    mem_prefault(out, (size_t)r->gw * r->gh * sizeof(*out));
    r->valid_cells[index] = 0;
    for (uint32_t y = 0; y < r->gh; y++) {
        for (uint32_t x = 0; x < r->gw; x++) {
            size_t i = (size_t)y * r->stride * m->width + (size_t)x * r->stride;
            struct reg_cell *cl = &out[(size_t)y * r->gw + x];
            cl->valid = m->reason[i] == SCAN_VALID;
            r->valid_cells[index] += cl->valid;
            memcpy(cl->xyz, &range->xyz_mm[3 * i], sizeof(cl->xyz));
            memcpy(cl->normal, &range->normal[3 * i], sizeof(cl->normal));
            if (cl->valid) /* no other cell's colour is ever read: 86% of make run's */
                cell_colour(m, rgb, confidence, r->stride, x * r->stride, y * r->stride, cl);
            else
                cell_uncoloured(cl);
        }
    }
    r->reported_mdeg[index] = angle_mdeg;
    r->present[index] = 1;
    return 0;
}

/* Neighbouring views of each pass: each with the next, the last with the first (the views of
 * a pass go round). */
static void make_edges(struct reg_ctx *r)
{
    r->edges = 0;
    uint32_t n = r->per_pass;
    for (uint32_t pass = 0; pass < r->passes; pass++)
        for (uint32_t k = 0; k < n && n >= 2; k++) {
            uint32_t i = pass * n + k, j = pass * n + (k + 1) % n;
            if (n == 2 && k == 1)
                break; /* two views: one pair */
            if (!r->present[i] || !r->present[j] || r->cut_after[i])
                continue;
            r->edge_from[r->edges] = i;
            r->edge_to[r->edges] = j;
            r->edges++;
        }
}

/* R(d, angle) as a row-major matrix. */
static void axis_rotation(vec3 d, double angle, double rot[9])
{
    const double x[6] = {d.x * angle, d.y * angle, d.z * angle, 0.0, 0.0, 0.0};
    struct frame_xform f;
    frame_from_small_motion(x, &f);
    memcpy(rot, f.rot, sizeof(f.rot));
}

/* Unknowns: the angle of each view but the first of its pass (the gauge of that pass's frame),
 * then the axis. @retval the unknown of view @p v's angle, -1 for a first view */
static int angle_param(struct reg_ctx *r, uint32_t v)
{
    uint32_t pass = v / r->per_pass;
    return v % r->per_pass == 0 ? -1 : (int)(v - 1 - pass);
}

int reg_turn_registered(const struct reg_ctx *r, uint32_t v)
{
    return v < r->views && r->present[v] && v % r->per_pass != 0 && !r->from_table[v];
}

static uint32_t n_params(struct reg_ctx *r)
{
    return r->views - r->passes + 4;
}

/* Add one residual with @p jac entries at @p idx (negative: a fixed angle) to the equations. */
static void add_residual(struct reg_ctx *r, const int idx[6], const double jac[6], double res,
                         double weight)
{
    const uint32_t n = n_params(r);
    for (int s = 0; s < 6; s++) {
        if (idx[s] < 0)
            continue;
        for (int t = 0; t < 6; t++)
            if (idx[t] >= 0)
                r->normal_a[(size_t)idx[s] * n + (size_t)idx[t]] += weight * jac[s] * jac[t];
        r->normal_b[idx[s]] += weight * jac[s] * res;
    }
}

/* The Huber threshold of the pairs (mm), a third of max_pair_mm; also the scale the axis's prior
 * is weighed in, so that it holds the axis near the calibrated one as firmly as its bounds
 * (max_axis_*) do. */
static double huber_mm(const struct reg_ctx *r)
{
    return r->p.max_pair_mm / 3.0;
}

/* A pair's weight: Huber's. */
static double w_of(const struct reg_ctx *r, double res)
{
    return fabs(res) <= huber_mm(r) ? 1.0 : huber_mm(r) / fabs(res);
}

/* The pairs from view @p src to view @p dst at the current unknowns, gated at @p gate_mm:
 * counted into @p st and, when @p solve, added to the normal equations. */
static void pair_views(struct reg_ctx *r, uint32_t src, uint32_t dst, double gate_mm, int solve,
                       struct reg_edge_stats *st)
{
    const double min_cos = cos(r->p.max_normal_deg * M_PI / 180.0);
    const double side_per_z = r->stride / r->calib.cam_fx_px; /* a sample's side per mm of depth */
    double rot[9];
    axis_rotation(r->d, r->theta[dst] - r->theta[src], rot);
    vec3 e1, e2;
    v3_across(r->d, &e1, &e2);
    vec3 r_e1 = m3_mul(rot, e1), r_e2 = m3_mul(rot, e2);
    struct scan_calib c; /* the object frame at the unknowns: both ways in one frame */
    struct frame_xform dst_pose;
    calib_at_axis(r, &c);
    frame_object_from_camera_rad(&c, r->theta[dst], &dst_pose);
    const int axis = (int)(r->views - r->passes);
    int idx[6] = {angle_param(r, src), angle_param(r, dst), axis, axis + 1, axis + 2, axis + 3};
    const struct reg_cell *from = reg_view_cells(r, src), *to = reg_view_cells(r, dst);
    for (size_t k = 0; k < reg_cell_count(r); k++) {
        const struct reg_cell *cp = &from[k];
        if (!cp->valid)
            continue;
        vec3 pa = v3_sub(v3(cp->xyz[0], cp->xyz[1], cp->xyz[2]), r->a);
        vec3 rpa = m3_mul(rot, pa), p = v3_add(r->a, rpa);
        if (p.z <= 1.0)
            continue;
        double fu, fv;
        camray_project(&r->calib, p, &fu, &fv);
        long u = lround(fu / r->stride), v = lround(fv / r->stride);
        if (u < 0 || v < 0 || u >= (long)r->gw || v >= (long)r->gh)
            continue;
        const struct reg_cell *cq = &to[(size_t)v * r->gw + (size_t)u];
        vec3 nq = v3(cq->normal[0], cq->normal[1], cq->normal[2]);
        vec3 n = m3_mul(rot, v3(cp->normal[0], cp->normal[1], cp->normal[2]));
        /* The overlap: samples landing on a surface of the other view that faces the same way.
         * One landing on another face (a side the other view sees, this one hides behind) says
         * nothing about the match: a box seen from 90 degrees apart shares one face only. */
        if (!cq->valid || v3_dot(n, nq) < min_cos)
            continue;
        int side = fabs(v3_dot(nq, r->d)) < REG_SIDE_COS;
        st->overlap++;
        st->side_overlap += (uint32_t)side;
        vec3 q = v3(cq->xyz[0], cq->xyz[1], cq->xyz[2]);
        vec3 diff = v3_sub(p, q);
        double dist = v3_len(diff);
        int ok = dist <= gate_mm && colours_agree(&r->p, cp, cq);
        double res = v3_dot(diff, nq);
        double cap = fmin(res * res, r->p.max_pair_mm * r->p.max_pair_mm);
        st->trunc_sq += ok ? cap : r->p.max_pair_mm * r->p.max_pair_mm;
        if (!ok)
            continue;
        st->coupled++;
        st->side_coupled += (uint32_t)side;
        st->sq += res * res;
        vec3 along = v3_cross(r->d, rpa); /* a turn's motion of the point, per radian */
        double dth = v3_dot(nq, along), w = w_of(r, res);
        st->turn_seen += w * dth * dth, st->turn_whole += w * v3_dot(along, along);
        double side_mm = side_per_z * cq->xyz[2]; /* the sample's, face on */
        st->area_mm2 += side_mm * side_mm;
        const vec3 n_obj = m3_mul(dst_pose.rot, nq);
        st->slide[0] += n_obj.x * n_obj.x, st->slide[1] += n_obj.x * n_obj.y;
        st->slide[2] += n_obj.y * n_obj.y;
        if (!solve)
            continue;
        vec3 tilt1 = v3_sub(v3_cross(e1, rpa), m3_mul(rot, v3_cross(e1, pa)));
        vec3 tilt2 = v3_sub(v3_cross(e2, rpa), m3_mul(rot, v3_cross(e2, pa)));
        double jac[6] = {-dth,
                         dth,
                         v3_dot(nq, v3_sub(e1, r_e1)),
                         v3_dot(nq, v3_sub(e2, r_e2)),
                         v3_dot(nq, tilt1),
                         v3_dot(nq, tilt2)};
        const vec3 shift[2] = {v3_sub(e1, r_e1), v3_sub(e2, r_e2)}; /* of the axis along e */
        for (int k = 0; k < 2; k++) {
            r->shift_seen[k] += w * jac[2 + k] * jac[2 + k];
            r->shift_whole[k] += w * v3_dot(shift[k], shift[k]);
        }
        add_residual(r, idx, jac, res, w);
    }
}

/* One pass over every edge, both directions. */
static void pass(struct reg_ctx *r, double gate_mm, int solve)
{
    if (solve) {
        uint32_t n = n_params(r);
        memset(r->normal_a, 0, (size_t)n * n * sizeof(double));
        memset(r->normal_b, 0, n * sizeof(double));
        memset(r->shift_seen, 0, sizeof(r->shift_seen));
        memset(r->shift_whole, 0, sizeof(r->shift_whole));
    }
    for (uint32_t e = 0; e < r->edges; e++) {
        memset(&r->stats[e], 0, sizeof(r->stats[e]));
        pair_views(r, r->edge_from[e], r->edge_to[e], gate_mm, solve, &r->stats[e]);
        pair_views(r, r->edge_to[e], r->edge_from[e], gate_mm, solve, &r->stats[e]);
    }
}

/* sqrt(mean truncated squared residual) over every overlap: lower is better, and dropping
 * pairs does not lower it (a dropped pair counts max_pair_mm). */
static double score(struct reg_ctx *r)
{
    double sum = 0.0;
    uint64_t n = 0;
    for (uint32_t e = 0; e < r->edges; e++) {
        sum += r->stats[e].trunc_sq;
        n += r->stats[e].overlap;
    }
    return n > 0 ? sqrt(sum / (double)n) : 0.0;
}

/* The angle the table reported for view @p v, in radians. */
static double reported_rad(struct reg_ctx *r, uint32_t v)
{
    return r->reported_mdeg[v] * (M_PI / 180000.0);
}

/* The scale of a pair's residual (mm): the residual of the pairs of the last pass, between
 * 0.01 mm and the Huber threshold of pair_views. */
static double pair_sigma_mm(const struct reg_ctx *r)
{
    double sq = 0.0;
    uint64_t coupled = 0;
    for (uint32_t e = 0; e < r->edges; e++) {
        sq += r->stats[e].sq;
        coupled += r->stats[e].coupled;
    }
    double rms = coupled > 0 ? sqrt(sq / (double)coupled) : huber_mm(r);
    return fmin(fmax(rms, 0.01), huber_mm(r));
}

/* The weight of the table's angles in the normal equations: a pseudo-observation of standard
 * deviation angle_accuracy_deg per angle, in the units of the pairs (whose residuals have
 * pair_sigma_mm): w = (sigma_pair / sigma_angle)^2. */
static double angle_prior_weight(const struct reg_ctx *r)
{
    double sigma = r->p.angle_accuracy_deg * M_PI / 180.0;
    return sigma > 0.0 ? pow(pair_sigma_mm(r) / sigma, 2.0) : 0.0;
}

/* A prior's standard deviation: the stated @p accuracy, never looser than a third of the
 * @p bound a solution may not pass (so the bound is three standard deviations); a third when
 * none is stated. */
static double prior_sigma(double accuracy, double bound)
{
    return accuracy > 0.0 ? fmin(accuracy, bound / 3.0) : bound / 3.0;
}

/* The turntable's angles and the calibrated axis as a prior (a regularised least squares, the
 * MAP estimate under Gaussian errors): each angle held to the reported one with
 * angle_accuracy_deg (weighed against the pairs' own residual), the axis to the calibrated one
 * with axis_accuracy_mm and axis_tilt_accuracy_deg. Where the pairs fix an unknown
 * (thousands of them, each as strong as the prior) the prior changes nothing; where they do not (a
 * surface of revolution turns into itself, so the pairs do not see the turn), it keeps the unknown
 * at the table's and the calibration's values instead of letting it wander. */
static void add_prior(struct reg_ctx *r)
{
    const uint32_t n = n_params(r);
    const double w_angle = angle_prior_weight(r);
    for (uint32_t v = 0; v < r->views; v++) {
        int i = angle_param(r, v);
        if (i < 0)
            continue;
        r->normal_a[(size_t)i * n + (size_t)i] += w_angle;
        r->normal_b[i] += w_angle * (r->theta[v] - reported_rad(r, v));
    }
    vec3 e1, e2, a0, d0;
    v3_across(r->d, &e1, &e2);
    calibrated_axis(r, &a0, &d0);
    vec3 da = v3_sub(r->a, a0), dd = v3_sub(r->d, d0);
    /* the unknowns' own measures of how far the axis is: shifts along e1, e2 and the tilts
     * that gauss_newton_step applies (d += (e1 t1 + e2 t2) x d moves d by -t1 e2 + t2 e1) */
    const double off[4] = {v3_dot(da, e1), v3_dot(da, e2), -v3_dot(dd, e2), v3_dot(dd, e1)};
    /* views alike as they stand cannot place the axis (reg_views_alike): held where calibrated */
    const double hold = r->views_alike || r->axis_held ? 1e-3 : 1.0;
    const double sigma_shift =
        hold * fmax(prior_sigma(r->p.axis_accuracy_mm, r->p.max_axis_shift_mm), 1e-3);
    const double sigma_tilt =
        hold * fmax(prior_sigma(r->p.axis_tilt_accuracy_deg, r->p.max_axis_tilt_deg), 1e-3) * M_PI /
        180.0;
    for (int k = 0; k < 4; k++) {
        uint32_t i = r->views - r->passes + (uint32_t)k;
        double w = pow(huber_mm(r) / (k < 2 ? sigma_shift : sigma_tilt), 2.0);
        r->normal_a[(size_t)i * n + i] += w;
        r->normal_b[i] += w * off[k];
    }
}

/* Pairs barely see a turn about the axis where the share of a turn's motion that lies across the
 * surface is below REG_TURN_SEEN, in root mean square: the object's shape turns into itself
 * there, as a sphere or a cylinder on the axis does. Measured on the simulator at 1280 x 960
 * (a view's pairs): the normals' noise alone gives 0.03 to 0.04 (sphere, cylinder, torus about
 * the axis), a box or the bunny 0.37 to 0.6; a feature that breaks the symmetry on a twentieth
 * of the surface (a handle) still lifts it above 0.1. */
#define REG_TURN_SEEN 0.1

/* A view's pairs tell its turn better than the table only where they couple over enough of the
 * surface: their errors are not independent (a face's depth bias is shared by all of its
 * samples), so they count as one observation per REG_TURN_PATCH_MM2 of coupled surface, not
 * one per sample. The pairs' information on the turn is then the mean over coupled samples of
 * (n . d x (p - a))^2 (mm^2 per rad^2) times area / patch, against the table's in the same units,
 * (pair sigma / angle_accuracy_deg)^2 (angle_prior_weight); the weaker loses. Measured on the
 * object corpus at 1280 x 960 (2026-12-06, the axis held at 0.1 mm): the L-bracket 30, 20 mm
 * off the axis in 4 views coupled view 2 with its neighbours over 213 mm^2 (202 samples), 0.28
 * of the table's information at this patch, and the pairs turned it 2.58 degrees from the exact
 * table (the model 0.303 mm from the truth, 0.091 at the table's angle); the next weakest view of
 * the corpus had 1.4 times the table's (the cone's beside a slip), and every turn that corrected
 * a table 1 or 2 degrees off by more than a quarter degree 7.2 times or more (the hex nut's). */
#define REG_TURN_PATCH_MM2 400.0

/* A pair of neighbours that shares no side (REG_SIDE_MIN) and whose coupled samples barely see a
 * turn about the axis (REG_TURN_SEEN, as a view's: only a top, which a turn slides into itself,
 * or nothing in common) holds no turn between its views: the stepped block's below, 0.03 to
 * 0.04 (the normals' noise); the thin box's end-on pairs, 280 to 440 samples on its thin sides,
 * 0.07 to 0.08, which still corrected its views from a table 2 degrees off (0.089 mm from the
 * truth; held, 0.153). Two or more such pairs cut a pass's ring
 * into arcs whose turns against each other no pair sees: the solve's normal equations are
 * blind along them, and the depth's small bias decided. Measured (2026-12-05): the stepped
 * block of data/objects stood 30, 20 mm off the axis in 6 views, its pairs 120 -> 180 and
 * 300 -> 0 degrees sharing only its steps' tops, turned its last three views 0.58 degrees from
 * the exact table for a residual 0.7% lower (0.3809 -> 0.3781 mm): the model 0.123 mm from the
 * truth, 0.067 centred. So each arc but the one with the pass's first view is held to that one,
 * the mean of its views' corrections from the table's angles to that arc's (REG_ARC_HOLD_DEG):
 * the table's angles across the cuts, the views within an arc registered as ever. Into
 * @p arc (per view: its arc, 0 the first's) @retval the arcs held (those but the first) */
#define REG_ARC_HOLD_DEG 0.001
static uint32_t find_arcs(const struct reg_ctx *r, uint32_t pass, uint8_t arc[REG_MAX_VIEWS])
{
    const uint32_t n = r->per_pass, first = pass * n;
    static int out[REG_MAX_VIEWS]; /* static: off the stack */
    static uint8_t blind[REG_MAX_VIEWS];
    uint32_t blinds = 0, at = 0;
    if (n < 3)
        return 0;
    for (uint32_t k = 0; k < n; k++)
        out[k] = -1;
    for (uint32_t e = 0; e < r->edges; e++)
        if (r->edge_from[e] / n == pass)
            out[r->edge_from[e] - first] = (int)e;
    for (uint32_t k = 0; k < n; k++) {
        const struct reg_edge_stats *st = out[k] >= 0 ? &r->stats[out[k]] : NULL;
        blind[k] = st == NULL || (st->side_overlap < REG_SIDE_MIN &&
                                  st->turn_seen <= REG_TURN_SEEN * REG_TURN_SEEN * st->turn_whole);
        blinds += blind[k];
    }
    if (blinds < 2)
        return 0;
    for (uint32_t k = 0; k < n; k++) {
        arc[first + k] = (uint8_t)at;
        at += blind[k];
    }
    if (!blind[n - 1]) /* the closing pair joins the last arc to the first */
        for (uint32_t k = 0; k < n; k++)
            if (arc[first + k] == at)
                arc[first + k] = 0;
    return blinds - 1;
}

/* The arcs of every pass that find_arcs holds. */
static uint32_t arcs_held(const struct reg_ctx *r)
{
    static uint8_t arc[REG_MAX_VIEWS];
    uint32_t held = 0;
    for (uint32_t pass = 0; pass < r->passes; pass++)
        held += find_arcs(r, pass, arc);
    return held;
}

/* The arcs of every pass held to their pass's first (find_arcs), in the normal equations. */
static void hold_arcs(struct reg_ctx *r)
{
    static uint8_t arc[REG_MAX_VIEWS];
    static double g[REG_PARAMS]; /* static: off the stack */
    const uint32_t n = n_params(r);
    const double sigma = REG_ARC_HOLD_DEG * M_PI / 180.0, w = pow(pair_sigma_mm(r) / sigma, 2.0);
    for (uint32_t pass = 0; pass < r->passes; pass++) {
        uint32_t arcs = find_arcs(r, pass, arc), first = pass * r->per_pass;
        for (uint32_t a = 1; a <= arcs; a++) {
            double count[2] = {0.0, 0.0}, res = 0.0;
            for (uint32_t v = first; v < first + r->per_pass; v++)
                if (r->present[v] && (arc[v] == a || arc[v] == 0))
                    count[arc[v] == a] += 1.0;
            if (count[0] == 0.0 || count[1] == 0.0)
                continue;
            memset(g, 0, n * sizeof(g[0]));
            for (uint32_t v = first; v < first + r->per_pass; v++) {
                if (!r->present[v] || (arc[v] != a && arc[v] != 0))
                    continue;
                double share = arc[v] == a ? 1.0 / count[1] : -1.0 / count[0];
                res += share * (r->theta[v] - reported_rad(r, v));
                if (angle_param(r, v) >= 0)
                    g[angle_param(r, v)] = share;
            }
            for (uint32_t i = 0; i < n; i++) {
                for (uint32_t k = 0; k < n && g[i] != 0.0; k++)
                    r->normal_a[(size_t)i * n + k] += w * g[i] * g[k];
                r->normal_b[i] += w * g[i] * res;
            }
        }
    }
}

/* Solve and apply one Gauss-Newton step. @retval the largest angle change (rad) */
static double gauss_newton_step(struct reg_ctx *r)
{
    const uint32_t n = n_params(r);
    add_prior(r);
    hold_arcs(r);
    /* A little damping keeps unknowns the data barely see (the axis of two views) in place. */
    double trace = 0.0;
    for (uint32_t i = 0; i < n; i++)
        trace += r->normal_a[(size_t)i * n + i];
    for (uint32_t i = 0; i < n; i++)
        r->normal_a[(size_t)i * n + i] += 1e-6 * trace / n + 1e-3 * r->normal_a[(size_t)i * n + i];
    for (uint32_t i = 0; i < n; i++)
        r->normal_b[i] = -r->normal_b[i];
    if (lsq_solve(n, r->normal_a, r->normal_b, r->step_x) != 0)
        return 0.0;
    double largest = 0.0;
    for (uint32_t v = 0; v < r->views; v++) {
        if (angle_param(r, v) < 0)
            continue;
        r->theta[v] += r->step_x[angle_param(r, v)];
        largest = fmax(largest, fabs(r->step_x[angle_param(r, v)]));
    }
    vec3 e1, e2;
    v3_across(r->d, &e1, &e2);
    const double *ax = &r->step_x[r->views - r->passes];
    r->a = v3_add(r->a, v3_add(v3_scale(e1, ax[0]), v3_scale(e2, ax[1])));
    r->d = v3_norm(v3_add(r->d, v3_cross(v3_add(v3_scale(e1, ax[2]), v3_scale(e2, ax[3])), r->d)));
    return fmax(largest, fmax(fabs(ax[2]), fabs(ax[3])));
}

/* A view whose pairs barely see a turn about the axis (REG_TURN_SEEN), or see it over too little
 * of the surface to outweigh the table (REG_TURN_PATCH_MM2), keeps the table's angle exactly:
 * what the pairs say of it is the noise or the bias of the surface, and the registration says
 * so (reg_view). */
static void keep_unfixed_turns(struct reg_ctx *r)
{
    const double w_table = angle_prior_weight(r);
    for (uint32_t v = 0; v < r->views; v++) {
        struct reg_edge_stats sum = {0}; /* over the view's pairs of the last pass */
        for (uint32_t e = 0; e < r->edges; e++)
            if (r->edge_from[e] == v || r->edge_to[e] == v) {
                sum.turn_seen += r->stats[e].turn_seen;
                sum.turn_whole += r->stats[e].turn_whole;
                sum.area_mm2 += r->stats[e].area_mm2;
                sum.coupled += r->stats[e].coupled;
            }
        double seen = sum.turn_whole > 0.0 ? sum.turn_seen / sum.turn_whole : 0.0;
        double told =
            sum.coupled > 0 ? sum.turn_seen / sum.coupled * sum.area_mm2 / REG_TURN_PATCH_MM2 : 0.0;
        int turning = angle_param(r, v) >= 0 && r->present[v];
        int unseen = seen < REG_TURN_SEEN * REG_TURN_SEEN;
        r->little_shared[v] = turning && !unseen && told < w_table;
        r->from_table[v] = turning && (unseen || r->little_shared[v]);
        if (r->from_table[v])
            r->theta[v] = reported_rad(r, v);
    }
    /* The axis moves the views apart across the surface the same way (its shift along e turns
     * into (I - R) e between views): where the pairs see no view's turn, or no shift of the axis
     * (a box whose views share only its top), the calibrated axis is kept. */
    uint32_t unfixed = 0;
    for (uint32_t v = 0; v < r->views; v++)
        unfixed += r->from_table[v];
    r->axis_from_calib = (unfixed > 0 && unfixed + r->passes >= r->views) || /* no turn seen */
                         r->views_alike;
    for (int k = 0; k < 2; k++)
        if (r->shift_whole[k] > 0.0 &&
            r->shift_seen[k] < REG_TURN_SEEN * REG_TURN_SEEN * r->shift_whole[k])
            r->axis_from_calib = 1;
    if (r->axis_from_calib)
        calibrated_axis(r, &r->a, &r->d);
}

/* Each view that keeps the table's angle, its shape not fixing its turn, turned where its paint
 * agrees with its registered neighbours' (reg_turn_by_paint), within the table's accuracy. */
static void turn_unfixed_by_paint(struct reg_ctx *r)
{
    double span = fmin(r->p.max_correction_deg, 3.0 * r->p.angle_accuracy_deg);
    int was = r->use_solution;
    r->use_solution = 1; /* the poses at the solved angles and axis */
    for (uint32_t v = 0; v < r->views; v++)
        r->by_paint[v] = r->from_table[v] && reg_turn_by_paint(r, v, span);
    r->use_solution = was;
}

/* The F value (hold_axis_unless_it_pays) above which moving the axis gains the pairs more than
 * their own errors explain. Measured on 10 parts of the object corpus in 8 views, the table exact
 * and 2 degrees off (2026-12-06): with the calibrated axis the truth (the simulator's), F was at
 * most 0.29, and the free axis had moved 0.08 to 0.09 mm for the thin box (its model 0.070 and
 * 0.084 mm from the truth; held, 0.060); the calibration made 0.1 mm off across, F 0.02 to 1.51
 * (held: the bunny 0.045 -> 0.052 mm, the thin box still better held, 0.084 -> 0.059); 0.3 mm
 * off, F 2.9 to 15 but for a gear 2 degrees off (0.72). A textbook 95% point of F(4, n) (2.5)
 * held every axis 0.1 mm off; 1 frees those whose pairs see it best (the bunny, the box). */
#define REG_AXIS_F 1.0

/* The unknowns at the turntable's answer. */
static void start_from_table(struct reg_ctx *r)
{
    for (uint32_t v = 0; v < r->views; v++)
        r->theta[v] = reported_rad(r, v);
    calibrated_axis(r, &r->a, &r->d);
}

/* How far the solution is from the calibrated axis; "" or why it is refused. */
static void check_bounds(struct reg_ctx *r, struct reg_report *rep)
{
    vec3 a0, d0;
    calibrated_axis(r, &a0, &d0);
    vec3 da = v3_sub(r->a, a0);
    da = v3_sub(da, v3_scale(d0, v3_dot(da, d0))); /* along the axis changes nothing */
    rep->axis_shift_mm = v3_len(da);
    double c = v3_dot(r->d, d0);
    rep->axis_tilt_deg = acos(c > 1.0 ? 1.0 : c) * 180.0 / M_PI;
    rep->refused[0] = '\0';
    for (uint32_t v = 0; v < r->views; v++) {
        double corr = (r->theta[v] - reported_rad(r, v)) * 180.0 / M_PI;
        if (r->present[v] && fabs(corr) > r->p.max_correction_deg) {
            snprintf(rep->refused, sizeof(rep->refused),
                     "view %u would turn %.2f deg from its reported angle, more than "
                     "max_correction_deg = %g",
                     (unsigned)v, corr, r->p.max_correction_deg);
            return;
        }
    }
    if (rep->axis_shift_mm > r->p.max_axis_shift_mm)
        snprintf(rep->refused, sizeof(rep->refused),
                 "the axis would move %.2f mm, more than max_axis_shift_mm = %g",
                 rep->axis_shift_mm, r->p.max_axis_shift_mm);
    else if (rep->axis_tilt_deg > r->p.max_axis_tilt_deg)
        snprintf(rep->refused, sizeof(rep->refused),
                 "the axis would tilt %.2f deg, more than max_axis_tilt_deg = %g",
                 rep->axis_tilt_deg, r->p.max_axis_tilt_deg);
}

/* Per-view numbers, the worst view, the loop closure and the first pair that does not match,
 * from the last pass. */
static void summarise(struct reg_ctx *r, struct reg_report *rep)
{
    uint64_t coupled = 0, loop_coupled = 0;
    double sq = 0.0, loop_sq = 0.0;
    rep->failed_view = rep->failed_against = -1;
    rep->apart_view = rep->apart_against = -1;
    rep->apart_pairs = 0;
    rep->arcs_held = r->use_solution ? arcs_held(r) : 0;
    for (uint32_t e = 0; e < r->edges; e++) {
        const struct reg_edge_stats *st = &r->stats[e];
        coupled += st->coupled;
        sq += st->sq;
        if (rep->failed_view < 0 && reg_edge_fails(r, e)) {
            rep->failed_view = (int)r->edge_to[e];
            rep->failed_against = (int)r->edge_from[e];
            rep->failed_share = reg_edge_share(r, st);
        }
        if (reg_edge_apart(r, e) && rep->apart_pairs++ == 0) {
            rep->apart_view = (int)r->edge_to[e];
            rep->apart_against = (int)r->edge_from[e];
        }
        if (r->edge_to[e] % r->per_pass == 0 && r->per_pass > 2) { /* a closing pair */
            loop_sq += st->sq;
            loop_coupled += st->coupled;
        }
    }
    rep->loop_rms_mm = loop_coupled > 0 ? sqrt(loop_sq / (double)loop_coupled) : 0.0;
    rep->rms_mm = coupled > 0 ? sqrt(sq / (double)coupled) : 0.0;
    rep->worst_rms_mm = -1.0;
    /* counted afresh: a moved object's views are solved again (place_moved_views), and each
     * solve ends here */
    rep->turns_from_table = rep->turns_little_shared = rep->turns_by_paint = 0;
    for (uint32_t v = 0; v < r->views; v++) {
        rep->turns_from_table += r->from_table[v], rep->turns_little_shared += r->little_shared[v];
        rep->turns_by_paint += r->use_solution && r->by_paint[v];
    }
    rep->axis_from_calibration = r->axis_from_calib;
    rep->views_alike = r->views_alike;
    for (uint32_t v = 0; v < r->views; v++) {
        struct reg_view rv;
        if (reg_view_pose(r, v, NULL, &rv) == 0 && rv.coupled > 0 &&
            rv.rms_mm > rep->worst_rms_mm) {
            rep->worst_rms_mm = rv.rms_mm;
            rep->worst_view = v;
        }
    }
    if (rep->worst_rms_mm < 0.0)
        rep->worst_rms_mm = 0.0;
}

/* The Gauss-Newton steps from the unknowns as they are, then the turns the shape does not fix
 * kept at the table's angles (or the paint's), the pairs of the working gate. @p wide: from the
 * table's angles, pairs searched wider first; else from a solution, at the working gate. */
static void solve_steps(struct reg_ctx *r, struct reg_report *rep, int wide)
{
    for (uint32_t it = wide ? 0 : 8; it < r->p.iterations + (wide ? 0 : 8); it++) {
        /* wide pairs first, to reach errors of a degree or two, then the working gate */
        double gate = r->p.max_pair_mm * fmax(1.0, 4.0 / (double)(1u << (it < 8 ? it : 8)));
        pass(r, gate, 1);
        rep->iterations = it + 1 - (wide ? 0 : 8);
        if (gauss_newton_step(r) < 1e-5 && gate <= r->p.max_pair_mm) /* 0.0006 deg */
            break;
    }
    keep_unfixed_turns(r);
    turn_unfixed_by_paint(r);
    pass(r, r->p.max_pair_mm, 0);
}

/* The solution's unknowns and what keep_unfixed_turns decided, to try another and come back. */
struct solution {
    double theta[REG_MAX_VIEWS];
    vec3 a, d;
    uint8_t from_table[REG_MAX_VIEWS], little_shared[REG_MAX_VIEWS], by_paint[REG_MAX_VIEWS];
    int axis_from_calib;
};

static void solution_save(const struct reg_ctx *r, struct solution *s)
{
    memcpy(s->theta, r->theta, sizeof(s->theta));
    memcpy(s->from_table, r->from_table, sizeof(s->from_table));
    memcpy(s->little_shared, r->little_shared, sizeof(s->little_shared));
    memcpy(s->by_paint, r->by_paint, sizeof(s->by_paint));
    s->a = r->a, s->d = r->d, s->axis_from_calib = r->axis_from_calib;
}

static void solution_restore(struct reg_ctx *r, const struct solution *s)
{
    memcpy(r->theta, s->theta, sizeof(s->theta));
    memcpy(r->from_table, s->from_table, sizeof(s->from_table));
    memcpy(r->little_shared, s->little_shared, sizeof(s->little_shared));
    memcpy(r->by_paint, s->by_paint, sizeof(s->by_paint));
    r->a = s->a, r->d = s->d, r->axis_from_calib = s->axis_from_calib;
}

/* The pairs' coupled surface as independent observations (REG_TURN_PATCH_MM2 each). */
static double patches(const struct reg_ctx *r)
{
    double area = 0.0;
    for (uint32_t e = 0; e < r->edges; e++)
        area += r->stats[e].area_mm2;
    return area / REG_TURN_PATCH_MM2;
}

/* The axis the pairs moved it to kept only where the move pays for itself: solved again with
 * the axis held where calibrated, the free axis's four unknowns must lower the truncated
 * residual's square by more than chance would over the pairs counted as one observation per
 * REG_TURN_PATCH_MM2 (their errors are a face's depth bias, shared by its samples), the F test
 * F = ((s_held^2 / s_free^2 - 1) / 4) x patches > REG_AXIS_F. */
static void hold_axis_unless_it_pays(struct reg_ctx *r, struct reg_report *rep)
{
    static struct solution free_axis; /* static: off the stack */
    if (r->axis_from_calib || r->views_alike)
        return; /* held already */
    double s_free = score(r), n_obs = patches(r);
    uint32_t iterations = rep->iterations;
    solution_save(r, &free_axis);
    r->axis_held = 1;
    solve_steps(r, rep, 0);
    r->axis_held = 0;
    double s_held = score(r);
    double f = s_free > 0.0 ? (s_held * s_held / (s_free * s_free) - 1.0) / 4.0 * n_obs : 0.0;
    rep->axis_f = fmax(f, 0.0); /* below 0: held, the views fit better (the free solve stopped
                                   in a worse minimum) */
    /* the pairs place the axis; or, held, the views fit no better than at the table's angles,
     * which would keep those (the L-bracket in 12 views, the table exact: 0.294 -> 0.295 mm held,
     * its model 0.069 mm from the truth at the table's angles against 0.063 registered) */
    if (f > REG_AXIS_F || !(s_held < rep->score_before_mm)) {
        solution_restore(r, &free_axis);
        rep->iterations = iterations;
        pass(r, r->p.max_pair_mm, 0);
        return;
    }
    r->axis_from_calib = 1;
    calibrated_axis(r, &r->a, &r->d);
    rep->axis_unpaid = 1;
}

/* Every view's angle and the axis, jointly, from the table's answer; kept when accepted.
 * @p hold_unpaid: the axis held where calibrated unless moving it pays for itself
 * (hold_axis_unless_it_pays). */
static void solve_joint(struct reg_ctx *r, struct reg_report *rep, int hold_unpaid)
{
    make_edges(r);
    start_from_table(r);
    r->views_alike = reg_views_alike(r);
    r->use_solution = 0;
    pass(r, r->p.max_pair_mm, 0);
    rep->score_before_mm = rep->score_after_mm = score(r);
    rep->solved = rep->accepted = 0;
    rep->refused[0] = '\0';
    if (r->p.enabled && r->edges > 0 && r->present[0] && r->present[r->views - r->per_pass] &&
        r->few_samples == 0) {
        rep->solved = 1;
        solve_steps(r, rep, 1);
        rep->axis_unpaid = 0;
        rep->axis_f = 0.0;
        if (hold_unpaid)
            hold_axis_unless_it_pays(r, rep);
        rep->score_after_mm = score(r);
        check_bounds(r, rep);
        rep->accepted = rep->refused[0] == '\0' && rep->score_after_mm < rep->score_before_mm;
        if (rep->refused[0] == '\0' && !rep->accepted)
            snprintf(rep->refused, sizeof(rep->refused),
                     "the residual did not improve (%.3f mm -> %.3f mm)", rep->score_before_mm,
                     rep->score_after_mm);
        if (!rep->accepted) {
            start_from_table(r);
            pass(r, r->p.max_pair_mm, 0);
        }
        r->use_solution = rep->accepted;
    }
    summarise(r, rep);
}

/* The object had moved: group 1 placed freely, near where the table put it (a few millimetres,
 * then a few centimetres away) or, failing that, by the search a second pass is found by
 * (align_second_pass); along what its shape does not hold, by its colour; how far it had moved. */
static void place_moved_views(struct reg_ctx *r, struct reg_report *rep)
{
    int failed = rep->failed_view, against = rep->failed_against;
    double share = rep->failed_share;
    /* each arc registered on its own, the axis free as ever: the views after the move are placed
     * against the arc with view 0, and with its axis held the placement's own turn (0.07 to 0.1
     * degrees of noise) cost more (the thin box of data/objects slipped 6 mm in 8 views, 0.071
     * -> 0.085 mm from the truth; 30 mm, 0.083 -> 0.092) */
    solve_joint(r, rep, 0);
    if (!reg_place_near_table(r, rep->rms_mm, 8.0) && !reg_place_near_table(r, rep->rms_mm, 32.0) &&
        !reg_place_slid_by_colour(r, rep->rms_mm))
        reg_align_group(r, rep);
    if (r->second_aligned && !reg_placement_holds(r) && !r->placed_by_colour &&
        !reg_place_by_colour(r, rep->rms_mm)) {
        r->second_aligned = 0; /* a slide neither shape nor colour sees: it could be anywhere */
        rep->moved_unfixed = 1;
    }
    if (!r->second_aligned) { /* nothing found: the failure as the ring showed it */
        rep->failed_view = failed, rep->failed_against = against, rep->failed_share = share;
        return;
    }
    rep->failed_view = rep->failed_against = -1;
    rep->failed_colour = 0.0;
    rep->moved_view = (int)reg_first_of_group(r);
    for (uint32_t v = 0; v < r->views; v++)
        rep->moved_views += r->group[v];
    const double *m = r->first_from_second.rot;
    double c = (m[0] + m[4] + m[8] - 1.0) / 2.0;
    rep->moved_deg = acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c) * 180.0 / M_PI;
    rep->moved_mm = v3_len(r->first_from_second.origin); /* the frame's origin: on the axis */
    rep->moved_by_colour = r->placed_by_colour;
    rep->second_turned_deg = rep->second_rms_mm = 0.0;
}

/* The most valid samples a view has, when every view has fewer than REG_MIN_VIEW_SAMPLES and
 * one has some; else 0. An object that small in the camera's image (the bunny 5 mm tall, 8 to
 * 13 samples a view at 1280 x 960) gives its pairs too few samples to couple or to fix a turn
 * (at 20 mm, 150 to 190, every turn was left at the table's for sharing too little), and a
 * pair of them failed as if a view held nothing: no model. A view of nothing among fuller ones
 * still fails. */
static uint32_t few_samples(const struct reg_ctx *r)
{
    uint32_t most = 0;
    for (uint32_t v = 0; v < r->views; v++)
        if (r->present[v] && r->valid_cells[v] > most)
            most = r->valid_cells[v];
    return most < REG_MIN_VIEW_SAMPLES ? most : 0;
}

int reg_solve(struct reg_ctx *r, struct reg_report *rep)
{
    memset(rep, 0, sizeof(*rep));
    rep->stride = r->stride;
    rep->moved_view = -1;
    for (uint32_t v = 0; v < r->views; v++)
        rep->views += r->present[v];
    /* with icp = 0 or one view nothing is registered anyway: said as such (reg_report) */
    r->few_samples = rep->few_samples = r->p.enabled && r->views > 1 ? few_samples(r) : 0;
    memset(r->cut_after, 0, sizeof(r->cut_after));
    memset(r->quiet_break_after, 0, sizeof(r->quiet_break_after));
    r->second_aligned = 0;
    r->placed_by_colour = 0;
    solve_joint(r, rep, 1);
    if (r->few_samples > 0 && r->passes == 1)
        return 0; /* the table's angles: nothing to tell a break or a move by */
    if (r->passes == 2)
        reg_align_group(r, rep);
    else if ((rep->failed_view >= 0 || reg_find_quiet_breaks(r, rep)) && reg_cut_at_the_move(r))
        place_moved_views(r, rep);
    return 0;
}

int reg_view_pose(struct reg_ctx *r, uint32_t v, struct frame_xform *obj_from_cam,
                  struct reg_view *out)
{
    if (v >= r->views || !r->present[v])
        return -EINVAL;
    memset(out, 0, sizeof(*out));
    out->present = 1;
    out->reported_mdeg = r->reported_mdeg[v];
    double theta = r->use_solution ? r->theta[v] : reported_rad(r, v);
    out->angle_deg = theta * 180.0 / M_PI;
    out->correction_deg = out->angle_deg - r->reported_mdeg[v] / 1000.0;
    out->turn_from_table = r->from_table[v];
    out->turn_little_shared = r->little_shared[v];
    out->turn_by_paint = r->use_solution && r->by_paint[v];
    out->placed_freely = r->passes == 1 && r->group[v] && r->second_aligned;
    double sq = 0.0;
    for (uint32_t e = 0; e < r->edges; e++) {
        if (r->edge_from[e] != v && r->edge_to[e] != v)
            continue;
        out->overlap += r->stats[e].overlap;
        out->coupled += r->stats[e].coupled;
        sq += r->stats[e].sq;
    }
    out->rms_mm = out->coupled > 0 ? sqrt(sq / out->coupled) : 0.0;
    if (obj_from_cam != NULL) {
        struct scan_calib c = r->calib;
        if (r->use_solution)
            calib_at_axis(r, &c);
        frame_object_from_camera_rad(&c, theta, obj_from_cam);
        if (r->group[v] && r->second_aligned) { /* into group 0's object frame */
            struct frame_xform in_second = *obj_from_cam;
            frame_compose(&r->first_from_second, &in_second, obj_from_cam);
        }
    }
    return 0;
}

void reg_each_point(struct reg_ctx *r, void (*each)(void *priv, vec3 p_obj), void *priv)
{
    for (uint32_t v = 0; v < r->views; v++) {
        struct frame_xform pose;
        struct reg_view info;
        if (reg_view_pose(r, v, &pose, &info) != 0)
            continue;
        const struct reg_cell *cells = reg_view_cells(r, v);
        for (size_t i = 0; i < reg_cell_count(r); i++)
            if (cells[i].valid)
                each(priv,
                     frame_point(&pose, v3(cells[i].xyz[0], cells[i].xyz[1], cells[i].xyz[2])));
    }
}
