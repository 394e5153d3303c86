/* Plain data the firmware is driven by: processing parameters and the rig calibration. */
#ifndef SCAN_TYPES_H
#define SCAN_TYPES_H

#include "hal_limits.h"

#include <stdint.h>

/** Geometry of the rig, all in the camera frame (x right, y down, z forward), millimetres. */
struct scan_calib {
    double cam_fx_px, cam_fy_px, cam_cx_px, cam_cy_px; /**< camera pinhole intrinsics */
    uint32_t cam_width, cam_height;                    /**< image size the intrinsics belong to */
    double cam_dist[5]; /**< camera lens distortion k1, k2, p1, p2, k3 (firmware/lens.h) */
    double proj_fx_px, proj_fy_px, proj_cx_px, proj_cy_px; /**< projector pinhole intrinsics */
    uint32_t proj_width, proj_height;                      /**< projector resolution */
    double proj_dist[5];     /**< projector lens distortion k1, k2, p1, p2, k3 */
    double proj_rot[9];      /**< rotation camera -> projector, row-major: p_proj = R p_cam + t */
    double proj_trans_mm[3]; /**< translation camera -> projector */
    double axis_point_mm[3]; /**< a point on the turntable axis, on the table surface */
    double axis_dir[3];      /**< unit direction of the axis, pointing up */
    uint32_t light_count;    /**< number of white lights */
    double light_pos_mm[HAL_MAX_LIGHTS][3]; /**< light positions */
    double light_gain[HAL_MAX_LIGHTS];      /**< each light's intensity relative to their mean (1:
                                                 equal lights); the multi method divides by it */
};

enum colour_method { COLOUR_NONE = 0, COLOUR_SINGLE, COLOUR_UNIFORM, COLOUR_MULTI, COLOUR_FIT };

/** Where Ca (ambient + black offset) comes from: the dark frame's mean over the object per
 *  channel, the dark frame per pixel, or per channel as offset + slope x the pixel's albedo
 *  (the ambient light is reflected by the paint like any other: dark paint gets little). */
enum colour_ca { COLOUR_CA_CHANNEL = 0, COLOUR_CA_PIXEL, COLOUR_CA_ALBEDO };

/** Intrinsic colour (firmware/colour.h). */
struct colour_params {
    uint32_t method;       /**< enum colour_method */
    uint32_t ca;           /**< enum colour_ca */
    double min_cos;        /**< cos(theta) below this: not used (grazing light amplifies noise) */
    double ke, ko;         /**< highlight rejection exponents of eq. 6 */
    double shadow_dn;      /**< a light frame within this of Ca: the light does not reach */
    uint32_t falloff;      /**< 1: inverse-square distance compensation */
    double reference_mm;   /**< distance at which the falloff factor is 1 */
    double white_scale[3]; /**< per channel: white surface -> 1 */
    uint32_t saturation_dn;
    uint32_t exposure_us, gain_milli; /**< the camera's: patterns, projector white, dark */
    uint32_t all_lights_exposure_us;  /**< the all-lights frame (0: exposure_us) */
    uint32_t light_exposure_us;       /**< each single-light frame (0: exposure_us) */
    uint32_t bracket;    /**< multi: each light also at this x its exposure (0, 1: not) */
    double shadow_ratio; /**< multi: a light estimating below this x the best one is shadowed */
    uint32_t clusters;   /**< fit: material clusters at most (reflect.h) */
    uint32_t taken_with; /**< the method the colour frames were taken with, when processing
                              with another (0: this one): method none reads a scan that has them */
};

/** Exposures an HDR pattern can be captured at. */
#define SCAN_MAX_EXPOSURES 3

/** Processing and sequencing parameters of one view. */
struct scan_params {
    uint32_t width, height;      /**< camera frame size */
    uint32_t min_contrast_dn;    /**< white minus black below this: not lit enough */
    uint32_t shadow_contrast_dn; /**< white minus black at or below this: no projector light */
    uint32_t min_bit_diff_dn;    /**< |I - I_inverse| at or below this: the bit is ambiguous */
    uint32_t max_ambiguous_bits; /**< more unclear bits than this: resolved by the neighbourhood */
    uint32_t max_unclear_bits;   /**< more unclear bits than this: low contrast, not resolved */
    double bit_noise_sigmas;     /**< bit threshold in noise standard deviations (0: fixed) */
    double read_noise_dn;        /**< the camera's read noise (sigma, grey levels) */
    double electrons_per_dn;     /**< the camera's conversion gain (sets its shot noise) */
    uint32_t saturation_dn;      /**< a channel at or above this is saturated */
    uint32_t max_column_jump;    /**< neighbours differing by more are not consistent */
    uint32_t min_consistent_neighbours; /**< of 8; fewer makes the pixel inconsistent */
    double max_depth_jump_mm;   /**< neighbour depth step that breaks the surface (normals) */
    uint32_t refine;            /**< 1: sub-stripe refinement of the columns (refine.h) */
    uint32_t decode_rows;       /**< 1: projector rows are coded too (more patterns) */
    uint32_t inverse_bits;      /**< the finest bits projected with their inverse (0: every bit) */
    uint32_t threads;           /**< cores a view's per-pixel stages split across (0: all) */
    uint32_t code;              /**< enum gray_code: Gray, or XOR-04 (robust to interreflection) */
    uint32_t normal_radius_px;  /**< normals span up to this many pixels each side */
    uint32_t pattern_settle_us; /**< wait after the projector changes pattern */
    uint32_t trigger_pulse_us;  /**< projector trigger/reset pulse width */
    uint32_t capture_retries;   /**< extra tries of a failed capture */
    uint32_t exposure_count;    /**< HDR: each pattern at these exposures (0: the camera's only) */
    uint32_t exposures_us[SCAN_MAX_EXPOSURES]; /**< ascending, one of them the camera's */
    struct colour_params colour; /**< intrinsic colour; its frames are captured unless none */
};

#endif
