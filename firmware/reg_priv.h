/* What the registration's files share (reg.c, reg_breaks.c, reg_place.c): not for other modules,
 * which go through reg.h. */
#ifndef REG_PRIV_H
#define REG_PRIV_H

#include "reg.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* A surface facing up or down (a top, a plate lying flat) turns and slides into itself under a
 * move across the table: its samples pair wherever the views stand. Whether two views match is
 * judged on the surfaces that face sideways, normals more than REG_SIDE_COS (about 26 degrees)
 * away from the axis, when there are REG_SIDE_MIN of them; else on all. Measured: a plate, a hex
 * nut, a gear and a thin box slipped 6 mm still coupled over a fifth of all their overlap (their
 * tops), so the slip went unseen and the model came out 0.4 to 1.5 mm off. */
#define REG_SIDE_COS 0.9
#define REG_SIDE_MIN 200u
/* Where the ring's median pair has REG_SIDE_MIN sideways samples, a pair with fewer is judged on
 * its sides still when it has REG_SIDE_EVIDENCE of them: the object moved between its two views,
 * its sides no longer land on each other but for a few by chance, and the rest of its overlap
 * is its top. Measured: slipped 30 mm, the parts of data/objects and the torus kept 7 to 139
 * sideways samples at the two pairs across the slip (against 400 to 3800 at the others), 0 or 1
 * coupled; judged on all, a third coupled and their models came out 2 to 5 mm off. A pair with
 * no sideways sample in common is no evidence (a box in 5 views: the last and the first see no
 * side face in common) and is judged on all. */
#define REG_SIDE_EVIDENCE 5u

/* Raw colours darker than this (sum of the channels) have no chromaticity or hue to compare
 * (reg.c's colour gate, reg_place.c's colour search). */
#define REG_COLOUR_MIN_DN 30.0

/* A colour whose distance from grey is under this share of its brightness is grey. */
#define REG_HUE_MIN_SATURATION 0.15
/* A cell's hue[0] when its pixels are too dark to have one; hue[1] is then REG_UNCOLOURED when
 * none of them had a colour at all (every light shadowed there, colour.h), else 0. */
#define REG_NO_HUE INT16_MIN
#define REG_UNCOLOURED 1

/* @retval 1 no pixel of cell @p cl had a colour: there is nothing to compare it by */
static inline int reg_cell_uncoloured(const struct reg_cell *cl)
{
    return cl->hue[0] == REG_NO_HUE && cl->hue[1] == REG_UNCOLOURED;
}

/* A colour's hue: the unit direction of its distance from grey, in the plane across the grey
 * axis. The same under any brightness of white light and under any grey added to it (ambient
 * light, the projector's black), so that raw colours, shaded and lit differently in each view,
 * compare as the paint's. A colour too close to grey has none: it is grey (hue 0, 0), which
 * matches grey only (were it left out, a patch of white paint would match anything and pull
 * the search towards it). @retval 0 too dark to tell */
static inline int reg_hue_of(const double rgb[3], double hue[2])
{
    double mean = (rgb[0] + rgb[1] + rgb[2]) / 3.0;
    double x = (rgb[0] - rgb[1]) / sqrt(2.0);
    double y = (rgb[0] + rgb[1] - 2.0 * rgb[2]) / sqrt(6.0);
    double len = sqrt(x * x + y * y);
    hue[0] = hue[1] = 0.0;
    if (3.0 * mean < REG_COLOUR_MIN_DN)
        return 0;
    if (len >= REG_HUE_MIN_SATURATION * mean)
        hue[0] = x / len, hue[1] = y / len;
    return 1;
}

/* The kept samples of one view: gw x gh cells. */
static inline size_t reg_cell_count(const struct reg_ctx *r)
{
    return (size_t)r->gw * r->gh;
}

static inline struct reg_cell *reg_view_cells(struct reg_ctx *r, uint32_t v)
{
    return &r->cells[(size_t)v * reg_cell_count(r)];
}

/* The first view of group 1 in the ring's order. */
uint32_t reg_first_of_group(const struct reg_ctx *r);

/* Group 1 (the second pass, or the views the object moved for) found in group 0 without a
 * starting pose, then refined against group 0's views; one that matches nothing fails the
 * registration at its first view (@p rep). */
