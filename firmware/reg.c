/* Joint registration of a turntable scan's views (reg.h), in static buffers.
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

#include "align.h"
#include "camray.h"
#include "lsq.h"
#include "vec3.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#define REG_PARAMS (REG_MAX_VIEWS + 4u) /* every angle, two shifts, two tilts */
#define REG_EDGES REG_MAX_VIEWS         /* a ring: one edge per view */

/* One kept pixel of a view, in its camera frame. */
struct reg_cell {
    float xyz[3];
    float normal[3];
    uint8_t rgb[3];
    uint8_t valid;
};
_Static_assert(sizeof(struct reg_cell) == 28, "cell layout");

static struct reg_cell cells[REG_MAX_CELLS];
static double normal_a[REG_PARAMS * REG_PARAMS], normal_b[REG_PARAMS], step_x[REG_PARAMS];

/* What the pairs of one edge (both directions) gave in the last pass. */
struct edge_stats {
    uint32_t overlap, coupled;
    double sq, trunc_sq; /* squared residuals of coupled pairs; truncated over the overlap */
};

static struct {
    struct reg_params p;
    struct scan_calib calib;
    uint32_t views, passes, per_pass, stride, gw, gh;
    int32_t reported_mdeg[REG_MAX_VIEWS];
    uint8_t present[REG_MAX_VIEWS];
    double theta[REG_MAX_VIEWS]; /* radians */
    vec3 a, d;                   /* the axis */
    int use_solution;            /* poses from theta, a, d rather than the turntable's */
    uint32_t edges, edge_from[REG_EDGES], edge_to[REG_EDGES];
    struct edge_stats stats[REG_EDGES];
    int second_aligned;          /* the second pass's views go through first_from_second */
    struct frame_xform first_from_second;
} rg;

static size_t cell_count(void)
{
    return (size_t)rg.gw * rg.gh;
}

static struct reg_cell *view_cells(uint32_t v)
{
    return &cells[(size_t)v * cell_count()];
}

int reg_begin(const struct reg_params *p, const struct scan_calib *c, uint32_t views,
              uint32_t passes, uint32_t width, uint32_t height)
{
    if (views == 0 || views > REG_MAX_VIEWS || width == 0 || height == 0 || passes == 0 ||
        passes > 2 || views % passes != 0)
        return -E2BIG;
    memset(&rg, 0, sizeof(rg));
    rg.p = *p;
    rg.calib = *c;
    rg.views = views;
    rg.passes = passes;
    rg.per_pass = views / passes;
    rg.stride = p->sample_stride > 0 ? p->sample_stride : 1;
    for (;;) {
        rg.gw = (width + rg.stride - 1) / rg.stride;
        rg.gh = (height + rg.stride - 1) / rg.stride;
        if ((uint64_t)rg.gw * rg.gh * views <= REG_MAX_CELLS)
            break;
        rg.stride++; /* terminates: REG_MAX_CELLS / REG_MAX_VIEWS >= 64 (hal_limits.h) */
    }
    rg.a = v3_from(c->axis_point_mm);
    rg.d = v3_norm(v3_from(c->axis_dir));
    return 0;
}

int reg_add_view(uint32_t index, int32_t angle_mdeg, const struct decode_maps *m,
                 const struct tri_range *r, const uint8_t *rgb)
{
    if (index >= rg.views || (m->width + rg.stride - 1) / rg.stride != rg.gw ||
        (m->height + rg.stride - 1) / rg.stride != rg.gh)
        return -EINVAL;
    struct reg_cell *out = view_cells(index);
    for (uint32_t y = 0; y < rg.gh; y++) {
        for (uint32_t x = 0; x < rg.gw; x++) {
            size_t i = (size_t)y * rg.stride * m->width + (size_t)x * rg.stride;
            struct reg_cell *cl = &out[(size_t)y * rg.gw + x];
            cl->valid = m->reason[i] == SCAN_VALID;
            memcpy(cl->xyz, &r->xyz_mm[3 * i], sizeof(cl->xyz));
            memcpy(cl->normal, &r->normal[3 * i], sizeof(cl->normal));
            memcpy(cl->rgb, &rgb[3 * i], 3);
        }
    }
    rg.reported_mdeg[index] = angle_mdeg;
    rg.present[index] = 1;
    return 0;
}

