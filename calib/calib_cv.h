/* OpenCV 4.6 behind a C interface for calibration: the board's picture, its corners in an image,
 * Zhang's camera calibration and the stereo pose (app/calib_cv.cpp, the only C++ of calibration).
 */
#ifndef CALIB_CV_H
#define CALIB_CV_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CALCV_MAX_CORNERS 1024 /**< corners of one board (inner corners of a 33 x 33 board) */

enum calcv_board_kind { CALCV_CHESSBOARD = 0, CALCV_CHARUCO = 1 };

/** A printed board. The sheet's origin is its top-left corner; x right, y down, z into it. */
struct calcv_board {
    int kind;                 /**< enum calcv_board_kind */
    int squares_x, squares_y; /**< squares across and down */
    double square_mm;         /**< side of a square */
    double marker_mm;         /**< ChArUco: side of a marker inside a white square */
    int dictionary;           /**< ChArUco: OpenCV's predefined dictionary id */
    double margin_mm;         /**< white border around the squares */
};

/** The corners found in one image, and where each lies on the sheet. */
struct calcv_corners {
    int count;
    int id[CALCV_MAX_CORNERS];          /**< corner number on the board (row-major) */
    double image[CALCV_MAX_CORNERS][2]; /**< pixel coordinates, centres at integers */
    double sheet[CALCV_MAX_CORNERS][3]; /**< on the sheet, mm (z = 0) */
};

/** A pinhole with Brown-Conrady distortion (k1, k2, p1, p2, k3). */
struct calcv_lens {
    double fx, fy, cx, cy;
    double dist[5];
};

/** Corners of the whole board (how many the board has). */
int calcv_board_corner_count(const struct calcv_board *b);

/** Sheet size in mm. */
void calcv_board_size_mm(const struct calcv_board *b, double *width_mm, double *height_mm);

/** Draw the sheet at @p px_per_mm into a grey image the caller frees with free().
 *  @retval 0 @retval -EINVAL bad board @retval -ENOMEM */
int calcv_board_image(const struct calcv_board *b, double px_per_mm, uint8_t **grey, int *width,
                      int *height);

/** Find the board in a grey image (chessboard: the whole board, findChessboardCornersSB;
 *  ChArUco: the markers, then the corners between them). A chessboard is ordered so that its
 *  first corner is the one higher in the image (a symmetric board has two readings).
 *  @param why  out when not found: what the image shows (too dark, glare, too few corners)
 *  @retval 0 found @retval -ENOENT not found @retval -EINVAL bad board */
int calcv_find_corners(const struct calcv_board *b, const uint8_t *grey, int width, int height,
                       int min_corners, struct calcv_corners *out, char *why, size_t why_len);

/** A picture for the page: @p rgb (@p width x @p height) shrunk to at most 640 pixels across,
 *  with @p corners drawn (cv::drawChessboardCorners; connected when the whole board was found).
 *  @param corners  NULL or none: the picture alone @param out  out: RGB the caller frees
 *  @retval 0 @retval -ENOMEM */
int calcv_preview(const struct calcv_board *b, const uint8_t *rgb, int width, int height,
                  const struct calcv_corners *corners, uint8_t **out, int *out_width,
                  int *out_height);
/** Zhang's calibration over @p n views (calibrateCamera), k3 fixed at 0 when @p fix_k3.
 *  @param lens  out @param rvec, tvec  out: 3 per view, board sheet -> camera
 *  @param view_rms  out: reprojection RMS per view, px @param rms  out: over all corners
 *  @retval 0 @retval -EINVAL too few views or corners @retval -EDOM OpenCV refused */
int calcv_calibrate(const struct calcv_corners *views, int n, int width, int height, int fix_k3,
                    struct calcv_lens *lens, double *rvec, double *tvec, double *view_rms,
                    double *rms);

/** Camera and projector together (stereoCalibrate, both lenses refined from the guesses given):
 *  @p cam and @p proj hold the same corners of each view (the caller keeps only corners both
 *  see). @param rot, trans  out: p_proj = rot p_cam + trans (row-major)
 *  @param rms  out @retval 0 @retval -EDOM OpenCV refused */
int calcv_stereo(const struct calcv_corners *cam, const struct calcv_corners *proj, int n,
                 int fix_k3, struct calcv_lens *cam_lens, struct calcv_lens *proj_lens,
                 double rot[9], double trans[3], double *rms);

/** Board pose from corners with a known lens (solvePnP, iterative).
 *  @param rvec, tvec  out @param rms  out: reprojection RMS @retval 0 @retval -EDOM */
int calcv_pose(const struct calcv_corners *v, const struct calcv_lens *lens, double rvec[3],
               double tvec[3], double *rms);

/** Rotation vector to matrix (row-major). */
void calcv_rodrigues(const double rvec[3], double rot[9]);

/** A pose carried through a rigid motion (composeRT): the board -> camera pose (@p rvec,
 *  @p tvec) followed by p' = @p rot p + @p trans, as a rotation vector and translation. */
void calcv_pose_through(const double rvec[3], const double tvec[3], const double rot[9],
                        const double trans[3], double rvec_out[3], double tvec_out[3]);

/** Reprojection RMS of @p v through @p lens at pose (rvec, tvec), px. */
double calcv_reprojection_rms(const struct calcv_corners *v, const struct calcv_lens *lens,
                              const double rvec[3], const double tvec[3]);

/** One standard deviation of each calibrated value (the weighted solve's own covariance: the
 *  inverse of Σ J_gᵀJ_g / var_g over each group g of reprojection residuals and every unknown,
 *  board poses included). Lens order: fx, fy, cx, cy, k1, k2, p1, p2, k3 (0 where fixed). */
struct calcv_sigma {
    double cam[9], proj[9];
    double rot_deg[3];  /**< the camera -> projector rotation vector's components */
    double trans_mm[3]; /**< its translation */
    double residual_px; /**< the residuals' standard deviation the covariance is scaled by */
    int residuals, unknowns;
};

/** A calibration drawn from the uncertainty (calcv_refine_weighted's covariance of the lenses and
 *  the pose, board poses marginalised): what the captures allow as well as the one found. */
struct calcv_draw {
    struct calcv_lens cam, proj;
    double rot[9], trans[3]; /**< p_proj = rot p_cam + trans */
};

/** A calibration solved once more, and its uncertainty: @p cam corners (and, unless @p proj is
 *  NULL, the same corners in the projector) of @p n views, from the lenses and the pose found.
 *  Each view's corners' x and y in the camera and in the projector are weighed by their own
 *  variance, estimated from their residuals (the corners of a board seen at a slant are found
 *  less exactly); the covariance is that weighted solve's.
 *  @param cam_lens, proj_lens, rot, trans  in: the unweighted solve's; out: the weighted one's
 *  (left as they were on an error). @param sigma  out @param draws, draw_count  out: that many
 *  calibrations drawn from the covariance (a fixed random sequence: the same captures give the
 *  same draws); NULL, 0: none
 *  @retval 0 @retval -EINVAL fewer residuals than unknowns @retval -EDOM */
int calcv_refine_weighted(const struct calcv_corners *cam, const struct calcv_corners *proj, int n,
                          int fix_k3, struct calcv_lens *cam_lens, struct calcv_lens *proj_lens,
                          double rot[9], double trans[3], struct calcv_sigma *sigma,
                          struct calcv_draw *draws, int draw_count);

#ifdef __cplusplus
}
#endif

#endif
