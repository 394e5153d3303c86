// OpenCV 4.6 (Debian libopencv-contrib-dev) for calibration, behind app/calib_cv.h: board
// drawing and detection (chessboard, ChArUco), calibrateCamera, stereoCalibrate, solvePnP.
#include "calib_cv.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace
{

cv::Ptr<cv::aruco::CharucoBoard> charuco(const calcv_board *b)
{
    cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(b->dictionary);
    return cv::aruco::CharucoBoard::create(b->squares_x, b->squares_y, (float)b->square_mm,
                                           (float)b->marker_mm, dict);
}

bool board_ok(const calcv_board *b)
{
    return b->squares_x >= 3 && b->squares_y >= 3 && b->square_mm > 0.0 &&
           (b->squares_x - 1) * (b->squares_y - 1) <= CALCV_MAX_CORNERS &&
           (b->kind == CALCV_CHESSBOARD ||
            (b->kind == CALCV_CHARUCO && b->marker_mm > 0.0 && b->marker_mm < b->square_mm));
}

cv::Matx33d camera_matrix(const calcv_lens *l)
{
    return cv::Matx33d(l->fx, 0, l->cx, 0, l->fy, l->cy, 0, 0, 1);
}

void lens_from(const cv::Mat &k, const cv::Mat &d, calcv_lens *l)
{
    l->fx = k.at<double>(0, 0);
    l->fy = k.at<double>(1, 1);
    l->cx = k.at<double>(0, 2);
    l->cy = k.at<double>(1, 2);
    for (int i = 0; i < 5; i++)
        l->dist[i] = i < (int)d.total() ? d.at<double>(i) : 0.0;
}

// (float points for OpenCV's calibration, double where a Jacobian is taken by differences)
template <typename P3, typename P2>
void split(const calcv_corners &v, std::vector<P3> &obj, std::vector<P2> &img)
{
    obj.clear();
    img.clear();
    for (int i = 0; i < v.count; i++) {
        obj.emplace_back(v.sheet[i][0], v.sheet[i][1], 0.0);
        img.emplace_back(v.image[i][0], v.image[i][1]);
    }
}

// Why a board was not found: what the image itself shows.
void explain(const cv::Mat &img, int found, int need, char *why, size_t len)
{
    double lo, hi;
    cv::Mat small;
    cv::resize(img, small, cv::Size(), 0.25, 0.25, cv::INTER_AREA);
    cv::minMaxLoc(small, &lo, &hi);
    int saturated = cv::countNonZero(img >= 250);
    if (hi - lo < 40.0)
        snprintf(why, len,
                 "too dark or too flat: the brightest and darkest areas differ by %.0f "
                 "grey levels (light the board, or raise the exposure)",
                 hi - lo);
    else if (saturated > (int)(img.total() / 50))
        snprintf(why, len,
                 "glare: %.1f%% of the image is saturated (tilt the board away from the "
                 "light, or lower the exposure)",
                 100.0 * saturated / (double)img.total());
    else if (found > 0)
        snprintf(why, len,
                 "too few corners: %d of the %d needed (is the board partly out of "
                 "view, or covered?)",
                 found, need);
    else
        snprintf(why, len,
                 "no board in view (is it partly out of view, too steep, or another "
                 "board than the config describes?)");
}

} // namespace

extern "C" int calcv_board_corner_count(const calcv_board *b)
{
    return (b->squares_x - 1) * (b->squares_y - 1);
}

extern "C" void calcv_board_size_mm(const calcv_board *b, double *w, double *h)
{
    *w = b->squares_x * b->square_mm + 2.0 * b->margin_mm;
    *h = b->squares_y * b->square_mm + 2.0 * b->margin_mm;
}

