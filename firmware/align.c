/* Second pass to first pass (align.h): orientations searched against a nearest-point field of
 * the first pass, the best few refined by point-to-plane ICP, the winner refined on every
 * point. */
#include "align.h"

#include "lsq.h"
#include "mem.h"
#include "vec3.h"

#include <errno.h>
#include <string.h>

#define SEARCH_POINTS 1200u /* second-pass points that score an orientation */
#define SEARCH_AXES 72u     /* rotation axes, spread over the sphere */
#define SEARCH_ANGLES 6u    /* 30, 60, ... 180 degrees about each */
#define REFINED 8u          /* best orientations refined by ICP */
#define FIELD_CELL_MM 2.0   /* the nearest-point field's cell, grown to fit ALIGN_MAX_CELLS */
#define SCORE_CAP_MM 10.0   /* a point farther than this from the first pass counts this */

/* A rigid motion p' = R p + t. */
struct motion {
    double r[9];
    vec3 t;
};

static vec3 apply(const struct motion *m, vec3 p)
{
    return v3_add(m3_mul(m->r, p), m->t);
}

void align_begin(struct align_ctx *a)
{
    a->npts[0] = a->npts[1] = 0;
}

int align_add_point(struct align_ctx *a, uint32_t pass, vec3 p, vec3 n)
{
    if (pass > 1 || a->npts[pass] >= ALIGN_MAX_POINTS)
        return -ENOSPC;
    float *q = a->pts[pass][a->npts[pass]], *m = a->nrm[pass][a->npts[pass]];
    q[0] = (float)p.x, q[1] = (float)p.y, q[2] = (float)p.z;
    m[0] = (float)n.x, m[1] = (float)n.y, m[2] = (float)n.z;
    a->npts[pass]++;
    return 0;
}

static vec3 point(struct align_ctx *a, uint32_t pass, uint32_t i)
{
    return v3(a->pts[pass][i][0], a->pts[pass][i][1], a->pts[pass][i][2]);
}

static vec3 normal(struct align_ctx *a, uint32_t pass, uint32_t i)
{
    return v3(a->nrm[pass][i][0], a->nrm[pass][i][1], a->nrm[pass][i][2]);
}

static size_t cell_index(struct align_ctx *a, uint32_t x, uint32_t y, uint32_t z)
{
    return ((size_t)z * a->field.dims[1] + y) * a->field.dims[0] + x;
}

static vec3 cell_centre(struct align_ctx *a, uint32_t x, uint32_t y, uint32_t z)
{
    return v3_add(a->field.lo, v3_scale(v3(x + 0.5, y + 0.5, z + 0.5), a->field.cell));
}

/* Take @p from's point for cell @p to when it is nearer the cell's centre. */
static void offer(struct align_ctx *a, size_t to, uint32_t cand, vec3 centre)
{
    if (cand == 0)
        return;
    if (a->nearest[to] == 0 || v3_len(v3_sub(point(a, 0, cand - 1), centre)) <
                                   v3_len(v3_sub(point(a, 0, a->nearest[to] - 1), centre)))
        a->nearest[to] = cand;
}

/* One sweep of the field, forward or backward: each cell looks at its three neighbours behind
 * (a chamfer propagation of nearest points; two rounds make it near exact). */
static void sweep(struct align_ctx *a, int backward)
{
    const uint32_t *d = a->field.dims;
    for (uint32_t k = 0; k < d[2]; k++)
        for (uint32_t j = 0; j < d[1]; j++)
            for (uint32_t i = 0; i < d[0]; i++) {
                uint32_t x = backward ? d[0] - 1 - i : i, y = backward ? d[1] - 1 - j : j;
                uint32_t z = backward ? d[2] - 1 - k : k;
                size_t c = cell_index(a, x, y, z);
                vec3 centre = cell_centre(a, x, y, z);
                int s = backward ? 1 : -1;
                if (backward ? x + 1 < d[0] : x > 0)
                    offer(a, c, a->nearest[cell_index(a, (uint32_t)((int)x + s), y, z)], centre);
                if (backward ? y + 1 < d[1] : y > 0)
                    offer(a, c, a->nearest[cell_index(a, x, (uint32_t)((int)y + s), z)], centre);
                if (backward ? z + 1 < d[2] : z > 0)
                    offer(a, c, a->nearest[cell_index(a, x, y, (uint32_t)((int)z + s))], centre);
            }
}

