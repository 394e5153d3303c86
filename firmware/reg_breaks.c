/* Whether two neighbouring views of a ring match, and where the ring breaks (reg.h): the pairs
 * judged on the surfaces that face sideways or shown to share none, the breaks a push along the
 * object's faces leaves its shape blind to (the paint misses, or two pairs share no surface),
 * and the ring cut into the two arcs the views placed freely are taken from (reg_place.c). */
#include "reg.h"
#include "reg_priv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static uint32_t side_median(const struct reg_ctx *r)
{
    uint32_t median = 0;
    int found = 0;
    for (uint32_t e = 0; e < r->edges; e++) { /* the least value with half the pairs at or under */
        uint32_t x = r->stats[e].side_overlap, n = 0;
        for (uint32_t f = 0; f < r->edges; f++)
            n += r->stats[f].side_overlap <= x;
        if (2 * n >= r->edges && (!found || x < median))
            median = x, found = 1;
    }
    return median;
}

double reg_edge_share(const struct reg_ctx *r, const struct reg_edge_stats *st)
{
    if (st->side_overlap >= REG_SIDE_MIN ||
        (st->side_overlap >= REG_SIDE_EVIDENCE && side_median(r) >= REG_SIDE_MIN))
        return (double)st->side_coupled / st->side_overlap;
    return st->overlap > 0 ? (double)st->coupled / st->overlap : 0.0;
}

/* Two neighbouring views share no surface to compare when the samples of one that land on a
 * surface of the other facing the same way are fewer than this share of the smaller view's
 * samples (two views half a turn apart see opposite sides: none land), while each view sees
 * something (REG_MIN_VIEW_SAMPLES): the pair says nothing, the table's angle stands, no failure.
 * A view of nothing (fewer samples) still fails, as does a pair that overlaps and does not
 * couple (the object moved, another object). */
#define REG_APART_SHARE 0.01
int reg_edge_apart(const struct reg_ctx *r, uint32_t e)
{
    uint32_t a = r->valid_cells[r->edge_from[e]], b = r->valid_cells[r->edge_to[e]];
    return a >= REG_MIN_VIEW_SAMPLES && b >= REG_MIN_VIEW_SAMPLES &&
           r->stats[e].overlap < REG_APART_SHARE * (a < b ? a : b);
}

/* Whether edge @p e's views do not match: they overlap, and too little of it couples. Where
 * every view holds too few samples to tell (few_samples), none does. */
int reg_edge_fails(const struct reg_ctx *r, uint32_t e)
{
    if (r->few_samples > 0)
        return 0;
    return (reg_edge_share(r, &r->stats[e]) < r->p.min_coupled_share && !reg_edge_apart(r, e)) ||
           r->quiet_break_after[r->edge_from[e]];
}

/* A pair across which the object slid along faces its shape cannot tell apart (a box pushed
 * along a face: its faces still couple, 91% of the overlap, and the model came out 3.9 mm from
 * the truth without a word) shows it in the paint. A pair breaks on colour when its hues miss
 * by more than REG_BREAK_MISFIT of a full miss both ways, over at least REG_BREAK_SAMPLES
 * samples each way, and REG_BREAK_RATIO times the ring's median pair. Measured (2026-12-05,
 * data/objects, 6 views, pushed 30 mm): the two pairs across the push 0.85 to 0.99 (the box,
 * the plate), 0.48 (the thin box; the others 0.13); the other pairs 0.04 to 0.15; the unslipped
 * scans of the corpus (4, 6, 12 views, the table exact and 2 deg off) at most 0.19 and 2.1
 * times their median. */
#define REG_BREAK_MISFIT 0.3
#define REG_BREAK_SAMPLES 50u
#define REG_BREAK_RATIO 3.0

/* Edge @p e a break its shape let through, the @p found-th: cut after it, and the first said in
 * @p rep as the failed pair (their paint missing by @p misfit; 0: not the paint). */
static void note_break(struct reg_ctx *r, struct reg_report *rep, uint32_t e, int found,
                       double misfit)
{
    r->quiet_break_after[r->edge_from[e]] = 1;
    if (found > 0)
        return;
    rep->failed_view = (int)r->edge_to[e];
    rep->failed_against = (int)r->edge_from[e];
    rep->failed_share = reg_edge_share(r, &r->stats[e]);
    rep->failed_colour = misfit;
}