/* Neighbouring views of each pass: each with the next, the last with the first (the views of
 * a pass go round). */
static void make_edges(void)
{
    rg.edges = 0;
    uint32_t n = rg.per_pass;
    for (uint32_t pass = 0; pass < rg.passes; pass++)
        for (uint32_t k = 0; k < n && n >= 2; k++) {
            uint32_t i = pass * n + k, j = pass * n + (k + 1) % n;
            if (n == 2 && k == 1)
                break; /* two views: one pair */
            if (!rg.present[i] || !rg.present[j])
                continue;
            rg.edge_from[rg.edges] = i;
            rg.edge_to[rg.edges] = j;
            rg.edges++;
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

/* Two unit vectors across d. */
static void across(vec3 d, vec3 *e1, vec3 *e2)
{
    vec3 t = fabs(d.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
    *e1 = v3_norm(v3_cross(d, t));
    *e2 = v3_cross(d, *e1);
}

/* Unknowns: the angle of each view but the first of its pass (the gauge of that pass's frame),
 * then the axis. @retval the unknown of view @p v's angle, -1 for a first view */
static int angle_param(uint32_t v)
{
    uint32_t pass = v / rg.per_pass;
    return v % rg.per_pass == 0 ? -1 : (int)(v - 1 - pass);
}

static uint32_t n_params(void)
{
    return rg.views - rg.passes + 4;
}

/* Add one residual with @p jac entries at @p idx (negative: a fixed angle) to the equations. */
static void add_residual(const int idx[6], const double jac[6], double res, double weight)
{
    const uint32_t n = n_params();
    for (int s = 0; s < 6; s++) {
        if (idx[s] < 0)
            continue;
        for (int t = 0; t < 6; t++)
            if (idx[t] >= 0)
                normal_a[(size_t)idx[s] * n + (size_t)idx[t]] += weight * jac[s] * jac[t];
        normal_b[idx[s]] += weight * jac[s] * res;
    }
}

/* The pairs from view @p src to view @p dst at the current unknowns, gated at @p gate_mm:
 * counted into @p st and, when @p solve, added to the normal equations. */
static void pair_views(uint32_t src, uint32_t dst, double gate_mm, int solve,
                       struct edge_stats *st)
{
    const double min_cos = cos(rg.p.max_normal_deg * M_PI / 180.0);
    const double huber = rg.p.max_pair_mm / 3.0;
    double rot[9];
    axis_rotation(rg.d, rg.theta[dst] - rg.theta[src], rot);
    vec3 e1, e2;
    across(rg.d, &e1, &e2);
    vec3 r_e1 = m3_mul(rot, e1), r_e2 = m3_mul(rot, e2);
    const int axis = (int)(rg.views - rg.passes);
    int idx[6] = {angle_param(src), angle_param(dst), axis, axis + 1, axis + 2, axis + 3};
    const struct reg_cell *from = view_cells(src), *to = view_cells(dst);
    for (size_t k = 0; k < cell_count(); k++) {
        const struct reg_cell *cp = &from[k];
        if (!cp->valid)
            continue;
        vec3 pa = v3_sub(v3(cp->xyz[0], cp->xyz[1], cp->xyz[2]), rg.a);
        vec3 rpa = m3_mul(rot, pa), p = v3_add(rg.a, rpa);
        if (p.z <= 1.0)
            continue;
        double fu, fv;
        camray_project(&rg.calib, p, &fu, &fv);
        long u = lround(fu / rg.stride), v = lround(fv / rg.stride);
        if (u < 0 || v < 0 || u >= (long)rg.gw || v >= (long)rg.gh)
            continue;
        const struct reg_cell *cq = &to[(size_t)v * rg.gw + (size_t)u];
        vec3 nq = v3(cq->normal[0], cq->normal[1], cq->normal[2]);
        vec3 n = m3_mul(rot, v3(cp->normal[0], cp->normal[1], cp->normal[2]));
        /* The overlap: samples landing on a surface of the other view that faces the same way.
         * One landing on another face (a side the other view sees, this one hides behind) says
         * nothing about the match: a box seen from 90 degrees apart shares one face only. */
        if (!cq->valid || v3_dot(n, nq) < min_cos)
            continue;
        st->overlap++;
        vec3 q = v3(cq->xyz[0], cq->xyz[1], cq->xyz[2]);
        vec3 diff = v3_sub(p, q);
        double dist = v3_len(diff);
        int ok = dist <= gate_mm;
        for (int c = 0; c < 3 && ok && rg.p.use_colour; c++)
            ok = fabs((double)cp->rgb[c] - cq->rgb[c]) <= rg.p.max_colour_dn;
        double res = v3_dot(diff, nq);
        double cap = fmin(res * res, rg.p.max_pair_mm * rg.p.max_pair_mm);
        st->trunc_sq += ok ? cap : rg.p.max_pair_mm * rg.p.max_pair_mm;
        if (!ok)
            continue;
        st->coupled++;
        st->sq += res * res;
        if (!solve)
            continue;
        double dth = v3_dot(nq, v3_cross(rg.d, rpa));
        vec3 tilt1 = v3_sub(v3_cross(e1, rpa), m3_mul(rot, v3_cross(e1, pa)));
        vec3 tilt2 = v3_sub(v3_cross(e2, rpa), m3_mul(rot, v3_cross(e2, pa)));
        double jac[6] = {-dth,
                         dth,
                         v3_dot(nq, v3_sub(e1, r_e1)),
                         v3_dot(nq, v3_sub(e2, r_e2)),
                         v3_dot(nq, tilt1),
                         v3_dot(nq, tilt2)};
        double w = fabs(res) <= huber ? 1.0 : huber / fabs(res);
        add_residual(idx, jac, res, w);
    }
}

/* One pass over every edge, both directions. */
static void pass(double gate_mm, int solve)
{
    if (solve) {
        uint32_t n = n_params();
        memset(normal_a, 0, (size_t)n * n * sizeof(double));
        memset(normal_b, 0, n * sizeof(double));
    }
    for (uint32_t e = 0; e < rg.edges; e++) {
        memset(&rg.stats[e], 0, sizeof(rg.stats[e]));
        pair_views(rg.edge_from[e], rg.edge_to[e], gate_mm, solve, &rg.stats[e]);
        pair_views(rg.edge_to[e], rg.edge_from[e], gate_mm, solve, &rg.stats[e]);
    }
}

/* sqrt(mean truncated squared residual) over every overlap: lower is better, and dropping
 * pairs does not lower it (a dropped pair counts max_pair_mm). */
static double score(void)
{
    double sum = 0.0;
    uint64_t n = 0;
    for (uint32_t e = 0; e < rg.edges; e++) {
        sum += rg.stats[e].trunc_sq;
        n += rg.stats[e].overlap;
    }
    return n > 0 ? sqrt(sum / (double)n) : 0.0;
}

/* Solve and apply one Gauss-Newton step. @retval the largest angle change (rad) */
static double gauss_newton_step(void)
{
    const uint32_t n = n_params();
    /* A little damping keeps unknowns the data barely see (the axis of two views) in place. */
    double trace = 0.0;
    for (uint32_t i = 0; i < n; i++)
        trace += normal_a[(size_t)i * n + i];
    for (uint32_t i = 0; i < n; i++)
        normal_a[(size_t)i * n + i] += 1e-6 * trace / n + 1e-3 * normal_a[(size_t)i * n + i];
    for (uint32_t i = 0; i < n; i++)
        normal_b[i] = -normal_b[i];
    if (lsq_solve(n, normal_a, normal_b, step_x) != 0)
        return 0.0;
    double largest = 0.0;
    for (uint32_t v = 0; v < rg.views; v++) {
        if (angle_param(v) < 0)
            continue;
        rg.theta[v] += step_x[angle_param(v)];
        largest = fmax(largest, fabs(step_x[angle_param(v)]));
    }
    vec3 e1, e2;
    across(rg.d, &e1, &e2);
    const double *ax = &step_x[rg.views - rg.passes];
    rg.a = v3_add(rg.a, v3_add(v3_scale(e1, ax[0]), v3_scale(e2, ax[1])));
    rg.d = v3_norm(v3_add(rg.d, v3_cross(v3_add(v3_scale(e1, ax[2]), v3_scale(e2, ax[3])), rg.d)));
    return fmax(largest, fmax(fabs(ax[2]), fabs(ax[3])));
}

/* The angle the table reported for view @p v, in radians. */
static double reported_rad(uint32_t v)
{
    return rg.reported_mdeg[v] * (M_PI / 180000.0);
}

/* The unknowns at the turntable's answer. */
static void start_from_table(void)
{
    for (uint32_t v = 0; v < rg.views; v++)
        rg.theta[v] = reported_rad(v);
    rg.a = v3_from(rg.calib.axis_point_mm);
    rg.d = v3_norm(v3_from(rg.calib.axis_dir));
}

/* How far the solution is from the calibrated axis; "" or why it is refused. */
static void check_bounds(struct reg_report *rep)
{
    vec3 a0 = v3_from(rg.calib.axis_point_mm), d0 = v3_norm(v3_from(rg.calib.axis_dir));
    vec3 da = v3_sub(rg.a, a0);
    da = v3_sub(da, v3_scale(d0, v3_dot(da, d0))); /* along the axis changes nothing */
    rep->axis_shift_mm = v3_len(da);
    double c = v3_dot(rg.d, d0);
    rep->axis_tilt_deg = acos(c > 1.0 ? 1.0 : c) * 180.0 / M_PI;
    rep->refused[0] = '\0';
    for (uint32_t v = 0; v < rg.views; v++) {
        double corr = (rg.theta[v] - reported_rad(v)) * 180.0 / M_PI;
        if (rg.present[v] && fabs(corr) > rg.p.max_correction_deg) {
            snprintf(rep->refused, sizeof(rep->refused),
                     "view %u would turn %.2f deg from its reported angle, more than "
                     "max_correction_deg = %g",
                     (unsigned)v, corr, rg.p.max_correction_deg);
            return;
        }
    }
    if (rep->axis_shift_mm > rg.p.max_axis_shift_mm)
        snprintf(rep->refused, sizeof(rep->refused),
                 "the axis would move %.2f mm, more than max_axis_shift_mm = %g",
                 rep->axis_shift_mm, rg.p.max_axis_shift_mm);
    else if (rep->axis_tilt_deg > rg.p.max_axis_tilt_deg)
        snprintf(rep->refused, sizeof(rep->refused),
                 "the axis would tilt %.2f deg, more than max_axis_tilt_deg = %g",
                 rep->axis_tilt_deg, rg.p.max_axis_tilt_deg);
}

/* Per-view numbers, the worst view, the loop closure and the first pair that does not match,
 * from the last pass. */
static void summarise(struct reg_report *rep)
{
    uint64_t coupled = 0, loop_coupled = 0;
    double sq = 0.0, loop_sq = 0.0;
    rep->failed_view = rep->failed_against = -1;
    for (uint32_t e = 0; e < rg.edges; e++) {
        const struct edge_stats *st = &rg.stats[e];
        coupled += st->coupled;
        sq += st->sq;
        double share = st->overlap > 0 ? (double)st->coupled / st->overlap : 0.0;
        if (rep->failed_view < 0 && share < rg.p.min_coupled_share) {
            rep->failed_view = (int)rg.edge_to[e];
            rep->failed_against = (int)rg.edge_from[e];
            rep->failed_share = share;
        }
        if (rg.edge_to[e] % rg.per_pass == 0 && rg.per_pass > 2) { /* a closing pair */
            loop_sq += st->sq;
            loop_coupled += st->coupled;
        }
    }
    rep->loop_rms_mm = loop_coupled > 0 ? sqrt(loop_sq / (double)loop_coupled) : 0.0;
    rep->rms_mm = coupled > 0 ? sqrt(sq / (double)coupled) : 0.0;
    rep->worst_rms_mm = -1.0;
    for (uint32_t v = 0; v < rg.views; v++) {
        struct reg_view rv;
        if (reg_view_pose(v, NULL, &rv) == 0 && rv.coupled > 0 && rv.rms_mm > rep->worst_rms_mm) {
            rep->worst_rms_mm = rv.rms_mm;
            rep->worst_view = v;
        }
    }
    if (rep->worst_rms_mm < 0.0)
        rep->worst_rms_mm = 0.0;
}

/* A cell's point and normal in its pass's object frame through @p pose. */
static void cell_in_object(const struct reg_cell *cl, const struct frame_xform *pose, vec3 *p,
                           vec3 *n)
{
    *p = frame_point(pose, v3(cl->xyz[0], cl->xyz[1], cl->xyz[2]));
    *n = frame_dir(pose, v3(cl->normal[0], cl->normal[1], cl->normal[2]));
}

/* Hand both passes' samples (object frames) to the alignment, spread to fit ALIGN_MAX_POINTS. */
static void feed_alignment(void)
{
    uint64_t valid[2] = {0, 0};
    for (uint32_t v = 0; v < rg.views; v++)
        for (size_t k = 0; k < cell_count() && rg.present[v]; k++)
            valid[v / rg.per_pass] += view_cells(v)[k].valid;
    align_begin();
    for (uint32_t v = 0; v < rg.views; v++) {
        uint32_t pass = v / rg.per_pass;
        uint64_t step = valid[pass] / ALIGN_MAX_POINTS + 1, seen = 0;
        struct frame_xform pose;
        struct reg_view rv;
        if (reg_view_pose(v, &pose, &rv) != 0)
            continue;
        for (size_t k = 0; k < cell_count(); k++) {
            const struct reg_cell *cl = &view_cells(v)[k];
            if (!cl->valid || seen++ % step != 0)
                continue;
            vec3 p, n;
            cell_in_object(cl, &pose, &p, &n);
            align_add_point(pass, p, n);
        }
    }
}

/* The second pass's samples against the first pass's views, projectively, as the views of a
 * pass are paired: one point-to-plane step of first_from_second per call (object frame 1).
 * @retval pairs coupled; @p rms their residual */
static uint32_t refine_second_step(double gate_mm, double *rms)
{
    const double min_cos = cos(rg.p.max_normal_deg * M_PI / 180.0);
    struct lsq_rigid eq;
    lsq_rigid_clear(&eq);
    static struct frame_xform first[REG_MAX_VIEWS], cam_of[REG_MAX_VIEWS]; /* too big for a stack */
    struct reg_view rv;
    for (uint32_t j = 0; j < rg.per_pass; j++)
        if (reg_view_pose(j, &first[j], &rv) == 0)
            frame_invert(&first[j], &cam_of[j]);
    for (uint32_t v = rg.per_pass; v < rg.views; v++) {
        struct frame_xform pose;
        if (reg_view_pose(v, &pose, &rv) != 0)
            continue;
        for (size_t k = 0; k < cell_count(); k += 2) {
            const struct reg_cell *cl = &view_cells(v)[k];
            if (!cl->valid)
                continue;
            vec3 p, n;
            cell_in_object(cl, &pose, &p, &n);
            for (uint32_t j = 0; j < rg.per_pass; j++) {
                if (!rg.present[j])
                    continue;
                vec3 c = frame_point(&cam_of[j], p);
                if (c.z <= 1.0 || v3_dot(frame_dir(&cam_of[j], n), c) >= 0.0)
                    continue; /* behind the camera, or facing away from it */
                double fu, fv;
                camray_project(&rg.calib, c, &fu, &fv);
                long u = lround(fu / rg.stride), w = lround(fv / rg.stride);
                if (u < 0 || w < 0 || u >= (long)rg.gw || w >= (long)rg.gh)
                    continue;
                const struct reg_cell *cq = &view_cells(j)[(size_t)w * rg.gw + (size_t)u];
                if (!cq->valid)
                    continue;
                vec3 q, nq;
                cell_in_object(cq, &first[j], &q, &nq);
                if (v3_len(v3_sub(p, q)) > gate_mm || v3_dot(n, nq) < min_cos)
                    continue;
                lsq_rigid_add(&eq, p, q, nq);
                break; /* one pair a point: the first view that sees it */
            }
        }
    }
    uint32_t coupled = eq.pairs;
    *rms = coupled > 0 ? sqrt(eq.sq / coupled) : 0.0;
    struct frame_xform s, moved;
    if (lsq_rigid_step(&eq, &s) == 0) {
        frame_compose(&s, &rg.first_from_second, &moved);
        rg.first_from_second = moved;
    }
    return coupled;
}

/* Two passes: the second found in the first (align.h), then refined against the first pass's
 * views; a second pass that matches nothing fails the registration at its first view. */
static void align_second_pass(struct reg_report *rep)
{
    struct align_params ap = {rg.p.max_pair_mm, rg.p.max_normal_deg, rg.p.min_coupled_share};
    struct align_report ar;
    rg.second_aligned = 0; /* the second pass's points in its own frame */
    feed_alignment();
    if (align_solve(&ap, &rg.first_from_second, &ar) != 0 || !ar.found) {
        rep->failed_view = (int)rg.per_pass;
        rep->failed_against = -1;
        rep->failed_share = ar.coupled_share;
        return;
    }
    rg.second_aligned = 1;
    double rms = 0.0;
    for (int it = 0; it < 15; it++)
        rep->second_coupled = refine_second_step(rg.p.max_pair_mm, &rms);
    rep->second_rms_mm = rms;
    rep->second_turned_deg = ar.turned_deg;
    rep->second_share = ar.coupled_share;
}

int reg_solve(struct reg_report *rep)
{
    memset(rep, 0, sizeof(*rep));
    rep->stride = rg.stride;
    for (uint32_t v = 0; v < rg.views; v++)
        rep->views += rg.present[v];
    make_edges();
    start_from_table();
    rg.use_solution = 0;
    pass(rg.p.max_pair_mm, 0);
    rep->score_before_mm = rep->score_after_mm = score();
    if (rg.p.enabled && rg.edges > 0 && rg.present[0] && rg.present[rg.views - rg.per_pass]) {
        rep->solved = 1;
        for (uint32_t it = 0; it < rg.p.iterations; it++) {
            /* wide pairs first, to reach errors of a degree or two, then the working gate */
            double gate = rg.p.max_pair_mm * fmax(1.0, 4.0 / (double)(1u << (it < 8 ? it : 8)));
            pass(gate, 1);
            rep->iterations = it + 1;
            if (gauss_newton_step() < 1e-5 && gate <= rg.p.max_pair_mm) /* 0.0006 deg */
                break;
        }
        pass(rg.p.max_pair_mm, 0);
        rep->score_after_mm = score();
        check_bounds(rep);
        rep->accepted = rep->refused[0] == '\0' && rep->score_after_mm < rep->score_before_mm;
        if (rep->refused[0] == '\0' && !rep->accepted)
            snprintf(rep->refused, sizeof(rep->refused),
                     "the residual did not improve (%.3f mm -> %.3f mm)", rep->score_before_mm,
                     rep->score_after_mm);
        if (!rep->accepted) {
            start_from_table();
            pass(rg.p.max_pair_mm, 0);
        }
        rg.use_solution = rep->accepted;
    }
    summarise(rep);
    if (rg.passes == 2)
        align_second_pass(rep);
    return 0;
}

int reg_view_pose(uint32_t v, struct frame_xform *obj_from_cam, struct reg_view *out)
{
    if (v >= rg.views || !rg.present[v])
        return -EINVAL;
    memset(out, 0, sizeof(*out));
    out->present = 1;
    out->reported_mdeg = rg.reported_mdeg[v];
    double theta = rg.use_solution ? rg.theta[v] : reported_rad(v);
    out->angle_deg = theta * 180.0 / M_PI;
    out->correction_deg = out->angle_deg - rg.reported_mdeg[v] / 1000.0;
    double sq = 0.0;
    for (uint32_t e = 0; e < rg.edges; e++) {
        if (rg.edge_from[e] != v && rg.edge_to[e] != v)
            continue;
        out->overlap += rg.stats[e].overlap;
        out->coupled += rg.stats[e].coupled;
        sq += rg.stats[e].sq;
    }
    out->rms_mm = out->coupled > 0 ? sqrt(sq / out->coupled) : 0.0;
    if (obj_from_cam != NULL) {
        struct scan_calib c = rg.calib;
        if (rg.use_solution) {
            c.axis_point_mm[0] = rg.a.x, c.axis_point_mm[1] = rg.a.y, c.axis_point_mm[2] = rg.a.z;
            c.axis_dir[0] = rg.d.x, c.axis_dir[1] = rg.d.y, c.axis_dir[2] = rg.d.z;
        }
        frame_object_from_camera_rad(&c, theta, obj_from_cam);
        if (v >= rg.per_pass && rg.second_aligned) { /* into the first pass's object frame */
            struct frame_xform in_second = *obj_from_cam;
            frame_compose(&rg.first_from_second, &in_second, obj_from_cam);
        }
    }
    return 0;
}
