/* Calibration targets the simulated person puts on the turntable: a printed board on a plate
 * (flat, upright or tilted) and a matte white sphere. */
#ifndef SIM_TARGET_H
#define SIM_TARGET_H

#include "sim_mesh.h"
#include "vec3.h"

#include <stdint.h>

enum sim_target_kind { SIM_TARGET_OBJECT = 0, SIM_TARGET_BOARD, SIM_TARGET_SPHERE };

/** A target as placed: what it is, the printed sheet, and where it stands on the table. */
struct sim_target {
    uint32_t kind;        /**< enum sim_target_kind */
    const uint8_t *sheet; /**< board: the printed sheet, grey, row-major, top-left first */
    uint32_t sheet_width, sheet_height; /**< pixels */
    double sheet_px_per_mm;             /**< print resolution */
    double thickness_mm;                /**< board: the plate the sheet is glued to */
    double tilt_deg;       /**< board: 0 upright facing the camera, leaning back by this; 90
                                lies flat, face up */
    double diameter_mm;    /**< sphere */
    double position_mm[2]; /**< table frame at angle 0 (x towards the camera): the plate's
                                bottom-edge centre, or the sphere's foot */
};

/** The sheet's frame in the object frame: origin at its top-left, x along its rows, y down its
 *  columns, n out of its face. */
struct sim_sheet_frame {
    vec3 origin, ex, ey, n;
};

/** Build the target's mesh in the object frame (z up, table at z = 0).
 *  @param sheet  out for a board: where the sheet lies @retval 0 @retval -ENOMEM @retval -EINVAL */
int sim_target_mesh(const struct sim_target *t, struct sim_mesh *m, struct sim_sheet_frame *sheet);

/** Reflectance of the printed sheet averaged over a footprint: @p n_samples points of the face
 *  (object frame) are looked up bilinearly and averaged. @retval albedo (0..1) */
double sim_target_sheet_albedo(const struct sim_target *t, const struct sim_sheet_frame *f,
                               const vec3 *points, uint32_t n_samples);

#endif
