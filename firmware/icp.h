/* Registration of each view against the previous one: point-to-plane ICP started from the
 * turntable pose, pairing points by projection and accepting pairs only when distance, normal
 * and (optionally) colour agree (multi-feature matching, Schutz et al.). */
#ifndef ICP_H
#define ICP_H

#include "decode.h"
#include "frames.h"
#include "tri.h"

struct icp_params {
    uint32_t enabled;          /**< 0: keep the turntable poses */
    uint32_t sample_stride;    /**< use every n-th pixel of the new view in x and y */
    uint32_t iterations;
    double max_pair_mm;        /**< a pair farther apart does not couple */
    double max_normal_deg;     /**< nor one whose normals differ more */
    uint32_t use_colour;       /**< 1: colours must agree too */
    double max_colour_dn;      /**< largest per-channel colour difference of a pair */
    double max_correction_mm;  /**< a larger correction of the turntable pose is refused */
    double max_correction_deg;
};

/** What registering a view against the previous one did. */
struct icp_report {
    int has_pair;              /**< 0 for the first view */
    uint32_t overlap_before, coupled_before; /**< samples landing on the previous view / pairs */
    uint32_t overlap_after, coupled_after;
    double rms_before_mm, rms_after_mm;      /**< point-to-plane residual of the coupled pairs */
    double correction_mm, correction_deg;    /**< applied to the turntable pose */
    int accepted;                            /**< 0: the turntable pose was kept */
};

/** Forget the previous view (start of a scan). */
void icp_reset(void);

/** Refine @p pose (camera frame of the last view to object frame, from the turntable) against
 *  the previous view, then keep this view as the next one's reference.
 *  @retval 0 */
int icp_register(const struct icp_params *params, const struct scan_calib *calib,
                 const struct decode_maps *maps, const struct tri_range *range,
                 const uint8_t *rgb, struct frame_xform *pose, struct icp_report *report);

#endif
