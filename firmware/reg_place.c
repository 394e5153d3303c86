/* Placing a group of views freely (reg_priv.h): the second pass found in the first, or the
 * views after the object moved on the table placed against the others, by the search of align.h
 * and point-to-plane ICP against the other group's views. */
#include "reg.h"
#include "reg_priv.h"

#include "align.h"
#include "camray.h"
#include "lsq.h"
#include "vec3.h"

#include <stddef.h>
#include <string.h>

/* A cell's point and normal in its pass's object frame through @p pose. */
static void cell_in_object(const struct reg_cell *cl, const struct frame_xform *pose, vec3 *p,
                           vec3 *n)
{
    *p = frame_point(pose, v3(cl->xyz[0], cl->xyz[1], cl->xyz[2]));
    *n = frame_dir(pose, v3(cl->normal[0], cl->normal[1], cl->normal[2]));
}

/* Hand both groups' samples (object frames) to the alignment, spread to fit ALIGN_MAX_POINTS. */
static void feed_alignment(struct reg_ctx *r)
{
    uint64_t valid[2] = {0, 0};
    for (uint32_t v = 0; v < r->views; v++)
        for (size_t k = 0; k < reg_cell_count(r) && r->present[v]; k++)
            valid[r->group[v]] += reg_view_cells(r, v)[k].valid;
    align_begin(&r->align);
    for (uint32_t v = 0; v < r->views; v++) {
        uint32_t pass = r->group[v];
        uint64_t step = valid[pass] / ALIGN_MAX_POINTS + 1, seen = 0;
        struct frame_xform pose;
        struct reg_view rv;
        if (reg_view_pose(r, v, &pose, &rv) != 0)
            continue;
        for (size_t k = 0; k < reg_cell_count(r); k++) {
            const struct reg_cell *cl = &reg_view_cells(r, v)[k];
            if (!cl->valid || seen++ % step != 0)
                continue;
            vec3 p, n;
            cell_in_object(cl, &pose, &p, &n);
            align_add_point(&r->align, pass, p, n);
        }
    }
}

/* Group 0's poses, and their inverses, for landing samples on its views (r->first_pose and
 * r->first_cam, too big for a stack). */
void reg_prepare_landing(struct reg_ctx *r)
{
    struct reg_view rv;
    for (uint32_t j = 0; j < r->views; j++)
        if (!r->group[j] && reg_view_pose(r, j, &r->first_pose[j], &rv) == 0)
            frame_invert(&r->first_pose[j], &r->first_cam[j]);
}

/* Where a sample (@p p, @p n in group 0's object frame) lands in group-0 view @p j, projectively:
 * @p landed when on a surface facing its way, and that surface's cell when within @p gate_mm
 * of it (@p q, @p nq; @p facing how squarely the view sees it, @p grid_xy where in its grid).
 * @retval the cell @retval NULL none within the gate */
static const struct reg_cell *land_in(struct reg_ctx *r, uint32_t j, vec3 p, vec3 n, double min_cos,
                                      double gate_mm, int *landed, double *facing, vec3 *q,
                                      vec3 *nq, double grid_xy[2])
{
    *landed = 0;
    vec3 c = frame_point(&r->first_cam[j], p);
    *facing = -v3_dot(frame_dir(&r->first_cam[j], n), c);
    if (c.z <= 1.0 || *facing <= 0.0)
        return NULL; /* behind the camera, or facing away from it */
    double fu, fv;
    camray_project(&r->calib, c, &fu, &fv);
    long u = lround(fu / r->stride), w = lround(fv / r->stride);
    if (u < 0 || w < 0 || u >= (long)r->gw || w >= (long)r->gh)
        return NULL;
    const struct reg_cell *cq = &reg_view_cells(r, j)[(size_t)w * r->gw + (size_t)u];
    if (!cq->valid)
        return NULL;
    cell_in_object(cq, &r->first_pose[j], q, nq);
    if (v3_dot(n, *nq) < min_cos)
        return NULL;
    *landed = 1;
    *facing /= v3_len(c);
    grid_xy[0] = fu / r->stride, grid_xy[1] = fv / r->stride;
    return v3_len(v3_sub(p, *q)) <= gate_mm ? cq : NULL;
}

/* Where a group-1 sample (@p p, @p n in group 0's object frame) lands on group 0, projectively,
 * as the views of a pass are paired: on a surface facing its way (@p landed) within @p gate_mm of
 * it (@p q, @p nq), in the first group-0 view that sees one or, with @p most_facing, in the one
 * that sees it most squarely. @retval its cell @retval NULL none */
static const struct reg_cell *land(struct reg_ctx *r, vec3 p, vec3 n, double min_cos,
                                   double gate_mm, int most_facing, int *landed, vec3 *q, vec3 *nq)
{
    const struct reg_cell *best = NULL;
    double best_facing = 0.0;
    *landed = 0;
    for (uint32_t j = 0; j < r->views; j++) {
        if (!r->present[j] || r->group[j])
            continue;
        int on;
        double facing, g[2];
        vec3 qj, nqj;
        const struct reg_cell *cq =
            land_in(r, j, p, n, min_cos, gate_mm, &on, &facing, &qj, &nqj, g);
        *landed |= on;
        if (cq == NULL || (best != NULL && facing <= best_facing))
            continue;
        best = cq, best_facing = facing, *q = qj, *nq = nqj;
        if (!most_facing)
            break;
    }
    return best;
}

/* A cell's footprint on its surface, in group 0's frame through @p pose: the square of the
 * region one of its view's pixels covers there, F = d^2 (I - n n^T + a a^T / cos^2 i), the
 * surface's own metric across its normal n, stretched along a (the direction to the camera
 * across the normal, of length sin i) by the view's slant, and scaled by the distance d (the
 * pixel's size; every view has the same lens). */
static void cell_footprint(const struct reg_cell *cl, const struct frame_xform *pose, double f[9])
{
    vec3 x = v3(cl->xyz[0], cl->xyz[1], cl->xyz[2]);
    vec3 n = v3(cl->normal[0], cl->normal[1], cl->normal[2]);
    double d = v3_len(x);
    vec3 to_camera = v3_scale(x, -1.0 / d);
    double cos_i = fmax(v3_dot(to_camera, n), 0.05); /* a grazing view: long, not endless */
    vec3 a = frame_dir(pose, v3_sub(to_camera, v3_scale(n, v3_dot(to_camera, n))));
    n = frame_dir(pose, n);
    const double av[3] = {a.x, a.y, a.z}, nv[3] = {n.x, n.y, n.z};
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            f[3 * i + k] = d * d * ((i == k) - nv[i] * nv[k] + av[i] * av[k] / (cos_i * cos_i));
}

