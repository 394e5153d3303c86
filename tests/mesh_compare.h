/* Surface distance between a scanned mesh and the true one (used by tests and mesh-compare). */
#ifndef MESH_COMPARE_H
#define MESH_COMPARE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "vec3.h"

/** Where the rig can look from (object frame is turned by each view's angle): a true surface
 *  point is observable when, for some view, both the camera and the projector reach it without
 *  occlusion and at less than max_incidence_deg from its normal. */
struct mesh_visibility {
    vec3 camera_table, projector_table; /**< centres in the turntable frame */
    uint32_t views;                     /**< angles 0, 360/views, ... */
    double max_incidence_deg;
};

struct mesh_comparison {
    uint32_t result_triangles;
    uint32_t result_pieces; /**< connected pieces of the result (1: no floating fragment) */
    uint32_t holes, holes_under_10mm; /**< boundary loops of the result (bounding box diagonal) */
    double largest_hole_mm;
    uint32_t boundary_edges;    /**< edges of one triangle: 0 with nonmanifold_edges 0 is */
    uint32_t nonmanifold_edges; /**< watertight (every edge shared by exactly two faces) */
    double result_to_truth_mean_mm, result_to_truth_p95_mm, result_to_truth_max_mm;
    double truth_to_result_mean_mm;
    double truth_within_1mm;      /**< share of the true surface within 1 mm of the result */
    double truth_seen_within_1mm; /**< the same without the face on the table (z < 1 mm) */
    double truth_seen_to_result_mean_mm;
    double symmetric_mean_mm;           /**< mean of the two directed means (truth: seen part) */
    double observable_share;            /**< share of the true surface the rig can observe */
    double truth_observable_within_1mm; /**< of the observable surface, share within 1 mm */
    double truth_observable_to_result_mean_mm;
    double symmetric_observable_mean_mm; /**< result->truth and observable truth->result */
    int aligned;                /**< the result was first moved onto the truth (rigid ICP) */
    double align_deg, align_mm; /**< how far that moved it (rotation; a point 100 mm out) */
};

/** @param align  1: first move the result rigidly onto the truth (point-to-plane ICP against
 *  the closest true points): a scan's frame is its first view's, and a table that missed that
 *  view's angle turns the whole model, which says nothing of its shape
 *  @retval 0 ok, or -errno with @p err saying which file */
int mesh_compare_files(const char *result_ply, const char *truth_ply, uint32_t samples,
                       const struct mesh_visibility *vis, int align, struct mesh_comparison *out,
                       char *err, size_t err_len);
/** The rig of a scan directory (calibration.ini, config.ini views). @retval 0 or -errno */
int mesh_visibility_from_scan(const char *scan_dir, struct mesh_visibility *vis, char *err,
                              size_t err_len);
void mesh_compare_print(const struct mesh_comparison *r, FILE *out);

#endif
