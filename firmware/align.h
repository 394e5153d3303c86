/* A second pass aligned to the first without a starting pose: the object was laid another way
 * on the table, so its frame is turned and moved by an unknown rigid motion. A coarse search
 * over orientations against the first pass's nearest-point field, then point-to-plane ICP, in
 * the caller's struct align_ctx (no allocation). */
#ifndef ALIGN_H
#define ALIGN_H

#include "frames.h"

struct align_params {
    double max_pair_mm;       /**< the final pairs are at most this far apart */
    double max_normal_deg;    /**< and their normals agree this well */
    double min_coupled_share; /**< fewer of the second pass's points coupled: no match */
};

struct align_report {
    uint32_t points[2];   /**< points of the first and the second pass */
    uint32_t candidates;  /**< orientations tried */
    double rms_mm;        /**< point-to-plane residual of the final pairs */
    double coupled_share; /**< of the second pass's points, paired at the end */
    double turned_deg;    /**< the rotation found */
    int found;            /**< 1: coupled_share reached min_coupled_share */
};

/** The points of both passes and the first's nearest-point field (a few MB: kept static by its
 *  owner, the registration's struct reg_ctx). Fields are the alignment's own. */
struct align_ctx {
    float pts[2][ALIGN_MAX_POINTS][3], nrm[2][ALIGN_MAX_POINTS][3];
    uint32_t npts[2];
    /* Per cell of the field: 1 + the index of the first-pass point nearest its centre, 0: none. */
    uint32_t nearest[ALIGN_MAX_CELLS];
    struct {
        vec3 lo;
        double cell;
        uint32_t dims[3];
    } field;
};

/** Forget every point of @p a. */
void align_begin(struct align_ctx *a);

/** Add a point of pass @p pass (0: the first, the reference; 1: the second), in that pass's
 *  object frame, with its unit normal. Beyond ALIGN_MAX_POINTS a pass's points are ignored
 *  (the caller spreads them: every n-th). @retval 0 @retval -ENOSPC full */
int align_add_point(struct align_ctx *a, uint32_t pass, vec3 p_mm, vec3 normal);

/** Find the motion taking the second pass's object frame to the first's.
 *  @param first_from_second  out @param report out
 *  @retval 0 (a failed match is report->found = 0) @retval -EINVAL too few points */
int align_solve(struct align_ctx *a, const struct align_params *params,
                struct frame_xform *first_from_second, struct align_report *report);

#endif