extern "C" int calcv_board_image(const calcv_board *b, double px_per_mm, uint8_t **grey, int *width,
                                 int *height)
{
    if (!board_ok(b) || px_per_mm <= 0.0)
        return -EINVAL;
    const int sq = (int)std::lround(b->square_mm * px_per_mm);
    // the margin at the squares' own scale, so that the whole sheet has one resolution
    const int margin = (int)std::lround(b->margin_mm * sq / b->square_mm);
    const int w = b->squares_x * sq + 2 * margin, h = b->squares_y * sq + 2 * margin;
    cv::Mat img(h, w, CV_8UC1, cv::Scalar(255));
    if (b->kind == CALCV_CHARUCO) {
        // The board exactly fills the area inside the margin: squares of sq pixels.
        cv::Mat inner;
        charuco(b)->draw(cv::Size(w - 2 * margin, h - 2 * margin), inner, 0, 1);
        inner.copyTo(img(cv::Rect(margin, margin, inner.cols, inner.rows)));
    } else {
        // A chessboard whose top-left square is black, as OpenCV's pattern generator draws it.
        for (int y = 0; y < b->squares_y; y++)
            for (int x = 0; x < b->squares_x; x++)
                if ((x + y) % 2 == 0)
                    img(cv::Rect(margin + x * sq, margin + y * sq, sq, sq)).setTo(0);
    }
    *grey = (uint8_t *)malloc((size_t)w * h);
    if (*grey == nullptr)
        return -ENOMEM;
    memcpy(*grey, img.data, (size_t)w * h);
    *width = w;
    *height = h;
    return 0;
}

extern "C" int calcv_preview(const calcv_board *b, const uint8_t *rgb, int width, int height,
                             const calcv_corners *corners, uint8_t **out, int *out_width,
                             int *out_height)
{
    const double scale = width > 640 ? 640.0 / width : 1.0;
    const int w = (int)(width * scale + 0.5), h = (int)(height * scale + 0.5);
    uint8_t *pixels = (uint8_t *)malloc((size_t)w * h * 3);
    if (pixels == NULL)
        return -ENOMEM;
    cv::Mat src(height, width, CV_8UC3, const_cast<uint8_t *>(rgb)), dst(h, w, CV_8UC3, pixels);
    cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_AREA);
    if (corners != NULL && corners->count > 0) { // OpenCV's colours are BGR
        cv::cvtColor(dst, dst, cv::COLOR_RGB2BGR);
        const int nx = b->squares_x - 1, ny = b->squares_y - 1;
        const bool whole = b->kind == CALCV_CHESSBOARD && corners->count == nx * ny;
        std::vector<cv::Point2f> pts;
        for (int i = 0; i < corners->count; i++) // centres at integers in both pictures
            pts.emplace_back((float)((corners->image[i][0] + 0.5) * scale - 0.5),
                             (float)((corners->image[i][1] + 0.5) * scale - 0.5));
        cv::drawChessboardCorners(dst, whole ? cv::Size(nx, ny) : cv::Size(corners->count, 1), pts,
                                  whole);
        cv::cvtColor(dst, dst, cv::COLOR_BGR2RGB);
    }
    *out = pixels;
    *out_width = w;
    *out_height = h;
    return 0;
}