/* How unlike footprint @p b is @p a: their difference's Frobenius norm over @p a's. */
static double footprint_miss(const double a[9], const double b[9])
{
    double diff = 0.0, size = 0.0;
    for (int i = 0; i < 9; i++)
        diff += (a[i] - b[i]) * (a[i] - b[i]), size += a[i] * a[i];
    return sqrt(diff / size);
}

/* Two hues further apart than this (the chord between their unit vectors, 0.43: 25 degrees) are
 * a miss: the palette's colours are 45 degrees and more apart. */
#define REG_HUE_TAU 0.43
/* The colour search (and the hues in the refinement after it) moves along the one or two directions
 * the shape holds less than this (the box, bracket, nut and stepped block of data/objects hold
 * their second weakest 0.14 to 0.48, the gear 0.016 and a plate lying flat little more: two to
 * search); the shape must hold the third. */
#define REG_COLOUR_MIN_NEXT 0.05

/* Where cell @p cl lies: its view @p j and its place @p x, @p y in that view's grid (NULL: not
 * wanted). */
static void cell_place(const struct reg_ctx *r, const struct reg_cell *cl, uint32_t *j, uint32_t *x,
                       uint32_t *y)
{
    size_t k = (size_t)(cl - r->cells), count = reg_cell_count(r);
    *j = (uint32_t)(k / count);
    if (x != NULL)
        *x = (uint32_t)(k % count % r->gw), *y = (uint32_t)(k % count / r->gw);
}

/* Cell @p cl's hue (reg_priv.h: the mean of its pixels'). @retval 0 too dark to tell */
static int hue_of(const struct reg_cell *cl, double hue[2])
{
    if (cl->hue[0] == REG_NO_HUE)
        return 0;
    hue[0] = cl->hue[0] / 32767.0, hue[1] = cl->hue[1] / 32767.0;
    return 1;
}

/* Two hues' squared distance, truncated at REG_HUE_TAU: grey against a hue is a miss. */
static double hue_miss(const double a[2], const double b[2])
{
    double dx = a[0] - b[0], dy = a[1] - b[1];
    return fmin(dx * dx + dy * dy, REG_HUE_TAU * REG_HUE_TAU);
}

/* The hue's gradient at group-0 cell @p hit (the hue across the surface, per unit of length
 * along it, Park, Zhou and Koltun 2017, "Colored point cloud registration revisited", eq. 7 to
 * 10): from the cells beside it in its view that lie on the same surface (within @p reach_mm,
 * facing within @p min_cos), by least squares in the plane of its normal @p nq.
 * @retval 0 @p hue and @p grad (one row per hue component) set @retval -1 not measurable */