/* Two neighbouring views that share no surface say nothing of each other (two views half a turn
 * apart: reg_edge_apart). In a ring of REG_APART_RING_MIN views and more, every pair no more than
 * 72 degrees apart, two such pairs and every other coupling is the mark of a push between them:
 * the stepped block of data/objects pushed 30 mm in 6 views, the views across the push landing
 * beside each other's surfaces, finished 3.0 mm from the truth without a word; no unslipped scan
 * of the corpus of 4 views or more has even one such pair. The first taken as the failed pair in
 * @p rep. @retval the breaks (0 or 2) */
#define REG_APART_RING_MIN 5u
static int apart_breaks(struct reg_ctx *r, struct reg_report *rep)
{
    int aparts = 0, found = 0;
    for (uint32_t e = 0; e < r->edges; e++)
        aparts += reg_edge_apart(r, e);
    if (aparts != 2 || r->edges < REG_APART_RING_MIN)
        return 0;
    for (uint32_t e = 0; e < r->edges; e++)
        if (reg_edge_apart(r, e))
            note_break(r, rep, e, found++, 0.0);
    return found;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Each edge's colour misfit into @p misfit (the lesser of its two directions, 0 where either has
 * fewer than REG_BREAK_SAMPLES samples). @retval the ring's median */
static double ring_misfits(struct reg_ctx *r, double *misfit)
{
    static double sorted[REG_EDGES]; /* static: off the stack */
    reg_prepare_landing(r);
    for (uint32_t e = 0; e < r->edges; e++) {
        uint64_t n_ab, n_ba;
        double ab = reg_pair_colour_misfit(r, r->edge_from[e], r->edge_to[e], &n_ab);
        double ba = reg_pair_colour_misfit(r, r->edge_to[e], r->edge_from[e], &n_ba);
        misfit[e] = n_ab >= REG_BREAK_SAMPLES && n_ba >= REG_BREAK_SAMPLES ? fmin(ab, ba) : 0.0;
        sorted[e] = misfit[e];
    }
    qsort(sorted, r->edges, sizeof(sorted[0]), by_value);
    return sorted[r->edges / 2];
}

/* The pairs of a ring that match in shape and break on colour (quiet_break_after), the first
 * as the failed pair in @p rep. @retval the breaks */
static int colour_breaks(struct reg_ctx *r, struct reg_report *rep)
{
    static double misfit[REG_EDGES]; /* static: off the stack */
    int found = 0;
    if (!r->p.use_colour)
        return 0;
    double median = ring_misfits(r, misfit);
    for (uint32_t e = 0; e < r->edges; e++) {
        if (misfit[e] > REG_BREAK_MISFIT && misfit[e] > REG_BREAK_RATIO * median)
            note_break(r, rep, e, found++, misfit[e]);
    }
    return found;
}

/* A pair that shares a top and no side (REG_SIDE_MIN) holds no shift along the table: the top
 * slides into itself. Its paint does, and lines up best where the one view's samples are moved
 * by the slip: a break when that is REG_SHIFT_MIN_MM or more away from where the two stand, and
 * misses there (the two ways summed, the second at the opposite shift) at most REG_SHIFT_DIP
 * times as much as where they stand. The search: steps of REG_SHIFT_STEP_MM out to
 * REG_SHIFT_SEARCH_MM across the table (its plane: the object frame's x and y), then half a
 * step either way about the best (a farther slip parts the sides of the other pairs). Measured
 * (2026-12-05, data/objects in 6 views, every default): the thin box slipped 6 mm along its
 * length, whose two pairs across the slip see only its top, finished 0.32 mm from the truth
 * without a word; they line up at 6.0 mm (0.46 times the miss where they stand), slipped 2, 3
 * and 4 mm at the slip (0.69, 0.67, 0.57 times); the unslipped pairs this judges over the
 * corpus in 4, 6 and 12 views, the table exact and 1 and 2 deg off (top-only pairs missing up
 * to twice the ring's median among them), within 1.4 mm of where they stand, and no better
 * than 0.76 times. */
#define REG_SHIFT_SEARCH_MM 12.0
#define REG_SHIFT_STEP_MM 2.0
#define REG_SHIFT_MIN_MM 2.0
#define REG_SHIFT_DIP 0.75
/* Paint that misses by less than this share of a full miss where the views stand (the mean of
 * the two ways) has no slip to show, and its dips are noise: the simulator's box in 4 views
 * with compensated colour (config/sim.ini), its tops alike to 0.008 to 0.025, dipped to half
 * 4 to 8 mm away and was cut and refused. A slip moves the paint's boundaries: the thin box's
 * pairs missed 0.13 and more slipped 2 mm, raw colour. */
