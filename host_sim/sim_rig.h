/* The simulated rig: renders what the camera sees of the object on the turntable under the
 * projector and the lights, and keeps the ground truth of every pixel. */
#ifndef SIM_RIG_H
#define SIM_RIG_H

#include "sim_config.h"
#include "gray.h"
#include "scan_types.h"
#include "sim_bvh.h"
#include "sim_material.h"
#include "sim_mesh.h"
#include "sim_target.h"

/** What lights the object while a frame is taken. */
struct sim_sources {
    int projector_on;
    uint32_t pattern_index; /**< index into the Gray-code stored sequence */
    uint32_t lights_mask;   /**< bit i: light i on */
    uint32_t exposure_us;
    uint32_t gain_milli;
};

/** Per-pixel ground truth of the current angle (all arrays width * height). */
struct sim_truth {
    uint8_t *hit;      /**< the pixel sees the object */
    float *pos_cam;    /**< 3 per pixel: surface point in the camera frame, mm */
    float *normal_cam; /**< 3 per pixel: unit shading normal, camera frame */
    float *albedo;     /**< 3 per pixel: diffuse colour (linear, 0..1) */
    float *proj_u;     /**< continuous projector column of the point (pixel centres at integers) */
    float *proj_v;     /**< continuous projector row of the point */
    uint8_t *proj_lit; /**< the projector reaches the point (in frustum, facing, not shadowed) */
    uint8_t *dark;     /**< the point lies on the very dark paint */
};

/** Pixels between the points where one bounce of light is sampled (it varies slowly). */
#define SIM_BOUNCE_STEP 4u

struct sim_rig {
    struct sim_config cfg;
    struct scan_calib calib;
    struct sim_mesh mesh;
    struct sim_bvh bvh;
    struct sim_material material;
    uint32_t width, height;
    struct gray_layout layout; /**< the projector's stored pattern sequence */
    double object_height_mm;   /**< height of the object standing (its paint is laid out by it) */
    double pose_rot[9];        /**< [sim] object_pose: standing -> as placed, p = R q + shift */
    vec3 pose_shift;
    int32_t table_angle_mdeg; /**< where the turntable is; the camera renders at this angle */
    int32_t truth_angle_mdeg; /**< angle the truth buffers belong to */
    int truth_valid;
    struct sim_truth truth;
    float *proj_radiance; /**< 3 per pixel: projector light reflected at full white */
    uint8_t *light_vis;   /**< bit i: light i reaches the point */
    uint32_t lights_done; /**< lights whose visibility is computed for truth_angle_mdeg */
    float *gauss;         /**< table of standard normal samples for the noise */
    float *signal;        /**< 3 per pixel: the frame being rendered, before gain and noise */
    float *blur_line;     /**< one row or column of signal, for the camera blur */
    uint32_t bounce_w, bounce_h; /**< the bounce grid: every SIM_BOUNCE_STEP-th pixel */
    float *bounce_u, *bounce_v;  /**< per grid point and sample: where the surface it sees is in
                                      the projector image (NAN: nothing lit) */
    float *bounce_rad;   /**< 3 per grid point and sample: that surface's light at full white */
    float *bounce_light; /**< 3 per grid point: the bounced light of the frame being rendered */
    struct sim_target target;     /**< what stands on the table (SIM_TARGET_OBJECT: the object) */
    struct sim_sheet_frame sheet; /**< a board's printed sheet, object frame */
    uint8_t *sheet_pixels;        /**< the rig's copy of the sheet */
    char dir[HAL_MAX_PATH];       /**< where relative paths of the config are resolved */
};

/** Build the object, material and buffers. Allocates; nothing allocates after this.
 *  @param config_dir  directory relative paths in @p cfg are resolved against
 *  @retval 0 ok @retval -errno, with @p err saying what */
int sim_rig_init(struct sim_rig *rig, const struct sim_config *cfg, const struct scan_calib *calib,
                 const struct gray_layout *layout, const char *config_dir, char *err,
                 size_t err_len);
void sim_rig_free(struct sim_rig *rig);

/** What the camera sees of light @p li's specular part at pixel @p i of the current angle (after
 *  sim_rig_update): the material with no diffuse colour, through the light's diffuser, with its
 *  falloff, before exposure gain and noise; 0 where the light's centre is hidden or the pixel
 *  misses the object. For comparing a fitted lobe with the material where the rig saw it.
 *  @param sig  3 channels, out */
void sim_rig_specular_at(struct sim_rig *rig, size_t i, uint32_t li, double sig[3]);

/** Put a calibration target on the table in place of the object (the simulated person's part
 *  of `scanner calibrate`); SIM_TARGET_OBJECT puts the object back. Allocates (a setup step).
 *  @retval 0 @retval -errno, with @p err saying what */
int sim_rig_set_target(struct sim_rig *rig, const struct sim_target *target, char *err,
                       size_t err_len);

/** Bring the truth buffers up to date for the current table angle (ray casting). */
void sim_rig_update(struct sim_rig *rig);

/** Render one RGB24 frame with noise; @p noise_id (with the seed and the angle) seeds it. */
void sim_rig_render(struct sim_rig *rig, const struct sim_sources *src, uint64_t noise_id,
                    uint8_t *rgb);

/** Height of the object as placed on the table (a torus lies flat). */
double sim_rig_placed_height(const struct sim_config *cfg);

/** Albedo of the painted pattern at an object-frame point. @retval 1 on the very dark paint */
int sim_albedo_at(const struct sim_config *cfg, double height_mm, vec3 p_obj, double albedo[3]);

/** [sim] albedo_pattern = image: the picture sim_albedo_at wraps round the object, 8-bit sRGB,
 *  @p width x @p height (sim_albedo_image.c keeps a linear copy), read from @p path (by the
 *  board: board_albedo.c). @retval 0 @retval -ENOMEM */
int sim_albedo_image_set(const char *path, const uint8_t *rgb, uint32_t width, uint32_t height);

/** @retval 1 the picture in use was read from @p path */
int sim_albedo_image_is(const char *path);

/** The loaded image's albedo at (@p u round the object, @p v down it), both 0..1, bilinear
 *  (mid grey when none is loaded). */
void sim_albedo_image_at(double u, double v, double albedo[3]);

#endif
