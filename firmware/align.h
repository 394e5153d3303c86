/* A second pass aligned to the first without a starting pose: the object was laid another way
 * on the table, so its frame is turned and moved by an unknown rigid motion. A coarse search
 * over orientations against the first pass's nearest-point field, then point-to-plane ICP, in
 * static memory. */
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

/** Forget every point. */
void align_begin(void);

/** Add a point of pass @p pass (0: the first, the reference; 1: the second), in that pass's
 *  object frame, with its unit normal. Beyond ALIGN_MAX_POINTS a pass's points are ignored
 *  (the caller spreads them: every n-th). @retval 0 @retval -ENOSPC full */
int align_add_point(uint32_t pass, vec3 p_mm, vec3 normal);

/** Find the motion taking the second pass's object frame to the first's.
 *  @param first_from_second  out @param report out
 *  @retval 0 (a failed match is report->found = 0) @retval -EINVAL too few points */
int align_solve(const struct align_params *params, struct frame_xform *first_from_second,
                struct align_report *report);

#endif
