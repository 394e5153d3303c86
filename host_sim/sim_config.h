/* The simulated rig's settings ([sim] in a config): what the simulator renders. */
#ifndef SIM_CONFIG_H
#define SIM_CONFIG_H

#include "hal_limits.h"
#include "scan_types.h"

#include <stdint.h>

/** The simulated rig ([sim]); read in every build so that configs stay portable, used only by
 *  the simulator board. */
struct sim_config {
    char object[16]; /**< sphere | cylinder | box | torus | mesh */
    char mesh_file[HAL_MAX_PATH];
    double object_height_mm;
    double second_pass_pose_deg[3]; /**< the object_pose of a scan's second pass */
    char person[8]; /**< auto: the simulated person lays the object at once; asked: the scanner
                         asks, as on a real rig, and waits for the answer */
    double object_pose_deg[3];  /**< turned about x, then y, then z before it is stood on the
                                     table (90, 0, 0: an upright object on its side) */
    double object_offset_mm[2]; /**< ... and stood this far from the table's axis (x, y) */
    double slip_mm[3];          /**< the object slips on the table by this (object frame) ... */
    double slip_at_deg;         /**< ... from this table angle on */
    uint32_t segments;          /**< tessellation of analytic shapes */
    char material[16];          /**< lambert | phong | merl | burley */
    char merl_file[HAL_MAX_PATH];
    char merl_name[64];
    double phong_ks, phong_ke;
    double burley_roughness;         /**< material = burley */
    char albedo_pattern[16];         /**< patches | uniform | image */
    char albedo_image[HAL_MAX_PATH]; /**< image: the PNG wrapped round the object */
    double albedo[3];
    uint32_t seed;
    uint32_t table_angle_error_mdeg;
    double placement_jitter_mm;  /**< a calibration board stood this far (up to) from where asked */
    double placement_jitter_deg; /**< ... and leaning up to this much more or less */
    double black_offset_dn, ambient_dn, read_noise_dn, electrons_per_dn;
    double projector_intensity_dn, projector_black_level, projector_blur_px;
    double camera_blur_px;   /**< sigma of the camera lens's Gaussian point spread */
    double frame_rate_hz;    /**< the sensor's streaming rate (0: a frame takes its exposure) */
    uint32_t readout_us;     /**< from a frame's end to its arrival */
    uint32_t jpeg_quality;   /**< 1..100: every frame goes through a JPEG round trip; 0: off */
    uint32_t bounce_samples; /**< one bounce of the projector's light: directions per point */
    double light_intensity_dn, light_diffuser_mm, reference_distance_mm;
    uint32_t reference_exposure_us;
    char rig_file[HAL_MAX_PATH]; /**< the true rig's geometry ("": the scan's calibration) */
    uint32_t has_rig;            /**< 1: rig holds the rig_file, loaded with the config */
    struct scan_calib rig;       /**< what the simulator renders with when has_rig */
};

#endif