void reg_align_group(struct reg_ctx *r, struct reg_report *rep);

/* Group 1 placed by ICP from where the table put it, pairs searched @p reach x max_pair_mm away
 * first. @retval 1 placed (second_aligned) */
int reg_place_near_table(struct reg_ctx *r, double ring_rms_mm, double reach);

/* Where ICP from the table's place (reg_place_near_table) found no placement that fits and
 * its pairs did not hold every shift, group 1 searched by its colour across the table from the
 * table's place (reg_place_by_colour), taken only where the shape fits too.
 * @retval 1 placed (placed_by_colour) */
int reg_place_slid_by_colour(struct reg_ctx *r, double ring_rms_mm);

/* @retval 1 the last placement's pairs hold a shift in every direction */
int reg_placement_holds(const struct reg_ctx *r);

/* The last placement, whose shape holds every direction but one or two (placed_axis[0], [1]),
 * moved along them to where the two groups' colours agree (their hues: raw colours compare as
 * the paint's), then refined by the shape and the hues together (Park, Zhou and Koltun 2017),
 * and taken when the shape still fits there as a placement near the table must
 * (@p ring_rms_mm).
 * @retval 1 placed (placed_by_colour)
 * @retval 0 the colour does not fix it either: the placement is left as it was */
int reg_place_by_colour(struct reg_ctx *r, double ring_rms_mm);

/* Group 0's poses and their inverses, where its views are landed on (first_pose, first_cam). */
void reg_prepare_landing(struct reg_ctx *r);

/* How badly view @p w's hues agree with view @p v's where @p v's samples land on @p w's surface
 * at the views' poses (both of group 0, after reg_prepare_landing), over @p compared samples,
 * as a share of a full miss. @retval 0 .. 1 */
double reg_pair_colour_misfit(struct reg_ctx *r, uint32_t v, uint32_t w, uint64_t *compared);

/* The same with @p v's samples moved by @p shift (group 0's object frame, mm) first. */
double reg_pair_colour_misfit_at(struct reg_ctx *r, uint32_t v, uint32_t w, vec3 shift,
                                 uint64_t *compared);

/* @retval 1 view @p v's turn is registered by its shape (not the first of its pass, which fixes
 * the pass's frame, nor kept at the table's angle) */
int reg_turn_registered(const struct reg_ctx *r, uint32_t v);

/* View @p v, whose turn about the axis its shape does not fix, turned within @p span_deg of its
 * angle to where its paint and its neighbours' whose turns are registered agree (the hues, as the
 * colour search compares them), when the paint draws a clear V there; its first_pose and
 * first_cam, and its neighbours', at the poses (use_solution set).
 * @retval 1 turned
 * @retval 0 left (no such neighbour, plain paint, or no clear V) */
int reg_turn_by_paint(struct reg_ctx *r, uint32_t v, double span_deg);

/* The share of edge @p e's overlap that couples (@p st: its counts), on its sideways surfaces
 * where they are enough to judge by. */
double reg_edge_share(const struct reg_ctx *r, const struct reg_edge_stats *st);

/* @retval 1 edge @p e's views share no surface to compare (and each sees something) */
int reg_edge_apart(const struct reg_ctx *r, uint32_t e);

/* @retval 1 edge @p e's views do not match (they overlap and too little couples), or the ring
 * was cut after it */
int reg_edge_fails(const struct reg_ctx *r, uint32_t e);

/* The breaks of a ring its pairs' shapes let through (a push along the object's faces), marked
 * in quiet_break_after, the first said in @p rep as the failed pair.
 * @retval 1 one or more @retval 0 none */
int reg_find_quiet_breaks(struct reg_ctx *r, struct reg_report *rep);

/* A ring that breaks at exactly two pairs cut into two arcs (cut_after; the arc without view 0
 * becomes group 1). @retval 1 cut @retval 0 not so */
int reg_cut_at_the_move(struct reg_ctx *r);

/* @retval 1 every pair of neighbouring views of group 0 (all of them, or the arc with view 0
 * after a slip) looks alike as the two stand, on REG_SIDE_MIN sideways samples or more (the
 * object's symmetry matches the table's step: its pairs cannot place the axis) */
int reg_views_alike(struct reg_ctx *r);

#endif