#define REG_SHIFT_MIN_MISS 0.05

/* The place across the table where the paint of @p a's samples lines up best on @p b's, from a
 * grid of @p half steps of @p step_mm either way about @p at (updated), along @p dir only when
 * it is not NULL (a unit direction of the table), over REG_BREAK_SAMPLES samples or more;
 * @p best: its misfit (updated). */
static void shift_search(struct reg_ctx *r, uint32_t a, uint32_t b, const double *dir,
                         double step_mm, int half, double at[2], double *best)
{
    const double centre[2] = {at[0], at[1]};
    const int across = dir != NULL ? 0 : half;
    for (int i = -half; i <= half; i++)
        for (int j = -across; j <= across; j++) {
            double x = centre[0] + (dir != NULL ? i * step_mm * dir[0] : i * step_mm);
            double y = centre[1] + (dir != NULL ? i * step_mm * dir[1] : j * step_mm);
            uint64_t n;
            double m = reg_pair_colour_misfit_at(r, a, b, v3(x, y, 0.0), &n);
            if (n >= REG_BREAK_SAMPLES && m < *best)
                *best = m, at[0] = x, at[1] = y;
        }
}

/* @retval 1 edge @p e's paint lines up REG_SHIFT_MIN_MM or more away from where its views stand,
 * searched across the table, or along @p dir only (not NULL: the one way its shape lets it
 * slide), at @p at (mm across the table; its misfit where they stand into @p misfit) */
static int pair_shifted(struct reg_ctx *r, uint32_t e, const double *dir, double *misfit,
                        double at[2])
{
    uint32_t a = r->edge_from[e], b = r->edge_to[e];
    uint64_t n_ab, n_ba, n_back;
    at[0] = at[1] = 0.0;
    double still_ab = reg_pair_colour_misfit(r, a, b, &n_ab), best = still_ab;
    double still_ba = reg_pair_colour_misfit(r, b, a, &n_ba);
    if (n_ab < REG_BREAK_SAMPLES || n_ba < REG_BREAK_SAMPLES)
        return 0;
    const int half = (int)(REG_SHIFT_SEARCH_MM / REG_SHIFT_STEP_MM);
    shift_search(r, a, b, dir, REG_SHIFT_STEP_MM, half, at, &best);
    shift_search(r, a, b, dir, REG_SHIFT_STEP_MM / 2.0, 1, at, &best);
    double back = reg_pair_colour_misfit_at(r, b, a, v3(-at[0], -at[1], 0.0), &n_back);
    *misfit = fmin(still_ab, still_ba);
    return hypot(at[0], at[1]) >= REG_SHIFT_MIN_MM && n_back >= REG_BREAK_SAMPLES &&
           still_ab + still_ba >= 2.0 * REG_SHIFT_MIN_MISS &&
           best + back <= REG_SHIFT_DIP * (still_ab + still_ba);
}

/* A slip is one move: the pair it happened across lines up at the move, the closing pair (the
 * views after it against view 0) at the opposite one. Two pairs whose paint lines up elsewhere
 * are the slip's breaks when their two places sum to within REG_SHIFT_AGREE_MM (the search's
 * step; each place is found on a 1 mm grid). Measured (2026-12-05): the thin box slipped
 * 6 mm in 6 views, (6.0, 0.0) and (-6.0, 0.0); the simulator's box in 4, 5 and 6 views stood
 * 20 to 50 mm off the table's axis (every default, as a person puts it down), its tops alone
 * shared by neighbours 72 and 90 degrees apart, lined up 6 to 18 mm away at two or three pairs
 * (dips 0.49 to 0.73 of where they stood, against the slip's 0.49), which took the box for
 * moved: refused, or a model 0.6 to 4.1 mm from the truth. Those places sum to 3.6 mm and more. */
#define REG_SHIFT_AGREE_MM 2.0