/* The nearest-point field over the first pass, with a margin for the search. */
static void build_field(struct align_ctx *a)
{
    vec3 lo = v3(1e30, 1e30, 1e30), hi = v3(-1e30, -1e30, -1e30);
    for (uint32_t i = 0; i < a->npts[0]; i++) {
        vec3 p = point(a, 0, i);
        lo = v3(fmin(lo.x, p.x), fmin(lo.y, p.y), fmin(lo.z, p.z));
        hi = v3(fmax(hi.x, p.x), fmax(hi.y, p.y), fmax(hi.z, p.z));
    }
    const double margin = 2.0 * SCORE_CAP_MM;
    a->field.lo = v3_sub(lo, v3(margin, margin, margin));
    vec3 span = v3_add(v3_sub(hi, lo), v3(2 * margin, 2 * margin, 2 * margin));
    for (a->field.cell = FIELD_CELL_MM;; a->field.cell *= 1.25) {
        a->field.dims[0] = (uint32_t)(span.x / a->field.cell) + 1;
        a->field.dims[1] = (uint32_t)(span.y / a->field.cell) + 1;
        a->field.dims[2] = (uint32_t)(span.z / a->field.cell) + 1;
        if ((uint64_t)a->field.dims[0] * a->field.dims[1] * a->field.dims[2] <= ALIGN_MAX_CELLS)
            break;
    }
    size_t cells = (size_t)a->field.dims[0] * a->field.dims[1] * a->field.dims[2];
    mem_fill(a->nearest, 0, cells * sizeof(a->nearest[0]));
    for (uint32_t i = 0; i < a->npts[0]; i++) {
        vec3 g = v3_scale(v3_sub(point(a, 0, i), a->field.lo), 1.0 / a->field.cell);
        uint32_t x = (uint32_t)g.x, y = (uint32_t)g.y, z = (uint32_t)g.z;
        offer(a, cell_index(a, x, y, z), i + 1, cell_centre(a, x, y, z));
    }
    for (int round = 0; round < 2; round++) {
        sweep(a, 0);
        sweep(a, 1);
    }
}

/* The first-pass point nearest @p p (from the field), or -1 outside it. */
static long nearest_to(struct align_ctx *a, vec3 p)
{
    vec3 g = v3_scale(v3_sub(p, a->field.lo), 1.0 / a->field.cell);
    if (g.x < 0 || g.y < 0 || g.z < 0 || g.x >= a->field.dims[0] || g.y >= a->field.dims[1] ||
        g.z >= a->field.dims[2])
        return -1;
    uint32_t c = a->nearest[cell_index(a, (uint32_t)g.x, (uint32_t)g.y, (uint32_t)g.z)];
    return c == 0 ? -1 : (long)c - 1;
}

/* Mean capped distance of the search points of the second pass moved by @p m. */
static double search_score(struct align_ctx *a, const struct motion *m)
{
    uint32_t step = a->npts[1] / SEARCH_POINTS + 1, n = 0;
    double sum = 0.0;
    for (uint32_t i = 0; i < a->npts[1]; i += step, n++) {
        vec3 x = apply(m, point(a, 1, i));
        long k = nearest_to(a, x);
        sum +=
            k < 0 ? SCORE_CAP_MM : fmin(SCORE_CAP_MM, v3_len(v3_sub(x, point(a, 0, (uint32_t)k))));
    }
    return n > 0 ? sum / n : SCORE_CAP_MM;
}

/* Point-to-plane ICP of every @p step -th second-pass point: @p iterations steps with the pair
 * gate shrinking from @p gate0_mm to @p gate1_mm. @p coupled, @p rms: of the last step. */
static void icp(struct align_ctx *a, struct motion *m, uint32_t step, int iterations,
                double gate0_mm, double gate1_mm, double max_normal_deg, uint32_t *coupled,
                double *rms)
{
    const double min_cos = cos(max_normal_deg * M_PI / 180.0);
    for (int it = 0; it < iterations; it++) {
        double gate = fmax(gate1_mm, gate0_mm * pow(0.8, it));
        struct lsq_rigid eq;
        lsq_rigid_clear(&eq);
        for (uint32_t i = 0; i < a->npts[1]; i += step) {
            vec3 p = apply(m, point(a, 1, i));
            long k = nearest_to(a, p);
            if (k < 0)
                continue;
            vec3 q = point(a, 0, (uint32_t)k), nq = normal(a, 0, (uint32_t)k);
            if (v3_len(v3_sub(p, q)) <= gate &&
                v3_dot(m3_mul(m->r, normal(a, 1, i)), nq) >= min_cos)
                lsq_rigid_add(&eq, p, q, nq);
        }
        *coupled = eq.pairs;
        *rms = eq.pairs > 0 ? sqrt(eq.sq / eq.pairs) : 0.0;
        struct frame_xform s;
        if (lsq_rigid_step(&eq, &s) != 0)
            return;
        vec3 ts = v3_scale(m3_mul(s.rot, s.origin), -1.0); /* p'' = Rs p' + ts */
        double r[9];
        m3_mul_m3(s.rot, m->r, r);
        memcpy(m->r, r, sizeof(r));
        m->t = v3_add(m3_mul(s.rot, m->t), ts);
    }
}

