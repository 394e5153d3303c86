/* Scanner configuration: INI files parsed with inih into plain structs, checked against the limits.
 */
#ifndef CONFIG_H
#define CONFIG_H

#include "board.h"
#include "calib_file.h"
#include "calib_settings.h"
#include "hal.h"
#include "fusion.h"
#include "reg.h"
#include "scan_dir.h"
#include "ini_schema.h"
#include "scan_types.h"
#include "sim_config.h"
#include "turntable_modbus.h"
#include "vec3.h"

#include <stddef.h>
#include <stdio.h>

/** [output] keep_frames: which camera frames a scan keeps. */
enum keep_frames { KEEP_FRAMES_ALL, KEEP_FRAMES_COLOUR, KEEP_FRAMES_NONE };

struct app_config {
    char path[HAL_MAX_PATH];             /**< the file it came from */
    char camera_backend[16];             /**< sim | v4l2 | libcamera */
    char camera_pixel_format[8];         /**< rgb24 | yuyv | grey, as written */
    char colour_method[16];              /**< none | single | uniform | multi, as written */
    char colour_ca[16];                  /**< channel | pixel, as written */
    char code[8];                        /**< [scan] code: gray | xor04, as written */
    char projector_backend[8];           /**< [projector] backend: gpio | drm */
    char projector_device[HAL_MAX_PATH]; /**< [projector] device (drm) */
    struct hal_camera_config camera;
    uint32_t light_count;
    struct scan_params scan;
    uint32_t views;  /**< per pass */
    uint32_t passes; /**< 1, or 2: the object laid another way for a second turn */
    double start_angle_deg;
    struct ini_list exposures_us; /**< [scan] exposures_us as written (HDR patterns) */
    uint32_t auto_exposure; /**< [scan]: 1: a dark object's patterns also at a longer exposure,
                               the single-light frames at the exposure the lights call for */
    struct ini_list light_exposure_us;   /**< [colour] light_exposure_us as written (one number) */
    char calibration_file[HAL_MAX_PATH]; /**< resolved against the config file's directory */
    char output_dir[HAL_MAX_PATH];
    char frame_format_name[8]; /**< [output] frame_format, as written */
    uint32_t frame_format;     /**< enum scan_frame_format */
    char keep_frames_name[8];  /**< [output] keep_frames, as written */
    uint32_t keep_frames;      /**< enum keep_frames */
    double min_fragment_share; /**< [output]: smaller floating pieces are left out of the mesh */
    double max_hole_mm;        /**< [output]: holes up to this wide are filled */
    uint32_t watertight;       /**< [output]: 1: the model is closed */
    uint32_t texture;          /**< [output]: 1: a texture atlas beside the vertex colours */
    double texel_mm;           /**< [output]: its texel (0: a camera pixel at the axis) */
    struct hal_gpio_config gpio;
    struct tt_client_config turntable;
    struct fusion_params fusion;
    struct reg_params registration;
    struct sim_config sim;
    struct calib_settings calibrate;
};

/** Parse and check @p path. On error @p err says file, line and key.
 *  @retval 0 ok @retval -EINVAL bad content @retval -ENOENT no such file */
int config_load(struct app_config *cfg, const char *path, char *err, size_t err_len);

/** config_load for a command that works on captures already on disk (scanner calibrate --from,
 *  calibrate import): the keys that only drive the rig may be left out ([camera] backend and
 *  exposure_us; [scan] calibration, then empty: the calibration starts from a guess).
 *  @retval as config_load */
int config_load_offline(struct app_config *cfg, const char *path, char *err, size_t err_len);

/** Check that the files the config names beyond its calibration can be read (the simulator's
 *  mesh_file and merl_file, where used; [sim] rig is read at load). A scan kept with its config
 *  does not need them again, so config_load leaves this to the commands that run the rig.
 *  @retval 0 @retval -errno (@p err names the file, the key and what is wrong) */
int config_check_files(const struct app_config *cfg, char *err, size_t err_len);

/** The devices' settings of @p cfg for board_init and board_selftest (pointers into @p cfg). */
void config_board(const struct app_config *cfg, struct board_config *out);

/** What a scan chose itself ([scan] auto_exposure: the patterns' HDR exposures, the
 *  single-light frames' exposure), taken from @p taken, its config.ini, into @p now where
 *  @p now leaves them to the scan (auto_exposure on, the key not in its file): a resume or a
 *  re-processing with a person's own file reads the frames as they were taken. */
void config_adopt_chosen(struct app_config *now, const struct app_config *taken);

/** The first key of how views are taken (views, passes, start angle, resolution, exposures,
 *  gain, patterns, lights, colour frames) on which @p now differs from @p taken, the settings a
 *  scan was taken with: a resume or a re-processing must keep them, or its views would not fit
 *  together. @param capturing  1: the colour method too (a resume takes its frames)
 *  @param what  out: "[section] key = taken's value, not now's value" when they differ
 *  @retval 0 the same @retval -EINVAL they differ */
int config_plan_differs(const struct app_config *taken, const struct app_config *now, int capturing,
                        char *what, size_t what_len);

/** Write the documentation of every key (Markdown) to @p out. */
void config_print_doc(FILE *out);

#endif