/* Whether edges @p e and @p f are where one move parts the views: a slip parts those after it
 * from view 0 at the pair it happened across and at the closing pair (the last view and the
 * first), and a view taken of the object knocked and put back parts at its two pairs. Measured
 * (2026-12-05): the simulator's box turned 30 degrees on the axis in 4 views, every pair
 * sharing only its top, had pairs 0 -> 1 and 2 -> 3 lining up at (-4, 1) and (5, -2) mm, which
 * no move makes; placed as moved, its model came out 1.9 mm from the truth. */
static int slip_pairs(const struct reg_ctx *r, uint32_t e, uint32_t f)
{
    int closing = r->edge_to[e] % r->per_pass == 0 || r->edge_to[f] % r->per_pass == 0;
    return closing || r->edge_to[e] == r->edge_from[f] || r->edge_to[f] == r->edge_from[e];
}

/* How edge @p e's pairs hold a slide along the table. They share a top and no side
 * (REG_SIDE_MIN): no slide at all. Or their normals have almost nothing along one direction of
 * the table (the weakest eigenvalue of reg_edge_stats' slide under REG_SLIDE_HOLD of the coupled
 * samples): that direction, object frame x and y, into @p dir. A box seen in 8 views shares one
 * face and its top with each neighbour: a push along that face moves no residual, and the box
 * pushed 6 mm along the faces its pairs across the push share came out 1.84 mm from the truth
 * without a word (its paint alone shows it; the pairs share a side, so the rule for a top alone
 * did not look). Measured (2026-12-06): that box's pairs 0.003 to 0.008 of their coupled samples,
 * the bunny's, the nut's and the gear's far above.
 * @retval SLIDE_NONE held every way @retval SLIDE_ANY a top alone @retval SLIDE_ALONG along @p dir
 */
#define REG_SLIDE_HOLD 0.02
enum { SLIDE_NONE, SLIDE_ANY, SLIDE_ALONG };
static int edge_slides(const struct reg_ctx *r, uint32_t e, double dir[2])
{
    const struct reg_edge_stats *st = &r->stats[e];
    if (st->side_overlap < REG_SIDE_MIN)
        return SLIDE_ANY;
    const double a = st->slide[0], b = st->slide[1], c = st->slide[2];
    const double weakest = 0.5 * (a + c) - sqrt(0.25 * (a - c) * (a - c) + b * b);
    if (st->coupled == 0 || weakest >= REG_SLIDE_HOLD * (double)st->coupled)
        return SLIDE_NONE;
    /* the eigenvector of [a b; b c] for the weakest: (b, weakest - a), or (weakest - c, b) */
    double x = b, y = weakest - a;
    if (fabs(a - weakest) < fabs(c - weakest))
        x = weakest - c, y = b;
    const double len = hypot(x, y);
    if (!(len > 0.0))
        x = 1.0, y = 0.0; /* a and c equal and b 0: no direction stands out */
    else
        x /= len, y /= len;
    dir[0] = x, dir[1] = y;
    return SLIDE_ALONG;
}

/* Whether edge @p e's shape lets it slide (into @p slides, edge_slides) and its paint lines up
 * elsewhere, searched along the free way only where there is one (pair_shifted's @p misfit,
 * @p at). */
static int slid_in_paint(struct reg_ctx *r, uint32_t e, int *slides, double *misfit, double at[2])
{
    double dir[2];
    *slides = edge_slides(r, e, dir);
    return *slides != SLIDE_NONE &&
           pair_shifted(r, e, *slides == SLIDE_ALONG ? dir : NULL, misfit, at);
}

/* The pair of a slip its shapes let through: a pair whose shape lets it slide along the table
 * (edge_slides: a top alone, or faces that all hold one way), whose paint lines up elsewhere
 * (slid_in_paint), and another pair where the same move parts the views (slip_pairs), whose
 * paint lines up at the opposite place. Both into quiet_break_after, the first as the failed
 * pair in @p rep. @retval the breaks (0 or 2) */