static int hue_gradient(struct reg_ctx *r, const struct reg_cell *hit, vec3 q, vec3 nq,
                        double min_cos, double reach_mm, double hue[2], vec3 grad[2])
{
    uint32_t j, x, y;
    cell_place(r, hit, &j, &x, &y);
    static const int step[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    vec3 e1, e2;
    double ata[3] = {0, 0, 0}, atb[2][2] = {{0, 0}, {0, 0}};
    if (!hue_of(hit, hue))
        return -1;
    v3_across(nq, &e1, &e2);
    for (int s = 0; s < 4; s++) {
        long xs = (long)x + step[s][0], ys = (long)y + step[s][1];
        double hs[2];
        vec3 qs, ns;
        if (xs < 0 || ys < 0 || xs >= (long)r->gw || ys >= (long)r->gh)
            continue;
        const struct reg_cell *cs = &reg_view_cells(r, j)[(size_t)ys * r->gw + (size_t)xs];
        if (!cs->valid || !hue_of(cs, hs))
            continue;
        cell_in_object(cs, &r->first_pose[j], &qs, &ns);
        vec3 d = v3_sub(qs, q);
        if (v3_len(d) > reach_mm || v3_dot(ns, nq) < min_cos)
            continue; /* another surface: an edge of the object, not of its paint */
        double a = v3_dot(d, e1), b = v3_dot(d, e2);
        ata[0] += a * a, ata[1] += a * b, ata[2] += b * b;
        for (int c = 0; c < 2; c++)
            atb[c][0] += a * (hs[c] - hue[c]), atb[c][1] += b * (hs[c] - hue[c]);
    }
    double det = ata[0] * ata[2] - ata[1] * ata[1];
    if (!(det > 1e-6 * (ata[0] + ata[2]) * (ata[0] + ata[2])))
        return -1; /* the neighbours on one line (or none): no gradient across it */
    for (int c = 0; c < 2; c++) {
        double g1 = (ata[2] * atb[c][0] - ata[1] * atb[c][1]) / det;
        double g2 = (ata[0] * atb[c][1] - ata[1] * atb[c][0]) / det;
        grad[c] = v3_add(v3_scale(e1, g1), v3_scale(e2, g2));
    }
    return 0;
}

/* A group-1 sample's hue (@p cl, at @p p) against the hue field about where it landed (@p hit,
 * at @p q, @p nq): two rows of the step's equations, residual h_q + grad (p - q) - h_p and its
 * derivatives p x grad, grad by the small motion (Park et al. 2017, eq. 13 and 17), weighted
 * @p weight; a residual beyond REG_HUE_TAU is another paint altogether and adds nothing. */
static void add_hue_rows(struct reg_ctx *r, struct lsq_rigid *eq, const struct reg_cell *cl, vec3 p,
                         const struct reg_cell *hit, vec3 q, vec3 nq, double min_cos,
                         double reach_mm, double weight)
{
    double hp[2], hq[2], res[2];
    vec3 grad[2];
    if (!hue_of(cl, hp) || hue_gradient(r, hit, q, nq, min_cos, reach_mm, hq, grad) != 0)
        return;
    for (int c = 0; c < 2; c++)
        res[c] = hq[c] + v3_dot(grad[c], v3_sub(p, q)) - hp[c];
    if (res[0] * res[0] + res[1] * res[1] > REG_HUE_TAU * REG_HUE_TAU)
        return;
    for (int c = 0; c < 2; c++) {
        vec3 pxg = v3_cross(p, grad[c]);
        const double jac[6] = {pxg.x, pxg.y, pxg.z, grad[c].x, grad[c].y, grad[c].z};
        lsq_rigid_add_row(eq, jac, res[c], weight);
    }
}

/* A footprint this unlike the sample's own (footprint_miss) weighs half as much as an alike one
 * (add_hues_alike). */
#define REG_ALIKE_MISS 0.1

/* The weight of group-0 view @p j's reading of the hue where group-1 cell @p cl (footprint
 * @p mine, at @p p, @p n) lands, by how alike the view's footprint there is to the cell's.
 * @retval the weight @retval 0 the view does not see it within @p gate_mm (@p q, @p nq, @p hit
 * set when it does) */
static double alike_weight(struct reg_ctx *r, uint32_t j, const double mine[9], vec3 p, vec3 n,
                           double min_cos, double gate_mm, const struct reg_cell **hit, vec3 *q,
                           vec3 *nq)
{
    int landed;
    double facing, grid_xy[2], theirs[9];
    if (!r->present[j] || r->group[j])
        return 0.0;
    *hit = land_in(r, j, p, n, min_cos, gate_mm, &landed, &facing, q, nq, grid_xy);
    if (*hit == NULL)
        return 0.0;
    cell_footprint(*hit, &r->first_pose[j], theirs);
    double miss = footprint_miss(mine, theirs);
    return 1.0 / (REG_ALIKE_MISS * REG_ALIKE_MISS + miss * miss);
}

/* Group-1 cell @p cl's hue rows (add_hue_rows; at @p p, @p n in group 0's frame, its view's pose
 * @p pose) against every group-0 view that sees it within @p gate_mm, each weighed by how alike
 * that view's footprint there is to the cell's own (cell_footprint), the weights summing to
 * @p weight. A cell's colour is the mean over its footprint, and two views place a paint boundary
 * alike only where their footprints are alike: a top seen at a slant from every side (as a
 * turntable sees it) is blurred along each view's slant, and the view that sees it from the
 * opposite side, slanted along the same line, sees its paint alike, the most squarely facing one
 * not. Measured on the parts of data/objects slipped 6 and 30 mm in 6, 8 and 12 views (35 scans,
 * 2026-12-06; docs/objects.md): the hues from the most facing view alone placed the thin box
 * slipped 30 mm 0.15 mm off across its length (1.19 times its unmoved scan's distance from the
 * truth); from the most alike alone 0.08 (1.10 times); weighed as here 1.10 times, and the sum
 * of the 35 ratios 36.06 -> 35.90. Two passes over the views (the weights first): no array of
 * them on the stack. */
static void add_hues_alike(struct reg_ctx *r, struct lsq_rigid *eq, const struct reg_cell *cl,
                           const struct frame_xform *pose, vec3 p, vec3 n, double min_cos,
                           double gate_mm, double weight)
{
    double mine[9], sum = 0.0;
    const struct reg_cell *hit;
    vec3 q, nq;
    cell_footprint(cl, pose, mine);
    for (uint32_t j = 0; j < r->views; j++)
        sum += alike_weight(r, j, mine, p, n, min_cos, gate_mm, &hit, &q, &nq);
    for (uint32_t j = 0; j < r->views && sum > 0.0; j++) {
        double w = alike_weight(r, j, mine, p, n, min_cos, gate_mm, &hit, &q, &nq);
        if (w > 0.0)
            add_hue_rows(r, eq, cl, p, hit, q, nq, min_cos, 4.0 * gate_mm, weight * w / sum);
    }
}

/* The hues' equations @p hues added to the shape's @p eq along the motions the shape does not
 * hold: each shift axis it holds under REG_COLOUR_MIN_NEXT of its pairs (@p share, @p axis as
 * lsq_rigid_shift_axes gives them) and, with @p turn, the turn about the table's axis (object
 * frame z). The hues' block projected onto those motions: each shift axis on its own and the
 * turn with each (two shift axes coupled too: measured on the 35 slipped parts, the box pushed
 * 30 mm in 6 views 0.081 -> 0.084 mm, slipped 6 mm in 6 views 0.070 -> 0.066, the rest the
 * same; not made). */
static void hues_along(struct lsq_rigid *eq, const struct lsq_rigid *hues, const double share[3],
                       const vec3 axis[3], int turn)
{
    double basis[4][6]; /* the motions, unit 6-vectors (turns, then shifts) */
    int count = 0;
    for (int k = 0; k < 3; k++)
        if (share[k] < REG_COLOUR_MIN_NEXT) {
            const double u[6] = {0.0, 0.0, 0.0, axis[k].x, axis[k].y, axis[k].z};
            memcpy(basis[count++], u, sizeof(u));
        }
    if (turn) {
        const double t[6] = {0.0, 0.0, 1.0, 0.0, 0.0, 0.0};
        memcpy(basis[count++], t, sizeof(t));
    }
    for (int i = 0; i < count; i++) {
        double b_i = 0.0;
        for (int r = 0; r < 6; r++)
            b_i += basis[i][r] * hues->b[r];
        for (int r = 0; r < 6; r++)
            eq->b[r] += b_i * basis[i][r]; /* b += (s_i . b_h) s_i */
        for (int j = 0; j < count; j++) {
            if (j != i && basis[i][2] == 0.0 && basis[j][2] == 0.0)
                continue; /* two shift axes: each on its own */
            double h_ij = 0.0;
            for (int r = 0; r < 6; r++)
                for (int c = 0; c < 6; c++)
                    h_ij += basis[i][r] * hues->a[r * 6 + c] * basis[j][c];
            for (int r = 0; r < 6; r++) /* A += (s_i^T H s_j) s_i s_j^T */
                for (int c = 0; c < 6; c++)
                    eq->a[r * 6 + c] += h_ij * basis[i][r] * basis[j][c];
        }
    }
}

/* The group-1 samples against the group-0 views: one point-to-plane step of first_from_second
 * per call (object frame 1); with @p hue_weight > 0 their hues as well, where they land on paint
 * that changes (add_hue_rows): the colour holds what the shape lets slide.
 * @retval pairs coupled; @p rms their residual, @p overlap the samples that landed on a group-0
 * surface facing the same way (coupled or not), @p hold how well the pairs hold a shift in every
 * direction: @p share and @p axis as lsq_rigid_shift_axes gives them (share[0] is
 * lsq_rigid_shift_hold), of the shape's pairs alone. @p hold_turn: the turn about the table's
 * axis (object frame z) is not moved (untwist_placement says why) */
static uint32_t refine_second_step(struct reg_ctx *r, double gate_mm, double hue_weight,
                                   int hold_turn, double *rms, uint32_t *overlap, double share[3],
                                   vec3 axis[3])
{
    *overlap = 0;
    const double min_cos = cos(r->p.max_normal_deg * M_PI / 180.0);
    struct lsq_rigid eq, hues;
    lsq_rigid_clear(&eq);
    lsq_rigid_clear(&hues);
    reg_prepare_landing(r);
    /* The shape's pairs from every second cell (thousands of them: plenty), the hues from every
     * cell. A paint boundary crosses few cells, and every second cell of a grid kept row by row is
     * every second column: a boundary running up the image was seen at one phase of the grid, 8
     * pixels apart, in every step. Measured on the parts of data/objects slipped in 6, 8 and 12
     * views (35 scans, 2026-12-06): the views after the slip were placed 0.06 to 0.13 mm off along
     * the faces they slid on (the stepped block slipped 6 mm, the box pushed 30 mm); with the hues
     * of every cell the models came 4% closer to the truth in all (the hex nut pushed 30 mm in 6
     * views 0.098 -> 0.065 mm, the stepped block 0.068 -> 0.056, the box 0.064 -> 0.055), four
     * of the 35 worse by at most 0.004 mm. Twice the hues at half the weight gave the same; the
     * weight doubled at every second cell, nothing. */
    const size_t step = hue_weight > 0.0 ? 1 : 2;
    double lever_sq = 0.0; /* the pairs' squared distance from the table's axis */
    for (uint32_t v = 0; v < r->views; v++) {
        struct frame_xform pose;
        struct reg_view rv;
        if (!r->group[v] || reg_view_pose(r, v, &pose, &rv) != 0)
            continue;
        for (size_t k = 0; k < reg_cell_count(r); k += step) {
            const struct reg_cell *cl = &reg_view_cells(r, v)[k];
            const int shape = k % 2 == 0;
            vec3 p, n, q, nq;
            int landed;
            if (!cl->valid)
                continue;
            cell_in_object(cl, &pose, &p, &n);
            const struct reg_cell *hit =
                land(r, p, n, min_cos, gate_mm, hue_weight > 0.0, &landed, &q, &nq);
            if (hit != NULL && shape) {
                lsq_rigid_add(&eq, p, q, nq);
                lever_sq += p.x * p.x + p.y * p.y;
            }
            if (hit != NULL && hue_weight > 0.0)
                add_hues_alike(r, &hues, cl, &pose, p, n, min_cos, gate_mm, hue_weight);
            *overlap += shape ? (uint32_t)landed : 0u;
        }
    }
    uint32_t coupled = eq.pairs;
    *rms = coupled > 0 ? sqrt(eq.sq / coupled) : 0.0;
    if (lsq_rigid_shift_axes(&eq, share, axis) != 0)
        memset(share, 0, 3 * sizeof(double)); /* no pairs: holds nothing */
    /* The hues only along the motions the shape does not hold: the shift axes it lets slide
     * (where the colour search looked, reg_place_by_colour), and the turn about the table's axis
     * where the pairs see under REG_COLOUR_MIN_NEXT of it (their information on the turn over
     * what normals square to it would give, their squared distance from the axis). Elsewhere the
     * shape's thousands of pairs fix the motion and the paint's few boundaries add nothing but
     * their noise. Measured on the box of data/objects slipped 30 mm, against the simulator's true
     * poses: the hues on every motion turned the views after the slip 0.25 to 0.3 degrees and
     * tilted them 0.17; on the shifts the shape lets slide only, 0.06 to 0.15 and 0.01
     * (REG_COLOUR_ITERATIONS). A long thin part's top and two small ends barely see its turn: the
     * thin box slipped 6 mm along its length in 8 views, 0.5 % of it seen, was placed turned 0.3
     * degrees (0.3 mm at its ends; its model 1.20 times its unmoved scan's distance from the
     * truth); with the paint on the turn, 0.1 degrees and 1.03 times (2026-12-06). The other
     * parts placed with one free shift see 3.8 % (the plate with holes) to 11 %; those under 5 %
     * changed by 0.001 mm at most. */
    if (hue_weight > 0.0)
        hues_along(&eq, &hues, share, axis,
                   !hold_turn && eq.a[2 * 6 + 2] < REG_COLOUR_MIN_NEXT * lever_sq);
    if (hold_turn) { /* x[2], the turn about z, fixed at 0 */
        for (int i = 0; i < 6; i++)
            eq.a[2 * 6 + i] = eq.a[i * 6 + 2] = 0.0;
        eq.a[2 * 6 + 2] = 1.0;
        eq.b[2] = 0.0;
    }
    struct frame_xform s, moved;
    if (lsq_rigid_step(&eq, &s) == 0) {
        frame_compose(&s, &r->first_from_second, &moved);
        r->first_from_second = moved;
    }
    return coupled;
}

/* The first view of group 1 in the ring's order: after a group-0 view, or view 0's pass's end. */
uint32_t reg_first_of_group(const struct reg_ctx *r)
{
    for (uint32_t v = 0; v < r->views; v++)
        if (r->group[v] && (v == 0 || !r->group[v - 1]))
            return v;
    return 0;
}

/* Group 1 (the second pass, or the views the object moved for) found in group 0 without a
 * starting pose (align.h), then refined against group 0's views; a group that matches nothing
 * fails the registration at its first view. */
void reg_align_group(struct reg_ctx *r, struct reg_report *rep)
{
    struct align_params ap = {r->p.max_pair_mm, r->p.max_normal_deg, r->p.min_coupled_share};
    struct align_report ar;
    r->second_aligned = 0; /* the second pass's points in its own frame */
    feed_alignment(r);
    if (align_solve(&r->align, &ap, &r->first_from_second, &ar) != 0 || !ar.found) {
        rep->failed_view = (int)reg_first_of_group(r);
        rep->failed_against = -1;
        rep->failed_share = ar.coupled_share;
        return;
    }
    r->second_aligned = 1;
    double rms = 0.0;
    uint32_t overlap;
    for (int it = 0; it < 15; it++)
        rep->second_coupled = refine_second_step(r, r->p.max_pair_mm, 0.0, 0, &rms, &overlap,
                                                 r->placed_share, r->placed_axis);
    rep->second_rms_mm = rms;
    rep->second_turned_deg = ar.turned_deg;
    rep->second_share = ar.coupled_share;
}

/* Whether a placement fits as well as the views of one arc fit each other (reg_place_near_table
 * says why and what was measured). */
static int placement_fits(const struct reg_ctx *r, uint32_t coupled, uint32_t overlap, double rms,
                          double ring_rms_mm)
{
    return overlap > 0 && coupled >= 2.0 * r->p.min_coupled_share * overlap &&
           rms <= 2.0 * ring_rms_mm + 0.02;
}

/* Group 1 placed by ICP against group 0's views from where the table put it, with pairs
 * searched @p reach x max_pair_mm away first (8: an object knocked by a few millimetres, a few
 * degrees; 32: pushed by a few centimetres).
 * A placement is taken when it fits as well as the views of one arc fit each other
 * (placement_fits): twice min_coupled_share of its overlap with group 0 coupled, their residual
 * within twice the arcs' own (@p ring_rms_mm) and 0.02 mm. Measured: 0.75 and 0.91 coupled at the
 * arcs' residual for a slipped bunny and a slipped group of spheres; another object from the slip
 * on (spheres 1.4 times as large) couples 0.52 at 60 times the residual.
 * @retval 1 placed */
int reg_place_near_table(struct reg_ctx *r, double ring_rms_mm, double reach)
{
    double rms = 0.0;
    uint32_t coupled = 0, overlap = 0;
    r->first_from_second = (struct frame_xform){{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}};
    r->second_aligned = 1;
    for (int it = 0; it <= 20; it++) {
        double gate = r->p.max_pair_mm * fmax(1.0, reach / (double)(1u << (it < 8 ? it : 8)));
        coupled = refine_second_step(r, it < 20 ? gate : r->p.max_pair_mm, 0.0, 0, &rms, &overlap,
                                     r->placed_share, r->placed_axis);
    }
    r->second_aligned = placement_fits(r, coupled, overlap, rms, ring_rms_mm);
    return r->second_aligned;
}

/* A placement is trusted only where its pairs hold a shift in every direction: under this share
 * of them along the weakest (lsq_rigid_shift_hold), a shift there moves no residual: a box whose
 * overlaps across the break are two parallel faces and its top could slide along them. Measured:
 * the box of data/objects slipped 6 mm in 8 views held 0.004 (placed, its model was 0.6 mm off;
 * now refused), the bunny slipped in 4 views 0.035 (placed to 0.06 mm). */
#define REG_PLACE_MIN_HOLD 0.015
int reg_placement_holds(const struct reg_ctx *r)
{
    return r->placed_share[0] >= REG_PLACE_MIN_HOLD;
}

/* The colour search: a direction the shape does not hold is searched this far each way, in
 * steps of REG_COLOUR_STEP_MM, then to a tenth of that about the best; two directions on a grid
 * from 4 mm steps down to 0.05 mm (reg_place_by_colour). */
#define REG_COLOUR_SEARCH_MM 40.0
#define REG_COLOUR_STEP_MM 0.5
/* The hue of group 0's surface at grid position @p grid_xy of the view whose cell @p hit (at
 * @p q, facing @p nq) a sample landed on: bilinear between the four cells about it when they
 * all lie on that surface (within @p reach_mm, facing within @p min_cos), else @p hit's own. A
 * hue taken at the nearest cell would step by a cell (1.5 to 2 mm on the object at a stride of
 * 4 pixels) as the search moves, hiding where the paint lines up between the steps.
 * @retval 0 too dark to tell */
static int hue_between(struct reg_ctx *r, const struct reg_cell *hit, vec3 q, vec3 nq,
                       const double grid_xy[2], double min_cos, double reach_mm, double hue[2])
{
    uint32_t j;
    cell_place(r, hit, &j, NULL, NULL);
    long x0 = (long)floor(grid_xy[0]), y0 = (long)floor(grid_xy[1]);
    double fx = grid_xy[0] - (double)x0, fy = grid_xy[1] - (double)y0, sum[2] = {0.0, 0.0};
    if (x0 < 0 || y0 < 0 || x0 + 1 >= (long)r->gw || y0 + 1 >= (long)r->gh)
        return hue_of(hit, hue);
    for (int c = 0; c < 4; c++) {
        const struct reg_cell *cl =
            &reg_view_cells(r, j)[(size_t)(y0 + c / 2) * r->gw + (size_t)(x0 + c % 2)];
        double h[2], w = (c % 2 ? fx : 1.0 - fx) * (c / 2 ? fy : 1.0 - fy);
        vec3 qc, nc;
        if (!cl->valid || !hue_of(cl, h))
            return hue_of(hit, hue);
        cell_in_object(cl, &r->first_pose[j], &qc, &nc);
        if (v3_len(v3_sub(qc, q)) > reach_mm || v3_dot(nc, nq) < min_cos)
            return hue_of(hit, hue); /* an edge of the object: not one surface */
        sum[0] += w * h[0], sum[1] += w * h[1];
    }
    hue[0] = sum[0], hue[1] = sum[1];
    return 1;
}

/* The hue of group 0's surface where a sample (@p p, @p n in group 0's frame) lands: the mean of
 * what every group-0 view that sees it there reads (hue_between; never view @p skip, a group-0
 * sample's own). A view's bilinear reading of its cells' box-filtered colour puts a paint
 * boundary up to a tenth of a cell off, by where its grid falls on the boundary; the views' grids
 * fall differently, and their mean is nearer the paint. Measured on the parts of data/objects
 * slipped 6 and 30 mm in 6, 8 and 12 views (35 scans, 2026-12-06): the search's place for the box
 * pushed 30 mm in 6 views 0.23 and 0.14 mm off along its faces from the most facing view's
 * hue, 0.04 from the views' mean; with the refinement's hues from the views seen alike
 * (add_hues_alike) the box, refused before (its paint agreeing 3.2 times worse than its arcs'),
 * is placed 0.98 times its unmoved scan's distance from the truth.
 * @retval the views read (0: none) */
static int group0_hue(struct reg_ctx *r, vec3 p, vec3 n, double min_cos, uint32_t skip,
                      double hue[2])
{
    int count = 0;
    hue[0] = hue[1] = 0.0;
    for (uint32_t j = 0; j < r->views; j++) {
        int landed;
        double facing, grid_xy[2], h[2];
        vec3 q, nq;
        if (!r->present[j] || r->group[j] || j == skip)
            continue;
        const struct reg_cell *hit =
            land_in(r, j, p, n, min_cos, r->p.max_pair_mm, &landed, &facing, &q, &nq, grid_xy);
        if (hit == NULL || !hue_between(r, hit, q, nq, grid_xy, min_cos, 2.0 * r->p.max_pair_mm, h))
            continue;
        hue[0] += h[0], hue[1] += h[1], count++;
    }
    if (count > 0)
        hue[0] /= count, hue[1] /= count;
    return count;
}

/* How badly the colours of view @p v's samples, shifted by @p shift (group 0's frame), agree
 * with group 0's where they land (group0_hue): each bright enough sample that lands on
 * bright enough paint adds to @p compared and its hue's squared distance, truncated at
 * REG_HUE_TAU, to @p sum (every sample: the boundaries of the paint are a few of them). */
static void view_misfit(struct reg_ctx *r, uint32_t v, vec3 shift, double *sum, uint64_t *compared)
{
    const double min_cos = cos(r->p.max_normal_deg * M_PI / 180.0);
    struct frame_xform pose;
    struct reg_view rv;
    if (reg_view_pose(r, v, &pose, &rv) != 0)
        return;
    for (size_t k = 0; k < reg_cell_count(r); k++) {
        const struct reg_cell *cl = &reg_view_cells(r, v)[k];
        double hp[2], hq[2];
        vec3 p, n;
        if (!cl->valid || !hue_of(cl, hp))
            continue;
        cell_in_object(cl, &pose, &p, &n);
        if (group0_hue(r, v3_add(p, shift), n, min_cos, v, hq) == 0)
            continue;
        *sum += hue_miss(hp, hq);
        (*compared)++;
    }
}

/* How badly group 1's colours agree with group 0's with group 1 shifted by @p shift (group 0's
 * frame), over @p compared samples. @retval the misfit, 0 .. REG_HUE_TAU^2 (that when nothing
 * was compared) */
static double colour_misfit(struct reg_ctx *r, vec3 shift, uint64_t *compared)
{
    double sum = 0.0;
    *compared = 0;
    for (uint32_t v = 0; v < r->views; v++)
        if (r->group[v])
            view_misfit(r, v, shift, &sum, compared);
    return *compared > 0 ? sum / (double)*compared : REG_HUE_TAU * REG_HUE_TAU;
}

double reg_pair_colour_misfit(struct reg_ctx *r, uint32_t v, uint32_t w, uint64_t *compared)
{
    return reg_pair_colour_misfit_at(r, v, w, v3(0.0, 0.0, 0.0), compared);
}

double reg_pair_colour_misfit_at(struct reg_ctx *r, uint32_t v, uint32_t w, vec3 shift,
                                 uint64_t *compared)
{
    const double min_cos = cos(r->p.max_normal_deg * M_PI / 180.0);
    double sum = 0.0;
    *compared = 0;
    for (size_t k = 0; k < reg_cell_count(r); k++) {
        const struct reg_cell *cl = &reg_view_cells(r, v)[k];
        double hp[2], hq[2], facing, grid_xy[2];
        vec3 p, n, q, nq;
        int landed;
        if (!cl->valid || !hue_of(cl, hp))
            continue;
        cell_in_object(cl, &r->first_pose[v], &p, &n);
        const struct reg_cell *cq = land_in(r, w, v3_add(p, shift), n, min_cos, r->p.max_pair_mm,
                                            &landed, &facing, &q, &nq, grid_xy);
        if (cq == NULL || !hue_of(cq, hq))
            continue;
        sum += hue_miss(hp, hq);
        (*compared)++;
    }
    return *compared > 0 ? sum / (double)*compared / (REG_HUE_TAU * REG_HUE_TAU) : 1.0;
}

/* The same among group 0's own views, which the ring registered together: how well an object's
 * paint lines up where its views are known to agree (its mixed pixels at the paint's boundaries,
 * its noise). @retval the misfit (REG_HUE_TAU^2 when nothing was compared) */
static double arc_colour_misfit(struct reg_ctx *r)
{
    double sum = 0.0;
    uint64_t compared = 0;
    for (uint32_t v = 0; v < r->views; v++)
        if (r->present[v] && !r->group[v])
            view_misfit(r, v, v3(0.0, 0.0, 0.0), &sum, &compared);
    return compared > 0 ? sum / (double)compared : REG_HUE_TAU * REG_HUE_TAU;
}

/* The search's best place is taken when its misfit is under this share of the mean over the
 * search (a clear dip where the paint lines up; a plain or evenly patterned object has none) with
 * this many samples compared there. Measured on the slipped parts of data/objects and the
 * simulator's box (painted in patches): 0.1 to 0.2; a box of one colour has no dip at all. */
#define REG_COLOUR_MAX_DIP 0.5
/* And once the shape and the hues have refined it, the placed views' colours agree with the
 * others' at most this many times as well as the others agree among themselves
 * (arc_colour_misfit: where views are known to line up, the pairs that disagree are those on
 * the paint's boundaries, mixed pixels, and the noise), as placement_fits asks of the shape's
 * residual, or at most REG_COLOUR_MAX_MISFIT of a full miss. Measured on the parts of data/objects
 * slipped 6 and 30 mm in 8 views (2026-12-05): 0.91 to 1.45 times (the arcs' own 0.043 to 0.088 of
 * a full miss). A bound on the search's misfit alone (0.14 of a full miss) refused the plate
 * slipped 30 mm, lined up at 0.17 before the refinement turned it the last tenth of a degree, 0.073
 * after, its arcs' 0.073; a cup slipped 30 mm, its shape fitting a wrong place, had lined up at
 * 0.20. */
#define REG_COLOUR_MAX_ARC_RATIO 2.0
/* The paint's boundaries alone: 0.07 to 0.10 of a full miss measured on the parts slipped in 8
 * views; the box of data/objects pushed 30 mm in 6 views, its arcs of three views agreeing
 * better (0.047), placed right at 0.134 (2.85 times; the model 0.087 mm from the truth). */
#define REG_COLOUR_MAX_MISFIT 0.14
#define REG_COLOUR_MIN_COMPARED 200
/* From the colour search's place, the shape and the hues refine the placement together
 * (refine_second_step), this many steps, a hue's residual weighing this many times a millimetre
 * of the shape's, the hues along the shifts the shape does not hold only. Measured on the box,
 * thin box, stepped block, L-bracket and plate of data/objects slipped 6 and 30 mm in 8 views
 * (2026-12-05, each cell's hue the mean of its pixels'): the hues on every motion gave 1.01 to
 * 1.54 times the scan without a slip (the box slipped 30 mm turned 0.3 deg and tilted 0.17 by
 * them); on those shifts only, 1.03 to 1.28. Before, with the hue of each cell's mean colour:
 * at the weight 1, 5 of 11 parts within 1.2 times; at 10, 6; at 100 the hues' noise turned the
 * gear 1.5 deg. */
#define REG_COLOUR_ITERATIONS 10
#define REG_HUE_WEIGHT 10.0

/* The placement moved by @p shift (the group-1 points, in group 0's frame). */
static void shift_placement(struct reg_ctx *r, vec3 shift)
{
    struct frame_xform move = {{1, 0, 0, 0, 1, 0, 0, 0, 1}, v3_scale(shift, -1.0)}, moved;
    frame_compose(&move, &r->first_from_second, &moved); /* p -> p - origin = p + shift */
    r->first_from_second = moved;
}

/* One level of the colour search: the grid of 2 @p half + 1 places @p step apart about
 * @p centre along each of the @p n axes; the best kept in @p at, @p best_misfit, @p compared.
 * @retval the level's mean misfit */
static double search_level(struct reg_ctx *r, const vec3 axes[2], int n, const double centre[2],
                           double step, int half, double at[2], double *best_misfit,
                           uint64_t *compared)
{
    double sum = 0.0;
    int count = 0;
    for (int i = -half; i <= half; i++)
        for (int j = n > 1 ? -half : 0; j <= (n > 1 ? half : 0); j++) {
            double a = centre[0] + i * step, b = centre[1] + j * step;
            uint64_t c;
            double m = colour_misfit(r, v3_add(v3_scale(axes[0], a), v3_scale(axes[1], b)), &c);
            sum += m, count++;
            if (m < *best_misfit && c >= REG_COLOUR_MIN_COMPARED) /* not a place seen by few */
                *best_misfit = m, at[0] = a, at[1] = b, *compared = c;
        }
    return sum / count;
}

/* The placement's turn about the table's axis (the object frames' z) taken off, its shift and
 * tilt kept: where the shape holds no shift along the table (a top, and little else), it holds
 * no turn about the table's axis either (a plane turns into itself), and ICP leaves one from
 * noise (the box slipped 6 mm in 6 views: 1.9 deg, its model 0.21 mm off); the colour search
 * moves shifts only, so it starts from the table's turn instead (the plate pushed 30 mm in 6
 * views: 4.4 deg taken off). The twist of a rotation about z is atan2(R10 - R01, R00 + R11),
 * exact for a turn about z alone. */
#define REG_UNTWIST_MAX_DEG 10.0 /* a larger turn is no noise: the shape found it, kept */
static void untwist_placement(struct reg_ctx *r)
{
    const double *m = r->first_from_second.rot;
    double phi = atan2(m[3] - m[1], m[0] + m[4]), c = cos(phi), s = sin(phi);
    if (fabs(phi) > REG_UNTWIST_MAX_DEG * M_PI / 180.0)
        return;
    struct frame_xform back = {{c, s, 0, -s, c, 0, 0, 0, 1}, {0, 0, 0}}, out;
    frame_compose(&back, &r->first_from_second, &out);
    r->first_from_second = out;
}

/* The placement moved along @p n (1 or 2) directions @p axes to where the colours agree, then
 * refined by the shape and the hues (reg_place_by_colour says how and when it is taken).
 * @retval 1 placed @retval 0 left as it was */
static int place_along(struct reg_ctx *r, const vec3 axes[2], int n, double ring_rms_mm)
{
    struct frame_xform before = r->first_from_second;
    if (n == 2)
        untwist_placement(r);
    /* Coarse to fine: a step, how many either way (the first level spans the search). */
    static const double levels[2][4][2] = {
        {{REG_COLOUR_STEP_MM, REG_COLOUR_SEARCH_MM / REG_COLOUR_STEP_MM},
         {REG_COLOUR_STEP_MM / 10.0, 10}},
        {{4.0, REG_COLOUR_SEARCH_MM / 4.0}, {1.0, 4}, {0.25, 4}, {0.05, 5}}};
    reg_prepare_landing(r);
    double at[2] = {0.0, 0.0}, best_misfit = HUGE_VAL, mean = 0.0;
    uint64_t best_compared = 0;
    for (int l = 0; l < 4 && levels[n - 1][l][0] > 0.0; l++) {
        double centre[2] = {at[0], at[1]};
        double m = search_level(r, axes, n, centre, levels[n - 1][l][0], (int)levels[n - 1][l][1],
                                at, &best_misfit, &best_compared);
        mean = l == 0 ? m : mean;
    }
    if (best_compared < REG_COLOUR_MIN_COMPARED || !(best_misfit < REG_COLOUR_MAX_DIP * mean)) {
        r->first_from_second = before;
        return 0; /* no dip: plain paint (all grey: 0 everywhere) or nothing compared */
    }
    shift_placement(r, v3_add(v3_scale(axes[0], at[0]), v3_scale(axes[1], at[1])));
    double rms = 0.0, share[3];
    uint32_t overlap = 0, coupled = 0;
    vec3 axis[3];
    for (int it = 0; it < REG_COLOUR_ITERATIONS; it++) /* shape and colour: every direction */
        coupled = refine_second_step(r, r->p.max_pair_mm, REG_HUE_WEIGHT, n == 2, &rms, &overlap,
                                     share, axis);
    uint64_t compared;
    double misfit = colour_misfit(r, v3(0.0, 0.0, 0.0), &compared);
    if (!placement_fits(r, coupled, overlap, rms, ring_rms_mm) ||
        compared < REG_COLOUR_MIN_COMPARED ||
        (misfit > REG_COLOUR_MAX_ARC_RATIO * arc_colour_misfit(r) &&
         misfit > REG_COLOUR_MAX_MISFIT * REG_HUE_TAU * REG_HUE_TAU)) {
        r->first_from_second = before; /* where the paint agrees the shape does not, or the
                                          paint agrees worse than the views of an arc */
        return 0;
    }
    r->placed_by_colour = n;
    return 1;
}

int reg_place_by_colour(struct reg_ctx *r, double ring_rms_mm)
{
    /* One free direction (two parallel faces and a top), or two (a plate: its top and little
     * else), the shape holding the rest. */
    int n = r->placed_share[1] >= REG_COLOUR_MIN_NEXT ? 1 : 2;
    if (!r->second_aligned || r->placed_share[2] < REG_COLOUR_MIN_NEXT)
        return 0;
    const vec3 axes[2] = {r->placed_axis[0], n > 1 ? r->placed_axis[1] : v3(0, 0, 0)};
    return place_along(r, axes, n, ring_rms_mm);
}

int reg_place_slid_by_colour(struct reg_ctx *r, double ring_rms_mm)
{
    static const vec3 table_plane[2] = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}}; /* object frame */
    if (reg_placement_holds(r))
        return 0; /* the shape held every direction and did not fit: no slide */
    r->first_from_second = (struct frame_xform){{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}};
    r->second_aligned = 1; /* group 1 where the table put it, moved by the search */
    r->second_aligned = place_along(r, table_plane, 2, ring_rms_mm);
    return r->second_aligned;
}

