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

/* The group-1 samples against the group-0 views, projectively, as the views of a pass are
 * paired: one point-to-plane step of first_from_second per call (object frame 1).
 * @retval pairs coupled; @p rms their residual, @p overlap the samples that landed on a group-0
 * surface facing the same way (coupled or not), @p hold how well the pairs hold a shift in every
 * direction (lsq_rigid_shift_hold) */
static uint32_t refine_second_step(struct reg_ctx *r, double gate_mm, double *rms,
                                   uint32_t *overlap, double *hold)
{
    *overlap = 0;
    const double min_cos = cos(r->p.max_normal_deg * M_PI / 180.0);
    struct lsq_rigid eq;
    lsq_rigid_clear(&eq);
    struct frame_xform *first = r->first_pose, *cam_of = r->first_cam; /* too big for a stack */
    struct reg_view rv;
    for (uint32_t j = 0; j < r->views; j++)
        if (!r->group[j] && reg_view_pose(r, j, &first[j], &rv) == 0)
            frame_invert(&first[j], &cam_of[j]);
    for (uint32_t v = 0; v < r->views; v++) {
        struct frame_xform pose;
        if (!r->group[v] || reg_view_pose(r, v, &pose, &rv) != 0)
            continue;
        for (size_t k = 0; k < reg_cell_count(r); k += 2) {
            const struct reg_cell *cl = &reg_view_cells(r, v)[k];
            if (!cl->valid)
                continue;
            vec3 p, n;
            int landed = 0;
            cell_in_object(cl, &pose, &p, &n);
            for (uint32_t j = 0; j < r->views; j++) {
                if (!r->present[j] || r->group[j])
                    continue;
                vec3 c = frame_point(&cam_of[j], p);
                if (c.z <= 1.0 || v3_dot(frame_dir(&cam_of[j], n), c) >= 0.0)
                    continue; /* behind the camera, or facing away from it */
                double fu, fv;
                camray_project(&r->calib, c, &fu, &fv);
                long u = lround(fu / r->stride), w = lround(fv / r->stride);
                if (u < 0 || w < 0 || u >= (long)r->gw || w >= (long)r->gh)
                    continue;
                const struct reg_cell *cq = &reg_view_cells(r, j)[(size_t)w * r->gw + (size_t)u];
                if (!cq->valid)
                    continue;
                vec3 q, nq;
                cell_in_object(cq, &first[j], &q, &nq);
                if (v3_dot(n, nq) < min_cos)
                    continue;
                landed = 1; /* on a surface of group 0 facing its way */
                if (v3_len(v3_sub(p, q)) > gate_mm)
                    continue;
                lsq_rigid_add(&eq, p, q, nq);
                break; /* one pair a point: the first view that sees it */
            }
            *overlap += (uint32_t)landed;
        }
    }
    uint32_t coupled = eq.pairs;
    *rms = coupled > 0 ? sqrt(eq.sq / coupled) : 0.0;
    *hold = lsq_rigid_shift_hold(&eq);
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
    double rms = 0.0, hold;
    uint32_t overlap;
    for (int it = 0; it < 15; it++)
        rep->second_coupled = refine_second_step(r, r->p.max_pair_mm, &rms, &overlap, &hold);
    r->placed_hold = hold;
    rep->second_rms_mm = rms;
    rep->second_turned_deg = ar.turned_deg;
    rep->second_share = ar.coupled_share;
}

/* Group 1 placed by ICP against group 0's views from where the table put it, with pairs
 * searched 8 x max_pair_mm away first (an object knocked by a few millimetres, a few degrees).
 * A placement is taken when it fits as well as the views of one arc fit each other: twice
 * min_coupled_share of its overlap with group 0 coupled, their residual within twice the
 * arcs' own (@p ring_rms_mm) and 0.02 mm. Measured: 0.75 and 0.91 coupled at the arcs'
 * residual for a slipped bunny and a slipped group of spheres; another object from the slip on
 * (spheres 1.4 times as large) couples 0.52 at 60 times the residual.
 * @retval 1 placed */
int reg_place_near_table(struct reg_ctx *r, double ring_rms_mm)
{
    double rms = 0.0, hold = 0.0;
    uint32_t coupled = 0, overlap = 0;
    r->first_from_second = (struct frame_xform){{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 0}};
    r->second_aligned = 1;
    for (int it = 0; it < 20; it++) {
        double gate = r->p.max_pair_mm * fmax(1.0, 8.0 / (double)(1u << (it < 8 ? it : 8)));
        coupled = refine_second_step(r, gate, &rms, &overlap, &hold);
    }
    coupled = refine_second_step(r, r->p.max_pair_mm, &rms, &overlap, &hold);
    r->placed_hold = hold;
    r->second_aligned = overlap > 0 && coupled >= 2.0 * r->p.min_coupled_share * overlap &&
                        rms <= 2.0 * ring_rms_mm + 0.02;
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
    return r->placed_hold >= REG_PLACE_MIN_HOLD;
}