static int shift_breaks(struct reg_ctx *r, struct reg_report *rep)
{
    static double at[REG_EDGES][2], misfit[REG_EDGES]; /* static: off the stack */
    static int shifted[REG_EDGES], slides[REG_EDGES];
    int any_shifted = 0;
    if (!r->p.use_colour)
        return 0;
    reg_prepare_landing(r);
    for (uint32_t e = 0; e < r->edges; e++) {
        shifted[e] = slid_in_paint(r, e, &slides[e], &misfit[e], at[e]);
        any_shifted |= shifted[e];
    }
    if (!any_shifted)
        return 0;
    for (uint32_t e = 0; e < r->edges; e++) /* the partner may hold every slide */
        if (slides[e] == SLIDE_NONE)
            shifted[e] = pair_shifted(r, e, NULL, &misfit[e], at[e]);
    for (uint32_t e = 0; e < r->edges; e++)
        for (uint32_t f = e + 1; f < r->edges; f++) {
            int slide = slides[e] != SLIDE_NONE || slides[f] != SLIDE_NONE;
            if (slide && shifted[e] && shifted[f] && slip_pairs(r, e, f) &&
                hypot(at[e][0] + at[f][0], at[e][1] + at[f][1]) <= REG_SHIFT_AGREE_MM) {
                note_break(r, rep, e, 0, misfit[e]);
                note_break(r, rep, f, 1, misfit[f]);
                return 2;
            }
        }
    return 0;
}

/* The breaks of a ring its pairs' shapes let through (a push along the object's faces): on
 * colour (the paint misses, or lines up elsewhere), or else where neighbours share no surface.
 * @retval 1 one or more @retval 0 none */
int reg_find_quiet_breaks(struct reg_ctx *r, struct reg_report *rep)
{
    if (r->passes != 1 || r->edges < 4)
        return 0;
    return colour_breaks(r, rep) > 0 || apart_breaks(r, rep) > 0 || shift_breaks(r, rep) > 0;
}

/* A slip parts the views after it from those before at two pairs: the one it happened across
 * and the closing pair (the last view and the first). Where only the closing pair is seen to
 * break, the other is the pair that shares no surface, if one alone does, or else the pair whose
 * paint misses most, when it misses REG_OTHER_BREAK_RATIO times the ring's median pair or more,
 * or else the one pair whose shape lets it slide (edge_slides) and whose paint lines up elsewhere
 * (slid_in_paint). Measured (2026-12-05, data/objects slipped 6 mm in 6 views, every default):
 * the L-bracket's pair across the slip shared no surface; the stepped block's missed 0.148
 * against a median 0.069 (2.1x), the box's 0.284 against 0.072 (3.9x); unseen, the three were
 * refused although 12 views of each were placed. The thin box slipped 6 mm along its length at
 * 100 degrees in 7 views (2026-12-06): 0.260 against 0.130 (2.0x, just under), refused; the one
 * pair of its ring whose paint lines up elsewhere is that one: placed, 0.062 mm from the truth.
 * Only a ring already broken at its closing pair comes here: an unbroken one is never cut.
 * @retval the edge @retval -1 none stands out */
#define REG_OTHER_BREAK_RATIO 2.0
static int other_break(struct reg_ctx *r, uint32_t closing)
{
    static double misfit[REG_EDGES]; /* static: off the stack */
    int apart = -1, aparts = 0;
    for (uint32_t e = 0; e < r->edges; e++)
        if (e != closing && reg_edge_apart(r, e))
            apart = (int)e, aparts++;
    if (aparts > 0 || !r->p.use_colour)
        return aparts == 1 ? apart : -1;
    double median = ring_misfits(r, misfit);
    int worst = -1;
    for (uint32_t e = 0; e < r->edges; e++)
        if (e != closing && (worst < 0 || misfit[e] > misfit[worst]))
            worst = (int)e;
    if (worst >= 0 && misfit[worst] > 0.0 && misfit[worst] >= REG_OTHER_BREAK_RATIO * median)
        return worst;
    /* else the one pair whose shape lets it slide and whose paint lines up elsewhere */
    int shifted = -1, count = 0;
    for (uint32_t e = 0; e < r->edges; e++) {
        double at[2], m;
        int slides;
        if (e != closing && slid_in_paint(r, e, &slides, &m, at))
            shifted = (int)e, count++;
    }
    return count == 1 ? shifted : -1;
}

/* One pass whose ring of views breaks at exactly two pairs (the object moved on the table
 * between two views, or one view was taken of a moved object) cuts into two arcs: cut_after
 * marks them and the arc without view 0 becomes group 1. @retval 1 cut @retval 0 not so */