/* The paint's search for a turn the shape does not fix (reg_turn_by_paint): turns this far apart
 * (0.26 mm at 60 mm from the axis, a sixth of a sample's cell), at most REG_PAINT_TURN_MAX of
 * them; the V fitted through them (v_bottom) taken where its flanks rise, at the search's ends,
 * REG_PAINT_TURN_MIN_RISE times its bottom or more (the thin box end on: 0.91; a plain paint,
 * nothing compared or a flat curve: none). */
#define REG_PAINT_TURN_STEP_DEG 0.25
#define REG_PAINT_TURN_MAX 256
#define REG_PAINT_TURN_MIN_RISE 0.5

/* View @p v's pose (and its inverse) for landing at angle @p theta_rad, the axis as solved. */
static void pose_at(struct reg_ctx *r, uint32_t v, double theta_rad)
{
    struct reg_view rv;
    r->theta[v] = theta_rad;
    if (reg_view_pose(r, v, &r->first_pose[v], &rv) == 0)
        frame_invert(&r->first_pose[v], &r->first_cam[v]);
}

/* How badly view @p v's hues and its @p n registered neighbours' @p nb agree, both ways, as a
 * share of a full miss over @p compared samples. */
static double turn_misfit(struct reg_ctx *r, uint32_t v, const uint32_t *nb, int n,
                          uint64_t *compared)
{
    double sum = 0.0;
    *compared = 0;
    for (int k = 0; k < 2 * n; k++) {
        uint64_t c;
        uint32_t a = k % 2 ? nb[k / 2] : v, b = k % 2 ? v : nb[k / 2];
        double m = reg_pair_colour_misfit(r, a, b, &c);
        sum += m * (double)c;
        *compared += c;
    }
    return *compared > 0 ? sum / (double)*compared : 1.0;
}

