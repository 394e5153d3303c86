/* The [calibrate] section of a config: the board, the procedure and what is accepted. Part of
 * the config (config_load parses and checks it); the calibration itself, which uses it, is the
 * calib/ layer, which nothing of app/ or web/ sees. */
#ifndef CALIB_SETTINGS_H
#define CALIB_SETTINGS_H

#include <stdint.h>

#define CALIB_MAX_PLACEMENTS 8 /**< board placements one procedure lists */
#define CALIB_MAX_VIEWS 96     /**< captures one calibration directory holds */

/** [calibrate] of a config: the board, the procedure, and what is accepted. */
struct calib_settings {
    char board[16]; /**< chessboard | charuco */
    uint32_t squares_x, squares_y;
    double square_mm, marker_mm, margin_mm, board_thickness_mm;
    char dictionary[16];      /**< ChArUco dictionary, e.g. 5x5_100 */
    char placements[160];     /**< board placements, comma-separated: tilt from upright in degrees
                                   (90: flat), optionally @ sideways offset in mm ("20@-70") */
    uint32_t placement_count; /**< parsed from placements */
    double tilt_deg[CALIB_MAX_PLACEMENTS];  /**< parsed from placements */
    double offset_mm[CALIB_MAX_PLACEMENTS]; /**< to the camera's right of the table's centre */
    uint32_t turns;                         /**< table angles per placement */
    double turn_step_deg;                   /**< between them, centred on 0 */
    double sphere_diameter_mm, sphere_offset_mm;
    uint32_t sphere_turns; /**< table angles of the sphere (0: lights not calibrated) */
    uint32_t projector_width, projector_height; /**< used when no calibration exists yet */
    uint32_t min_corners;
    uint32_t fix_k3;
    double max_camera_rms_px, max_projector_rms_px;
    double max_sigma_centre_px, max_sigma_focal_share;       /**< a lens this uncertain: weak */
    double max_sigma_translation_mm, max_sigma_rotation_deg; /**< the pose this uncertain: weak */
    double max_depth_error_mm; /**< a predicted depth error at the volume's edge above: weak */
};

#endif