int reg_cut_at_the_move(struct reg_ctx *r)
{
    uint32_t cuts = 0, at[2] = {0, 0}, first = 0;
    for (uint32_t e = 0; e < r->edges; e++) {
        if (!reg_edge_fails(r, e))
            continue;
        if (cuts < 2)
            at[cuts] = r->edge_from[e];
        first = cuts == 0 ? e : first;
        cuts++;
    }
    if (r->passes != 1 || r->views < 4 || r->edges != r->views)
        return 0;
    if (cuts == 1 && at[0] + 1 < r->views - 1) {
        /* A slip is one moment: the views after it part from those before across the closing
         * pair as well, even where that pair shares only a face they slide along (a thin box's
         * top: the pair couples, a shift along it unseen). The placement then tells. */
        at[1] = r->views - 1;
        cuts = 2;
    } else if (cuts == 1) { /* the closing pair alone: which other? */
        int other = other_break(r, first);
        if (other >= 0) {
            at[1] = at[0];
            at[0] = r->edge_from[other];
            cuts = 2;
        }
    }
    if (cuts != 2)
        return 0;
    memset(r->group, 0, sizeof(r->group));
    for (uint32_t v = at[0] + 1; v <= at[1]; v++) /* the arc between the cuts ... */
        r->group[v] = 1;
    if (r->group[0]) /* ... or the other one, so that view 0 stays in group 0 */
        for (uint32_t v = 0; v < r->views; v++)
            r->group[v] = !r->group[v];
    r->cut_after[at[0]] = r->cut_after[at[1]] = 1;
    return 1;
}

/* Views that look alike as they stand: an object whose symmetry matches the table's step (a hex
 * nut in 6 views, a 24-tooth gear in 3, 4, 6, 8 or 12, a box in 2) shows each view what its
 * neighbour saw, so every pair fits the table's turn about the object's own axis as measured,
 * and the depth's small bias (the same in every view) moves that axis: the hex nut's 0.24 to
 * 0.27 mm and 0.08 deg from the truth over three noise seeds, its model 0.17 to 0.21 mm off
 * against 0.065 with the calibrated axis (2026-12-05). Measured, the share of a view's sideways
 * samples alike in its neighbour as they stand: the nut in 6 views 0.98 to 0.997, the gear
 * 0.93 to 0.96, a cylinder 0.96 to 0.98, the box in 2 views 0.999; the bunny in 8 views at most
 * 0.007, the box in 6 0.01, in 36 (10 degrees apart) 0.13 to 0.24. */
#define REG_ALIKE_SHARE 0.8

/* The share of view @p v's samples on surfaces facing sideways whose pixel in view @p w, as the
 * two stand (no turn: the same pixel of the same camera), holds a sample within max_pair_mm
 * facing within max_normal_deg; @p sideways: how many there were. */
static double alike_share(struct reg_ctx *r, uint32_t v, uint32_t w, uint32_t *sideways)
{
    const struct reg_cell *a = reg_view_cells(r, v), *b = reg_view_cells(r, w);
    const double min_cos = cos(r->p.max_normal_deg * M_PI / 180.0);
    const double gate_sq = r->p.max_pair_mm * r->p.max_pair_mm;
    uint32_t n = 0, alike = 0;
    for (size_t i = 0; i < reg_cell_count(r); i++) {
        if (!a[i].valid)
            continue;
        vec3 na = v3(a[i].normal[0], a[i].normal[1], a[i].normal[2]);
        if (fabs(v3_dot(na, r->d)) >= REG_SIDE_COS)
            continue;
        n++;
        if (!b[i].valid)
            continue;
        vec3 nb = v3(b[i].normal[0], b[i].normal[1], b[i].normal[2]);
        vec3 pa = v3(a[i].xyz[0], a[i].xyz[1], a[i].xyz[2]);
        vec3 pb = v3(b[i].xyz[0], b[i].xyz[1], b[i].xyz[2]);
        vec3 diff = v3_sub(pa, pb);
        alike += v3_dot(diff, diff) <= gate_sq && v3_dot(na, nb) >= min_cos;
    }
    *sideways = n;
    return n > 0 ? (double)alike / n : 0.0;
}

int reg_views_alike(struct reg_ctx *r)
{
    uint32_t judged = 0;
    for (uint32_t e = 0; e < r->edges; e++) {
        uint32_t sideways;
        if (r->group[r->edge_from[e]] || r->group[r->edge_to[e]])
            continue; /* the arc after a slip: the object stands elsewhere on the table */
        if (alike_share(r, r->edge_from[e], r->edge_to[e], &sideways) < REG_ALIKE_SHARE ||
            sideways < REG_SIDE_MIN)
            return 0;
        judged++;
    }
    return judged > 0;
}