extern "C" int calcv_find_corners(const calcv_board *b, const uint8_t *grey, int width, int height,
                                  int min_corners, calcv_corners *out, char *why, size_t why_len)
{
    if (!board_ok(b))
        return -EINVAL;
    cv::Mat img(height, width, CV_8UC1, const_cast<uint8_t *>(grey));
    out->count = 0;
    const int nx = b->squares_x - 1, ny = b->squares_y - 1;
    std::vector<cv::Point2f> pts;
    std::vector<int> ids;
    if (b->kind == CALCV_CHESSBOARD) {
        // (CALIB_CB_NORMALIZE_IMAGE equalises the histogram, which loses boards that fill
        // only part of a dark frame)
        if (!cv::findChessboardCornersSB(img, cv::Size(nx, ny), pts,
                                         cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) {
            explain(img, 0, nx * ny, why, why_len);
            return -ENOENT;
        }
        // A symmetric board reads the same turned by 180 degrees: take the reading whose first
        // corner is the higher one, so that every view numbers the corners alike.
        if (pts.front().y > pts.back().y)
            std::reverse(pts.begin(), pts.end());
        // Seen from the front, the sheet's x (along a row) turned into its y (down the rows) is
        // clockwise in the image; a reading the other way round is the board's mirror image.
        cv::Point2f ax = pts[nx - 1] - pts[0], ay = pts[(size_t)nx * (ny - 1)] - pts[0];
        if (ax.x * ay.y - ax.y * ay.x < 0.0f)
            for (int y = 0; y < ny; y++)
                std::reverse(pts.begin() + y * nx, pts.begin() + (y + 1) * nx);
        for (int i = 0; i < nx * ny; i++)
            ids.push_back(i);
    } else {
        cv::Ptr<cv::aruco::CharucoBoard> board = charuco(b);
        std::vector<int> marker_ids;
        std::vector<std::vector<cv::Point2f>> markers;
        cv::Ptr<cv::aruco::DetectorParameters> params = cv::aruco::DetectorParameters::create();
        params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_SUBPIX;
        cv::aruco::detectMarkers(img, board->dictionary, markers, marker_ids, params);
        if (!marker_ids.empty())
            cv::aruco::interpolateCornersCharuco(markers, marker_ids, img, board, pts, ids);
    }
    if ((int)ids.size() < min_corners) {
        explain(img, (int)ids.size(), min_corners, why, why_len);
        return -ENOENT;
    }
    // interpolateCornersCharuco refines over a window wide enough to take in the markers' edges,
    // which pulls the corners (0.1% in focal length, a pixel in the principal point, measured on
    // the simulator); refine again over a window within the white borders.
    if (b->kind == CALCV_CHARUCO)
        cv::cornerSubPix(
            img, pts, cv::Size(4, 4), cv::Size(-1, -1),
            cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-4));
    for (size_t i = 0; i < ids.size() && i < CALCV_MAX_CORNERS; i++) {
        int id = ids[i];
        out->id[i] = id;
        out->image[i][0] = pts[i].x;
        out->image[i][1] = pts[i].y;
        // Corner id runs row-major over the inner corners; corner (1, 1) of the squares is id 0.
        out->sheet[i][0] = b->margin_mm + (1 + id % nx) * b->square_mm;
        out->sheet[i][1] = b->margin_mm + (1 + id / nx) * b->square_mm;
        out->sheet[i][2] = 0.0;
        out->count = (int)i + 1;
    }
    return 0;
}

extern "C" int calcv_calibrate(const calcv_corners *views, int n, int width, int height, int fix_k3,
                               calcv_lens *lens, double *rvec, double *tvec, double *view_rms,
                               double *rms)
{
    if (n < 3)
        return -EINVAL;
    std::vector<std::vector<cv::Point3f>> obj(n);
    std::vector<std::vector<cv::Point2f>> img(n);
    for (int v = 0; v < n; v++) {
        if (views[v].count < 6)
            return -EINVAL;
        split(views[v], obj[v], img[v]);
    }
    cv::Mat k, d, per_view, sd_in, sd_ex;
    std::vector<cv::Mat> rv, tv;
    try {
        *rms = cv::calibrateCamera(
            obj, img, cv::Size(width, height), k, d, rv, tv, sd_in, sd_ex, per_view,
            fix_k3 ? cv::CALIB_FIX_K3 : 0,
            cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
    } catch (const cv::Exception &e) {
        fprintf(stderr, "calibrate: OpenCV: %s\n", e.what());
        return -EDOM;
    }
    lens_from(k, d, lens);
    for (int v = 0; v < n; v++) {
        for (int i = 0; i < 3; i++) {
            rvec[3 * v + i] = rv[v].at<double>(i);
            tvec[3 * v + i] = tv[v].at<double>(i);
        }
        view_rms[v] = per_view.at<double>(v);
    }
    return 0;
}

extern "C" int calcv_stereo(const calcv_corners *cam, const calcv_corners *proj, int n, int fix_k3,
                            calcv_lens *cam_lens, calcv_lens *proj_lens, double rot[9],
                            double trans[3], double *rms)
{
    std::vector<std::vector<cv::Point3f>> obj(n), obj2(n);
    std::vector<std::vector<cv::Point2f>> img1(n), img2(n);
    for (int v = 0; v < n; v++) {
        split(cam[v], obj[v], img1[v]);
        split(proj[v], obj2[v], img2[v]);
    }
    cv::Mat k1(camera_matrix(cam_lens)), k2(camera_matrix(proj_lens));
    cv::Mat d1(1, 5, CV_64F, cam_lens->dist), d2(1, 5, CV_64F, proj_lens->dist);
    d1 = d1.clone();
    d2 = d2.clone();
    cv::Mat r, t, e, f;
    try {
        *rms = cv::stereoCalibrate(
            obj, img1, img2, k1, d1, k2, d2, cv::Size(1, 1), r, t, e, f,
            cv::CALIB_USE_INTRINSIC_GUESS | (fix_k3 ? cv::CALIB_FIX_K3 : 0),
            cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-12));
    } catch (const cv::Exception &ex) {
        fprintf(stderr, "calibrate: OpenCV: %s\n", ex.what());
        return -EDOM;
    }
    lens_from(k1, d1, cam_lens);
    lens_from(k2, d2, proj_lens);
    for (int i = 0; i < 9; i++)
        rot[i] = r.at<double>(i / 3, i % 3);
    for (int i = 0; i < 3; i++)
        trans[i] = t.at<double>(i);
    return 0;
}