/* Where a misfit curve sampled at @p n turns @p d (degrees) has its bottom: the symmetric V
 * m = b + s |d - d0| fitted by least squares for each d0 within @p span_deg, 0.01 degree apart,
 * the best kept (@p b, @p s). The paint's boundaries make the curve a V whose flanks are clear
 * and whose bottom is flat within the noise (mixed pixels at the boundaries, cells 1.5 to 2 mm
 * apart): the thin box of data/objects seen end on, its table 0.61 degrees off, bottomed
 * anywhere from 0.5 to 1.0 degrees, its flanks met at 0.58. @retval d0 */
static double v_bottom(const double *d, const double *m, int n, double span_deg, double *b,
                       double *s)
{
    double best_sse = HUGE_VAL, at = 0.0;
    *b = *s = 0.0;
    for (double d0 = -span_deg; d0 <= span_deg + 1e-9; d0 += 0.01) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
        for (int i = 0; i < n; i++) {
            double x = fabs(d[i] - d0);
            sx += x, sy += m[i], sxx += x * x, sxy += x * m[i], syy += m[i] * m[i];
        }
        double det = n * sxx - sx * sx;
        if (!(det > 0.0))
            continue;
        double slope = (n * sxy - sx * sy) / det, base = (sy - slope * sx) / n;
        double sse = syy - base * sy - slope * sxy;
        if (slope > 0.0 && sse < best_sse)
            best_sse = sse, at = d0, *b = base, *s = slope;
    }
    return at;
}