/* Candidate @p k of the search: identity, then turns about spread axes. */
static void candidate(uint32_t k, const vec3 centre[2], struct motion *m)
{
    double x[6] = {0, 0, 0, 0, 0, 0};
    if (k > 0) {
        uint32_t a = (k - 1) / SEARCH_ANGLES, s = (k - 1) % SEARCH_ANGLES;
        double zc = 1.0 - (2.0 * a + 1.0) / SEARCH_AXES, rr = sqrt(1.0 - zc * zc);
        double phi = a * M_PI * (3.0 - sqrt(5.0)); /* Fibonacci sphere */
        double ang = (s + 1.0) * M_PI / SEARCH_ANGLES;
        x[0] = rr * cos(phi) * ang, x[1] = rr * sin(phi) * ang, x[2] = zc * ang;
    }
    struct frame_xform f;
    frame_from_small_motion(x, &f);
    memcpy(m->r, f.rot, sizeof(m->r));
    m->t = v3_sub(centre[0], m3_mul(m->r, centre[1])); /* centroids on each other */
}

int align_solve(struct align_ctx *a, const struct align_params *p, struct frame_xform *out,
                struct align_report *rep)
{
    memset(rep, 0, sizeof(*rep));
    rep->points[0] = a->npts[0];
    rep->points[1] = a->npts[1];
    if (a->npts[0] < 100 || a->npts[1] < 100)
        return -EINVAL;
    build_field(a);
    vec3 centre[2] = {v3(0, 0, 0), v3(0, 0, 0)};
    for (uint32_t s = 0; s < 2; s++) {
        for (uint32_t i = 0; i < a->npts[s]; i++)
            centre[s] = v3_add(centre[s], point(a, s, i));
        centre[s] = v3_scale(centre[s], 1.0 / a->npts[s]);
    }
    /* the best few orientations by their capped distance */
    uint32_t best[REFINED];
    double best_score[REFINED];
    for (uint32_t k = 0; k < REFINED; k++)
        best_score[k] = 1e30, best[k] = 0;
    rep->candidates = 1 + SEARCH_AXES * SEARCH_ANGLES;
    for (uint32_t k = 0; k < rep->candidates; k++) {
        struct motion m;
        candidate(k, centre, &m);
        double sc = search_score(a, &m);
        for (uint32_t r = 0; r < REFINED; r++) {
            if (sc >= best_score[r])
                continue;
            memmove(&best[r + 1], &best[r], (REFINED - 1 - r) * sizeof(best[0]));
            memmove(&best_score[r + 1], &best_score[r], (REFINED - 1 - r) * sizeof(double));
            best[r] = k, best_score[r] = sc;
            break;
        }
    }
    /* each refined on the search points; the one that ends closest wins */
    struct motion winner;
    double winner_score = 1e30;
    uint32_t step = a->npts[1] / SEARCH_POINTS + 1, coupled;
    for (uint32_t r = 0; r < REFINED; r++) {
        struct motion m;
        double rms;
        candidate(best[r], centre, &m);
        icp(a, &m, step, 30, 2.0 * SCORE_CAP_MM, 2.0, 45.0, &coupled, &rms);
        double sc = search_score(a, &m);
        if (sc < winner_score)
            winner = m, winner_score = sc;
    }
    /* then on every point at the working gate */
    icp(a, &winner, 1, 10, 4.0 * p->max_pair_mm, p->max_pair_mm, p->max_normal_deg, &coupled,
        &rep->rms_mm);
    rep->coupled_share = (double)coupled / a->npts[1];
    rep->found = rep->coupled_share >= p->min_coupled_share;
    double tr = winner.r[0] + winner.r[4] + winner.r[8], c = 0.5 * (tr - 1.0);
    rep->turned_deg = acos(c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c) * 180.0 / M_PI;
    memcpy(out->rot, winner.r, sizeof(out->rot));
    out->origin = v3_scale(m3_tmul(winner.r, winner.t), -1.0); /* p' = R (p - origin) */
    return 0;
}