extern "C" void calcv_rodrigues(const double rvec[3], double rot[9])
{
    cv::Mat r;
    cv::Rodrigues(cv::Vec3d(rvec[0], rvec[1], rvec[2]), r);
    for (int i = 0; i < 9; i++)
        rot[i] = r.at<double>(i / 3, i % 3);
}

extern "C" void calcv_pose_through(const double rvec[3], const double tvec[3], const double rot[9],
                                   const double trans[3], double rvec_out[3], double tvec_out[3])
{
    cv::Vec3d r2, r3, t3;
    cv::Rodrigues(cv::Matx33d(rot), r2);
    cv::composeRT(cv::Vec3d(rvec), cv::Vec3d(tvec), r2, cv::Vec3d(trans), r3, t3);
    for (int i = 0; i < 3; i++) {
        rvec_out[i] = r3[i];
        tvec_out[i] = t3[i];
    }
}

extern "C" double calcv_reprojection_rms(const calcv_corners *v, const calcv_lens *lens,
                                         const double rvec[3], const double tvec[3])
{
    std::vector<cv::Point3f> obj;
    std::vector<cv::Point2f> img, proj;
    split(*v, obj, img);
    if (obj.empty())
        return 0.0;
    cv::Mat d(1, 5, CV_64F, const_cast<double *>(lens->dist));
    cv::projectPoints(obj, cv::Vec3d(rvec[0], rvec[1], rvec[2]),
                      cv::Vec3d(tvec[0], tvec[1], tvec[2]), camera_matrix(lens), d, proj);
    double sum = 0.0;
    for (size_t i = 0; i < img.size(); i++) {
        cv::Point2f e = img[i] - proj[i];
        sum += e.dot(e);
    }
    return std::sqrt(sum / (double)img.size());
}

extern "C" int calcv_pose(const calcv_corners *v, const calcv_lens *lens, double rvec[3],
                          double tvec[3], double *rms)
{
    std::vector<cv::Point3f> obj;
    std::vector<cv::Point2f> img;
    split(*v, obj, img);
    cv::Mat d(1, 5, CV_64F, const_cast<double *>(lens->dist));
    cv::Vec3d r, t;
    try {
        if (!cv::solvePnP(obj, img, camera_matrix(lens), d, r, t, false, cv::SOLVEPNP_ITERATIVE))
            return -EDOM;
    } catch (const cv::Exception &e) {
        fprintf(stderr, "calibrate: OpenCV: %s\n", e.what());
        return -EDOM;
    }
    for (int i = 0; i < 3; i++) {
        rvec[i] = r[i];
        tvec[i] = t[i];
    }
    *rms = calcv_reprojection_rms(v, lens, rvec, tvec);
    return 0;
}

