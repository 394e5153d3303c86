/* Shared between the calibration's capture (calibrate.c) and its computation (calib_solve.c):
 * the calibration directory's files (docs/calibration.md) and the capture's settings. */
#ifndef CALIB_PRIV_H
#define CALIB_PRIV_H

#include "calib_cv.h"
#include "calibrate.h"
#include "config.h"
#include "vec3.h"

/** The printed sheet as the simulated person receives it: 10 pixels per mm. */
#define CALIB_SHEET_PX_PER_MM 10.0

enum calib_target_kind { CALIB_TARGET_BOARD = 0, CALIB_TARGET_SPHERE = 1 };

/** A capture's target.ini: what stood on the table, and at which angle. */
struct calib_target_info {
    uint32_t kind;      /**< enum calib_target_kind */
    uint32_t placement; /**< board placement (captures of one placement differ by the table) */
    double tilt_deg;    /**< the placement's tilt, as the person was asked */
    int32_t angle_mdeg; /**< the table's angle as the controller reported it */
    uint32_t has_angle; /**< 0: captures made elsewhere, no table angle known */
};

/** The board of [calibrate] (config_load has checked it: a ChArUco marker below its square, a
 *  chessboard that is not square). */
void calib_board_from_settings(const struct calib_settings *s, struct calcv_board *b);

/** Write view @p view's target.ini durably. @retval 0 @retval -errno (logged) */
int calib_write_target(const struct hal_storage *st, const char *dir, uint32_t view,
                       const struct calib_target_info *t);

/** Read view @p view's target.ini; a capture without one is a board of its own placement with
 *  no known angle. @retval 0 @retval -EINVAL (@p err: file, line, key) */
int calib_read_target(const char *dir, uint32_t view, struct calib_target_info *t, char *err,
                      size_t err_len);

/** Copy file @p from to @p dir / @p name. @retval 0 @retval -errno (logged to stderr) */
int calib_write_file(const struct hal_storage *st, const char *dir, const char *name,
                     const char *from);

/** The calibration the captures were taken with (its sizes), as dir/calibration.ini. */
int calib_write_guess(const struct hal_storage *st, const char *dir, const struct scan_calib *g);

/** An SVG at true size showing the @p width x @p height picture @p png_path of the board, drawn
 *  at @p px_per_mm. @retval 0 @retval -errno */
int calib_write_svg(const struct hal_storage *st, const char *base, const char *png_path, int width,
                    int height, double px_per_mm);

/** Solve the @p n x @p n system a x = b (row-major) by Gauss-Jordan with partial pivoting; @p a
 *  and @p b are destroyed. @retval 0 singular @retval 1 solved */
int calib_solve_n(double *a, double *b, double *x, int n);

/** A sphere through the valid points of a range image: Gauss-Newton on sum (|p - c| - r)^2 from
 *  the visible cap's centroid pushed back by r. @param fit_radius  0: @p radius is known
 *  @param radius  in: known or first guess; out: fitted @param centre  out
 *  @param used  out: points @retval RMS distance to the sphere, mm @retval -1 too few points */
double calib_fit_sphere(const float *xyz, const uint8_t *reason, size_t n, int fit_radius,
                        double *radius, vec3 *centre, uint32_t *used);

/** What a calibration found, for calib_json_write: every value with its uncertainty, the
 *  quality, the prediction and the verdict. A refused one has @p file NULL and @p refusal. */
struct calib_result {
    const char *file, *report; /**< the files written */
    const char *refusal;       /**< why nothing was written */
    const struct scan_calib *calib;
    int camera_only, have_sigma;
    const struct calcv_sigma *sigma;
    double axis_dir_sigma_deg, axis_across_sigma_mm, axis_along_sigma_mm; /**< 0: not known */
    const double *light_sigma_mm;                                         /**< per light */
    double camera_rms_px, projector_rms_px;
    uint32_t boards;
    double depth_centre_mm, depth_edge_mm, length_100_mm; /**< 0: not predicted */
    const char *weak, *advice;                            /**< "" when not weak */
    const char *add_placements; /**< the advice as [calibrate] placements (weak only) */
    uint32_t residual_views;    /**< boards found, each with its reprojection RMS: */
    uint32_t residual_view[CALIB_MAX_VIEWS];       /**< its view number in the captures */
    double residual_camera_px[CALIB_MAX_VIEWS];    /**< the camera's */
    double residual_projector_px[CALIB_MAX_VIEWS]; /**< the projector's; -1: not known */
};

/** Write @p r to @p out as one JSON object on one line (scanner calibrate --json). */
void calib_json_write(FILE *out, const struct calib_result *r);

#endif