int reg_turn_by_paint(struct reg_ctx *r, uint32_t v, double span_deg)
{
    uint32_t nb[2];
    int n = 0;
    for (uint32_t e = 0; e < r->edges && n < 2; e++) {
        uint32_t w = r->edge_from[e] == v ? r->edge_to[e]
                     : r->edge_to[e] == v ? r->edge_from[e]
                                          : v;
        if (w != v && reg_turn_registered(r, w))
            nb[n++] = w;
    }
    if (n == 0 || span_deg < 2.0 * REG_PAINT_TURN_STEP_DEG)
        return 0; /* no neighbour registered by its shape to turn against (a surface of
                     revolution: none is); no room to search */
    const double start = r->theta[v], rad = M_PI / 180.0;
    for (int k = 0; k < n; k++)
        pose_at(r, nb[k], r->theta[nb[k]]);
    static double d[REG_PAINT_TURN_MAX], m[REG_PAINT_TURN_MAX];
    int count = 0, half = (int)fmin(span_deg / REG_PAINT_TURN_STEP_DEG, REG_PAINT_TURN_MAX / 2 - 1);
    for (int i = -half; i <= half; i++) {
        uint64_t c;
        pose_at(r, v, start + i * REG_PAINT_TURN_STEP_DEG * rad);
        double mi = turn_misfit(r, v, nb, n, &c);
        if (c >= REG_COLOUR_MIN_COMPARED)
            d[count] = i * REG_PAINT_TURN_STEP_DEG, m[count++] = mi;
    }
    double b = 0.0, s = 0.0, span = half * REG_PAINT_TURN_STEP_DEG;
    double at = count >= half ? v_bottom(d, m, count, span, &b, &s) : 0.0;
    /* a clear V: at the search's ends half as bad again as at its bottom, and not at an end */
    int taken = count >= half && s * span >= REG_PAINT_TURN_MIN_RISE * b &&
                fabs(at) <= span - 2.0 * REG_PAINT_TURN_STEP_DEG;
    pose_at(r, v, taken ? start + at * rad : start);
    return taken;
}