namespace
{

// The unknowns of a calibration as one vector: camera lens (9), projector lens (9), the camera
// -> projector rotation vector and translation (6), and each view's board -> camera pose (6).
// In double throughout: a step of 1e-6 of a principal point moves a corner by 6e-4 px, which
// float coordinates (6e-5 px at 1000 px) would blur into noise, and noise in the Jacobian's
// columns hides the near-degenerate directions (it said a camera's principal point to 0.006 px
// where the calibration's spread over noise seeds was 0.4 px).
struct joint_problem {
    const calcv_corners *cam, *proj;
    int n;
    std::vector<std::vector<cv::Point3d>> obj;
    std::vector<std::vector<cv::Point2d>> img_cam, img_proj;
};

void lens_at(const std::vector<double> &x, int at, cv::Matx33d &k, cv::Mat &d)
{
    k = cv::Matx33d(x[at], 0, x[at + 2], 0, x[at + 1], x[at + 3], 0, 0, 1);
    d = cv::Mat(1, 5, CV_64F);
    for (int i = 0; i < 5; i++)
        d.at<double>(i) = x[at + 4 + i];
}

// Every reprojection residual: of each view, the corners' x in the camera, their y, then their x
// and y in the projector (so that each is one group of rows, joint_groups).
void joint_residuals(const joint_problem &p, const std::vector<double> &x, std::vector<double> &r)
{
    r.clear();
    cv::Matx33d kc, kp;
    cv::Mat dc, dp;
    lens_at(x, 0, kc, dc);
    lens_at(x, 9, kp, dp);
    cv::Vec3d rs(x[18], x[19], x[20]), ts(x[21], x[22], x[23]);
    std::vector<cv::Point2d> out;
    for (int v = 0; v < p.n; v++) {
        const double *pose = &x[24 + 6 * (size_t)v];
        cv::Vec3d rv(pose[0], pose[1], pose[2]), tv(pose[3], pose[4], pose[5]);
        cv::projectPoints(p.obj[v], rv, tv, kc, dc, out);
        for (size_t i = 0; i < out.size(); i++)
            r.push_back(out[i].x - p.img_cam[v][i].x);
        for (size_t i = 0; i < out.size(); i++)
            r.push_back(out[i].y - p.img_cam[v][i].y);
        if (p.proj == nullptr)
            continue;
        cv::Vec3d r3, t3;
        cv::composeRT(rv, tv, rs, ts, r3, t3);
        cv::projectPoints(p.obj[v], r3, t3, kp, dp, out);
        for (size_t i = 0; i < out.size(); i++)
            r.push_back(out[i].x - p.img_proj[v][i].x);
        for (size_t i = 0; i < out.size(); i++)
            r.push_back(out[i].y - p.img_proj[v][i].y);
    }
}

// The residuals at @p x and their Jacobian in the unknowns @p free, by central differences with a
// step relative to each value.
void joint_jacobian(const joint_problem &p, const std::vector<double> &x,
                    const std::vector<int> &free, std::vector<double> &r0, cv::Mat &jac)
{
    std::vector<double> rp, rm;
    joint_residuals(p, x, r0);
    const int m = (int)r0.size(), k = (int)free.size();
    jac.create(m, k, CV_64F);
    for (int c = 0; c < k; c++) {
        int i = free[c];
        double h = 1e-6 * std::max(1.0, std::fabs(x[i]));
        std::vector<double> xp = x, xm = x;
        xp[i] += h;
        xm[i] -= h;
        joint_residuals(p, xp, rp);
        joint_residuals(p, xm, rm);
        for (int row = 0; row < m; row++)
            jac.at<double>(row, c) = (rp[row] - rm[row]) / (2.0 * h);
    }
}

// The rows of one group of residuals: one coordinate of one view's corners in the camera or in
// the projector.
struct group {
    int row, count;
};

// The groups in joint_residuals' order: of each view, the camera's x and y, the projector's x
// and y. Each its own: the projector's columns and rows are decoded from different stripes, seen
// at different slants, and a corner's x and y errors differ with the board's tilt.
std::vector<group> joint_groups(const joint_problem &p)
{
    std::vector<group> g;
    int row = 0;
    for (int v = 0; v < p.n; v++)
        for (int axis = 0; axis < (p.proj != nullptr ? 4 : 2); axis++) {
            g.push_back({row, p.cam[v].count});
            row += p.cam[v].count;
        }
    return g;
}

// The weighted sum of squares of residuals @p r, group @p g over its variance @p var.
double weighted_squares(const std::vector<double> &r, const std::vector<group> &g,
                        const std::vector<double> &var)
{
    double chi = 0.0;
    for (size_t i = 0; i < g.size(); i++)
        for (int row = g[i].row; row < g[i].row + g[i].count; row++)
            chi += r[(size_t)row] * r[(size_t)row] / var[i];
    return chi;
}

// The weighted normal equations of @p jac and residuals @p r, each group @p g weighed by the
// inverse of its variance @p var: a = sum J_g^T J_g / var_g, b = sum J_g^T r_g / var_g; and the
// weighted sum of squares.
double weighted_normal(const cv::Mat &jac, const std::vector<double> &r,
                       const std::vector<group> &g, const std::vector<double> &var, cv::Mat &a,
                       cv::Mat &b)
{
    const int k = jac.cols;
    a = cv::Mat::zeros(k, k, CV_64F);
    b = cv::Mat::zeros(k, 1, CV_64F);
    for (size_t i = 0; i < g.size(); i++) {
        cv::Mat jg = jac(cv::Range(g[i].row, g[i].row + g[i].count), cv::Range::all());
        cv::Mat rg(g[i].count, 1, CV_64F, const_cast<double *>(&r[(size_t)g[i].row]));
        a += jg.t() * jg / var[i];
        b += jg.t() * rg / var[i];
    }
    return weighted_squares(r, g, var); /* the sum a step's is compared with, summed alike */
}

// Each group's variance again from its residuals @p r over its redundancy (Foerstner's variance
// components): var_g = r_g^T r_g / (n_g - tr(A^-1 J_g^T J_g / var_g)), the trace being the
// share of the unknowns the group's own rows determine; the redundancies sum to m - k. A
// group's variance is held above a hundredth of the mean's, so that no view can take the whole
// weight by fitting too well.
void group_variances(const cv::Mat &jac, const std::vector<double> &r, const std::vector<group> &g,
                     const cv::Mat &cov, std::vector<double> &var)
{
    double sum = 0.0, count = 0.0;
    std::vector<double> next(g.size());
    for (size_t i = 0; i < g.size(); i++) {
        cv::Mat jg = jac(cv::Range(g[i].row, g[i].row + g[i].count), cv::Range::all());
        double ss = 0.0;
        for (int row = g[i].row; row < g[i].row + g[i].count; row++)
            ss += r[(size_t)row] * r[(size_t)row];
        double redundancy = g[i].count - cv::sum((cov * (jg.t() * jg)).diag())[0] / var[i];
        next[i] = ss / std::max(redundancy, 0.5);
        sum += ss;
        count += g[i].count;
    }
    for (size_t i = 0; i < g.size(); i++) /* and above 1e-12 px^2: corners that fit exactly */
        var[i] = std::max(next[i], std::max(0.01 * sum / count, 1e-12));
}

// The lenses (and, with @p projector, the projector's lens and the pose) of unknowns @p x.
void what_was_solved(const std::vector<double> &x, bool projector, calcv_lens *cam,
                     calcv_lens *proj, double rot[9], double trans[3])
{
    calcv_lens *l[2] = {cam, proj};
    for (int j = 0; j < (projector ? 2 : 1); j++) {
        l[j]->fx = x[9 * j], l[j]->fy = x[9 * j + 1], l[j]->cx = x[9 * j + 2];
        l[j]->cy = x[9 * j + 3];
        for (int i = 0; i < 5; i++)
            l[j]->dist[i] = x[9 * j + 4 + i];
    }
    if (!projector)
        return;
    cv::Matx33d r;
    cv::Rodrigues(cv::Vec3d(x[18], x[19], x[20]), r);
    for (int i = 0; i < 9; i++)
        rot[i] = r(i / 3, i % 3);
    for (int i = 0; i < 3; i++)
        trans[i] = x[21 + i];
}

// The unknowns solved for: the camera's lens, the projector's and the pose between them when
// there is a projector, k3 unless fixed, every board pose.
std::vector<int> joint_free(int n, bool projector, int fix_k3)
{
    std::vector<int> free;
    for (int i = 0; i < 24 + 6 * n; i++) {
        bool projector_part = i >= 9 && i < 24;
        bool k3 = i == 8 || i == 17;
        if ((projector_part && !projector) || (k3 && fix_k3))
            continue;
        free.push_back(i);
    }
    return free;
}

// The problem @p p and its unknowns @p x from the lenses and the pose given, each board's pose
// where the camera alone puts it. @retval 0 @retval -EDOM a board's pose not found
int joint_start(const calcv_lens *cam_lens, const calcv_lens *proj_lens, const double rot[9],
                const double trans[3], joint_problem &p, std::vector<double> &x)
{
    x.assign(24 + 6 * (size_t)p.n, 0.0);
    const calcv_lens *lenses[2] = {cam_lens, p.proj != nullptr ? proj_lens : cam_lens};
    for (int l = 0; l < 2; l++) {
        x[9 * l] = lenses[l]->fx, x[9 * l + 1] = lenses[l]->fy;
        x[9 * l + 2] = lenses[l]->cx, x[9 * l + 3] = lenses[l]->cy;
        for (int i = 0; i < 5; i++)
            x[9 * l + 4 + i] = lenses[l]->dist[i];
    }
    if (p.proj != nullptr) {
        cv::Vec3d rs;
        cv::Rodrigues(cv::Matx33d(rot), rs);
        for (int i = 0; i < 3; i++)
            x[18 + i] = rs[i], x[21 + i] = trans[i];
    }
    p.obj.resize(p.n);
    p.img_cam.resize(p.n);
    p.img_proj.resize(p.n);
    for (int v = 0; v < p.n; v++) {
        split(p.cam[v], p.obj[v], p.img_cam[v]);
        if (p.proj != nullptr) {
            std::vector<cv::Point3d> o;
            split(p.proj[v], o, p.img_proj[v]);
        }
        double rv[3], tv[3], rms;
        if (calcv_pose(&p.cam[v], cam_lens, rv, tv, &rms) != 0)
            return -EDOM;
        for (int i = 0; i < 3; i++)
            x[24 + 6 * (size_t)v + i] = rv[i], x[24 + 6 * (size_t)v + 3 + i] = tv[i];
    }
    return 0;
}

// Gauss-Newton on unknowns @p x (@p free of them), each group of residuals weighed by its own
// variance, estimated again before each step. The corners of a board seen at a slant are found
// several times less exactly than those of a square one (per view 0.015 to 0.07 px on the demo
// rig): weighed alike they pull the lenses as hard as the best, and a covariance
// scaled by one variance for all states the best views' corners as poorly known as the
// worst's. A step is kept only if it lowers the weighted sum of squares (a near-degenerate
// problem, five boards, could otherwise wander). Out: @p cov, the weighted solve's covariance
// (sum J_g^T J_g / var_g)^-1 scaled by the weighted residuals' variance factor (1 when the
// variances are right), and the residuals @p r0. @retval 0 @retval -EDOM singular
int weighted_steps(const joint_problem &p, const std::vector<int> &free, std::vector<double> &x,
                   std::vector<double> &r0, cv::Mat &cov)
{
    cv::Mat jac, a, b;
    std::vector<group> g = joint_groups(p);
    joint_jacobian(p, x, free, r0, jac);
    const int m = (int)r0.size(), k = (int)free.size();
    double sse = 0.0;
    for (double e : r0)
        sse += e * e;
    std::vector<double> var(g.size(), std::max(sse / (double)(m - k), 1e-12));
    double chi = weighted_normal(jac, r0, g, var, a, b);
    for (int pass = 0; pass < 12; pass++) {
        if (cv::invert(a, cov, cv::DECOMP_SVD) == 0.0)
            return -EDOM;
        group_variances(jac, r0, g, cov, var);
        chi = weighted_normal(jac, r0, g, var, a, b);
        if (cv::invert(a, cov, cv::DECOMP_SVD) == 0.0)
            return -EDOM;
        cv::Mat step = -(cov * b);
        std::vector<double> y = x, r1;
        double largest = 0.0;
        for (int c = 0; c < k; c++) {
            y[free[c]] += step.at<double>(c);
            largest = std::max(largest, std::fabs(step.at<double>(c)) /
                                            std::max(1.0, std::fabs(x[free[c]])));
        }
        joint_residuals(p, y, r1);
        if (!(weighted_squares(r1, g, var) < chi))
            break;
        x = y;
        joint_jacobian(p, x, free, r0, jac);
        chi = weighted_normal(jac, r0, g, var, a, b);
        if (largest < 1e-10)
            break;
    }
    if (cv::invert(a, cov, cv::DECOMP_SVD) == 0.0)
        return -EDOM;
    cov *= chi / (double)(m - k);
    return 0;
}

} // namespace

extern "C" int calcv_refine_weighted(const calcv_corners *cam, const calcv_corners *proj, int n,
                                     int fix_k3, calcv_lens *cam_lens, calcv_lens *proj_lens,
                                     double rot[9], double trans[3], calcv_sigma *sigma,
                                     calcv_draw *draws, int draw_count)
{
    std::memset(sigma, 0, sizeof(*sigma));
    joint_problem p{cam, proj, n, {}, {}, {}};
    std::vector<int> free = joint_free(n, proj != nullptr, fix_k3);
    int m = 0;
    for (int v = 0; v < n; v++)
        m += 2 * cam[v].count + (proj != nullptr ? 2 * proj[v].count : 0);
    const int k = (int)free.size();
    if (m <= k)
        return -EINVAL;
    std::vector<double> x, r0;
    if (joint_start(cam_lens, proj_lens, rot, trans, p, x) != 0)
        return -EDOM;
    // First Gauss-Newton steps on the board poses alone (the lenses and the pose between them
    // as the calibration found them), so that the residuals the variances are first estimated
    // from are where camera and projector agree; then every unknown, weighed.
    cv::Mat jac, cov;
    for (int pass = 0; pass < 2; pass++) {
        joint_jacobian(p, x, free, r0, jac);
        if (cv::invert(jac.t() * jac, cov, cv::DECOMP_SVD) == 0.0)
            return -EDOM;
        cv::Mat step = -(cov * (jac.t() * cv::Mat(r0)));
        for (int c = 0; c < k; c++)
            if (free[c] >= 24)
                x[free[c]] += step.at<double>(c);
    }
    if (weighted_steps(p, free, x, r0, cov) != 0)
        return -EDOM;
    double sse = 0.0;
    for (double e : r0)
        sse += e * e;
    for (int c = 0; c < k; c++) {
        int i = free[c];
        double sd = std::sqrt(std::max(0.0, cov.at<double>(c, c)));
        if (i < 9)
            sigma->cam[i] = sd;
        else if (i < 18)
            sigma->proj[i - 9] = sd;
        else if (i < 21)
            sigma->rot_deg[i - 18] = sd * 180.0 / CV_PI;
        else if (i < 24)
            sigma->trans_mm[i - 21] = sd;
    }
    sigma->residual_px = std::sqrt(sse / (double)(m - k));
    sigma->residuals = m;
    sigma->unknowns = k;
    what_was_solved(x, proj != nullptr, cam_lens, proj_lens, rot, trans);
    // Draws from the lenses' and the pose's block of the covariance (the board poses' rows
    // marginalised by leaving them out): its square root by eigen-decomposition, times N(0, I).
    int q = 0;
    while (q < k && free[q] < 24)
        q++;
    if (draws == nullptr || draw_count <= 0 || q == 0)
        return 0;
    cv::Mat block = cov(cv::Range(0, q), cv::Range(0, q)).clone(), w, u;
    cv::eigen(block, w, u); // block = u^T diag(w) u
    cv::RNG rng(31);
    for (int d = 0; d < draw_count; d++) {
        cv::Mat z(q, 1, CV_64F);
        for (int i = 0; i < q; i++)
            z.at<double>(i) = rng.gaussian(1.0) * std::sqrt(std::max(0.0, w.at<double>(i)));
        cv::Mat delta = u.t() * z;
        std::vector<double> y = x;
        for (int c = 0; c < q; c++)
            y[free[c]] += delta.at<double>(c);
        calcv_draw *o = &draws[d];
        what_was_solved(y, true, &o->cam, &o->proj, o->rot, o->trans);
    }
    return 0;
}
