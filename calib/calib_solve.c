/* The calibration computed from the captures of a calibration directory: camera and projector
 * lenses and pose (OpenCV, calib/calib_cv.cpp), the turntable axis, the lights; the file and its
 * report (docs/calibration.md). A setup step: it allocates. Longer than 800 lines on purpose:
 * one procedure whose stages run top to bottom in the order they are written (the board views,
 * the joint solve, the axis, the lights, the sphere check, the file), each a short function, so
 * that a reader follows a calibration in one file. */
#define _POSIX_C_SOURCE 200809L
#include "calib_priv.h"

#include "decode.h"
#include "camray.h"
#include "lsq.h"
#include "scan.h"
#include "scan_dir.h"
#include "scan_job.h"
#include "tri.h"
#include "vec3.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <unistd.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

/* Calibrations drawn from the uncertainty to see what it does to a scan. */
#define CALIB_DEPTH_DRAWS 64
/* Half the side of the window the projector's coordinates are interpolated over at a corner. */
#define CORNER_WINDOW_PX 12

/* The folders captures are read from: --from's, and --add's (placements added later). */
#define CALIB_MAX_DIRS 2

struct board_view {
    const char *dir; /* the folder it was captured into */
    uint32_t view;
    struct calib_target_info ti;
    struct calcv_corners cam;  /* every corner found */
    struct calcv_corners camp; /* the corners the projector's coordinates are known at */
    struct calcv_corners proj; /* those corners in projector pixels */
    double rvec[3], tvec[3], rms;
    double joint_cam_rms, joint_proj_rms; /* px, through the joint lenses; -1: not known */
    int found, has_proj;
};

struct solve {
    const struct app_config *cfg;
    const char *dir; /* the first folder: the calibration the captures were taken with */
    const char *dirs[CALIB_MAX_DIRS];
    uint32_t dir_count;
    struct scan_calib start; /* the calibration the captures were taken with */
    int start_guessed;       /* none was found: start is calibrate_guess's */
    struct scan_calib out;
    struct scan_params params;
    struct calcv_board board;
    struct board_view *views;
    uint32_t view_count;
    uint32_t sphere_views[CALIB_MAX_VIEWS];
    const char *sphere_dirs[CALIB_MAX_VIEWS];
    uint32_t sphere_count;
    char *report;
    size_t report_len, report_cap;
    char refusal[512]; /* the last "refused: ..." line, for the error message */
    int json;          /* --json: stdout holds the JSON object alone */
    double cam_rms, proj_rms, stereo_rms;
    int camera_only;
    struct calcv_sigma sigma; /* one standard deviation of each value (have_sigma) */
    int have_sigma;
    struct calcv_draw *draws; /* calibrations drawn from the uncertainty (draw_count) */
    int draw_count;
    double depth_centre_mm, depth_worst_mm, length_100_mm; /* predict_depth_error's */
    /* one standard deviation of the axis (its direction; its point across the axis and along
     * it) and of each light's position (the length of its error); 0: not known */
    double axis_dir_sigma_deg, axis_across_sigma_mm, axis_along_sigma_mm;
    double light_sigma_mm[HAL_MAX_LIGHTS];
    char weak[192];             /* what is too uncertain ("" when nothing) ... */
    char advice[192];           /* ... and what to capture next */
    const char *add_placements; /* ... as [calibrate] placements */
};

static void say(struct solve *s, const char *fmt, ...)
{
    va_list ap;
    char line[1024];
    va_start(ap, fmt);
    int n = vsnprintf(line, sizeof(line), fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if ((size_t)n >= sizeof(line))
        n = (int)sizeof(line) - 1;
    if (s->report_len + (size_t)n + 1 > s->report_cap) {
        size_t cap = 2 * s->report_cap + (size_t)n + 1024;
        char *r = realloc(s->report, cap);
        if (r == NULL)
            return;
        s->report = r;
        s->report_cap = cap;
    }
    memcpy(s->report + s->report_len, line, (size_t)n + 1);
    s->report_len += (size_t)n;
    if (strncmp(line, "refused: ", 9) == 0)
        snprintf(s->refusal, sizeof(s->refusal), "%.*s", (int)strcspn(line + 9, "\n"), line + 9);
}

static int frame_exists(const char *dir, uint32_t view, uint32_t frame)
{
    char path[SCAN_DIR_PATH_MAX];
    struct stat sb;
    return scan_dir_find_frame(path, sizeof(path), dir, view, frame) == 0 && stat(path, &sb) == 0;
}

/* Feed a capture's pattern frames to the decoder. @retval 0 @retval -ENOENT the last is not
 * there (a capture of the white frame alone) @retval -EINVAL one before it is missing or
 * unreadable: a damaged capture, said */
static int feed_patterns(struct solve *s, const char *dir, uint32_t v,
                         const struct scan_calib *calib)
{
    struct gray_layout layout;
    char err[SCAN_DIR_PATH_MAX + 256];
    scan_layout(&s->params, calib, &layout);
    if (!frame_exists(dir, v, gray_layout_count(&layout) - 1))
        return -ENOENT;
    int rc =
        scan_job_feed_view(scan_job_views(), dir, v, &s->params, calib, NULL, err, sizeof(err));
    if (rc != 0)
        fprintf(stderr, "scanner: error: %s\n", err);
    return rc == -ENOENT ? -EINVAL : rc;
}

/* The projector's column and row at camera point (x, y): a plane fitted by least squares to
 * the decoded integer codes of the valid pixels within CORNER_WINDOW_PX (each coordinate on its
 * own: a linear interpolation of the decoded maps, not a homography between the images),
 * evaluated at the point; twice, the second fit without the codes more than 1.5 off the first.
 * The stair-steps of the codes average out over the window; the black squares (too dark to
 * decode) leave holes in it, which a plane bridges. Over a window of a few millimetres the
 * curvature of the map (perspective, the projector's lens) is far below a hundredth of a pixel.
 * @retval 1 known @retval 0 too few decoded pixels around */
#define NB 3 /* the plane's coefficients: 1, dx, dy */
static int projector_at(const struct decode_maps *m, double x, double y, double *u, double *v)
{
    const int r = CORNER_WINDOW_PX;
    double out[2];
    for (int which = 0; which < 2; which++) {
        const uint16_t *code = which == 0 ? m->column : m->row;
        double first[NB] = {0};
        for (int pass = 0; pass < 2; pass++) {
            double a[NB][NB + 1];
            memset(a, 0, sizeof(a));
            int n = 0;
            for (int dy = -r; dy <= r; dy++) {
                for (int dx = -r; dx <= r; dx++) {
                    long px = lround(x) + dx, py = lround(y) + dy;
                    if (px < 0 || py < 0 || px >= (long)m->width || py >= (long)m->height)
                        continue;
                    size_t i = (size_t)py * m->width + (size_t)px;
                    if (m->reason[i] != SCAN_VALID)
                        continue;
                    double ex = (double)px - x, ey = (double)py - y;
                    double b[NB] = {1, ex, ey};
                    double val = code[i];
                    if (pass == 1) {
                        double pred = 0;
                        for (int k = 0; k < NB; k++)
                            pred += first[k] * b[k];
                        if (fabs(pred - val) > 1.5)
                            continue;
                    }
                    for (int j = 0; j < NB; j++) {
                        for (int k = 0; k < NB; k++)
                            a[j][k] += b[j] * b[k];
                        a[j][NB] += b[j] * val;
                    }
                    n++;
                }
            }
            if (n < (2 * r + 1) * (2 * r + 1) / 4)
                return 0;
            double m[NB * NB], rhs[NB];
            for (int j = 0; j < NB; j++) {
                for (int k = 0; k < NB; k++)
                    m[NB * j + k] = a[j][k];
                rhs[j] = a[j][NB];
            }
            if (!calib_solve_n(m, rhs, first, NB))
                return 0;
        }
        out[which] = first[0];
    }
    *u = out[0];
    *v = out[1];
    return 1;
}

/* A board capture: its corners, and where the projector's coordinates are known, those. */
static int load_board_view(struct solve *s, struct board_view *bv)
{
    static uint8_t rgb[HAL_MAX_PIXELS * 3], grey[HAL_MAX_PIXELS];
    static uint8_t reason[HAL_MAX_PIXELS];
    char err[SCAN_DIR_PATH_MAX + 256], why[256];
    const uint32_t w = s->start.cam_width, h = s->start.cam_height;
    int rc = scan_dir_read_frame(bv->dir, bv->view, 0, rgb, sizeof(rgb), w, h, 3, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return rc;
    }
    decode_rgb_to_grey(rgb, grey, (size_t)w * h, 256);
    if (calcv_find_corners(&s->board, grey, (int)w, (int)h, (int)s->cfg->calibrate.min_corners,
                           &bv->cam, why, sizeof(why)) != 0) {
        say(s, "view_%03u: rejected: board not found: %s\n", (unsigned)bv->view, why);
        return 0;
    }
    bv->found = 1;
    if (frame_exists(bv->dir, bv->view, 1) == 0) {
        say(s, "view_%03u: %d corners (white frame only: camera alone)\n", (unsigned)bv->view,
            bv->cam.count);
        return 0;
    }
    if ((rc = feed_patterns(s, bv->dir, bv->view, &s->start)) != 0) {
        say(s, "view_%03u: %d corners; the pattern frames are incomplete: camera only\n",
            (unsigned)bv->view, bv->cam.count);
        return rc == -ENOENT ? 0 : rc;
    }
    struct decode_maps maps;
    if ((rc = decode_finish(&scan_job_views()->decode, NULL, reason, &maps)) != 0)
        return rc;
    if (maps.row == NULL) {
        say(s, "view_%03u: no projector rows were captured: camera only\n", (unsigned)bv->view);
        return 0;
    }
    for (int i = 0; i < bv->cam.count; i++) {
        double u, v;
        if (!projector_at(&maps, bv->cam.image[i][0], bv->cam.image[i][1], &u, &v))
            continue;
        int k = bv->camp.count++;
        bv->camp.id[k] = bv->proj.id[k] = bv->cam.id[i];
        memcpy(bv->camp.image[k], bv->cam.image[i], sizeof(bv->cam.image[i]));
        memcpy(bv->camp.sheet[k], bv->cam.sheet[i], sizeof(bv->cam.sheet[i]));
        memcpy(bv->proj.sheet[k], bv->cam.sheet[i], sizeof(bv->cam.sheet[i]));
        bv->proj.image[k][0] = u;
        bv->proj.image[k][1] = v;
        bv->proj.count = k + 1;
    }
    bv->has_proj = bv->proj.count >= (int)s->cfg->calibrate.min_corners;
    say(s, "view_%03u: %d corners, %d with projector coordinates%s\n", (unsigned)bv->view,
        bv->cam.count, bv->proj.count, bv->has_proj ? "" : " (too few: camera only)");
    return 0;
}

static int by_number(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* The captures in the directory: every view_NNN folder with a first frame, by number, however
 * many digits (view_100 and on too). More than CALIB_MAX_VIEWS is refused, not cut short; a
 * folder whose first frame cannot be looked at (a link loop) is said. @retval 0 @retval -errno */
static int list_views(struct solve *s, const char *dir, uint32_t room, uint32_t *views,
                      uint32_t *count)
{
    DIR *d = opendir(dir);
    uint32_t n = 0, over = 0;
    int rc = 0;
    if (d == NULL) {
        rc = -errno;
        fprintf(stderr, "scanner: error: %s: %s\n", dir, strerror(-rc));
        return rc;
    }
    for (struct dirent *e; rc == 0 && (e = readdir(d)) != NULL;) {
        unsigned long v;
        char *end;
        if (strncmp(e->d_name, "view_", 5) != 0 || e->d_name[5] < '0' || e->d_name[5] > '9')
            continue;
        v = strtoul(e->d_name + 5, &end, 10);
        if (*end != '\0' || v > 999999)
            continue;
        char path[SCAN_DIR_PATH_MAX];
        rc = scan_dir_find_frame(path, sizeof(path), dir, (uint32_t)v, 0);
        if (rc == -ENOENT) {
            rc = 0;
            continue;
        }
        if (rc != 0) {
            fprintf(stderr, "scanner: error: %s: %s\n", path, strerror(-rc));
            break;
        }
        if (n < room)
            views[n++] = (uint32_t)v;
        else
            over++;
    }
    closedir(d);
    if (rc == 0 && over > 0) {
        say(s, "refused: %s holds %u captures; a calibration takes at most %u in all\n", dir,
            (unsigned)(n + over), (unsigned)CALIB_MAX_VIEWS);
        rc = -EINVAL;
    }
    qsort(views, n, sizeof(*views), by_number);
    *count = n;
    return rc;
}

/* The captures of folder @p f. A placement is one folder's: the axis pairs captures of one
 * placement only, so an added folder's placements are numbered apart (CALIB_PLACEMENTS_APART). */
#define CALIB_PLACEMENTS_APART 100000u
static int load_folder(struct solve *s, uint32_t f)
{
    static uint32_t views[CALIB_MAX_VIEWS];
    const char *dir = s->dirs[f];
    uint32_t count = 0, had = s->view_count + s->sphere_count;
    int listed = list_views(s, dir, CALIB_MAX_VIEWS - had, views, &count);
    if (listed != 0)
        return listed;
    if (s->dir_count > 1)
        say(s, "%s: %u captures\n", dir, (unsigned)count);
    for (uint32_t k = 0; k < count; k++) {
        uint32_t v = views[k];
        struct calib_target_info ti;
        char err[SCAN_DIR_PATH_MAX + 256];
        int rc = calib_read_target(dir, v, &ti, err, sizeof(err));
        if (rc != 0) {
            fprintf(stderr, "scanner: error: %s\n", err);
            return rc;
        }
        if (ti.kind == CALIB_TARGET_SPHERE) {
            s->sphere_dirs[s->sphere_count] = dir;
            s->sphere_views[s->sphere_count++] = v;
            continue;
        }
        ti.placement += f * CALIB_PLACEMENTS_APART;
        struct board_view *bv = &s->views[s->view_count];
        memset(bv, 0, sizeof(*bv));
        bv->joint_cam_rms = bv->joint_proj_rms = -1.0;
        bv->dir = dir;
        bv->view = v;
        bv->ti = ti;
        if ((rc = load_board_view(s, bv)) != 0)
            return rc;
        s->view_count++;
    }
    return 0;
}

static int load_views(struct solve *s)
{
    for (uint32_t f = 0; f < s->dir_count; f++) {
        int rc = load_folder(s, f);
        if (rc != 0)
            return rc;
    }
    return 0;
}

/* The largest angle between two boards' normals, degrees: Zhang's method needs the board in
 * several orientations; one orientation (however many images) cannot give the focal length. */
static double orientation_spread_deg(const struct solve *s)
{
    double worst = 0.0;
    for (uint32_t i = 0; i < s->view_count; i++) {
        for (uint32_t j = i + 1; j < s->view_count; j++) {
            const struct board_view *a = &s->views[i], *b = &s->views[j];
            if (!a->found || !b->found)
                continue;
            double ra[9], rb[9];
            calcv_rodrigues(a->rvec, ra);
            calcv_rodrigues(b->rvec, rb);
            double c = ra[2] * rb[2] + ra[5] * rb[5] + ra[8] * rb[8];
            worst = fmax(worst, acos(fmin(1.0, fmax(-1.0, c))) * 180.0 / M_PI);
        }
    }
    return worst;
}

static void lens_to_calib(const struct calcv_lens *l, int projector, struct scan_calib *c)
{
    if (projector) {
        c->proj_fx_px = l->fx, c->proj_fy_px = l->fy, c->proj_cx_px = l->cx, c->proj_cy_px = l->cy;
        memcpy(c->proj_dist, l->dist, sizeof(c->proj_dist));
    } else {
        c->cam_fx_px = l->fx, c->cam_fy_px = l->fy, c->cam_cx_px = l->cx, c->cam_cy_px = l->cy;
        memcpy(c->cam_dist, l->dist, sizeof(c->cam_dist));
    }
}

static void calib_to_lens(const struct scan_calib *c, int projector, struct calcv_lens *l)
{
    if (projector) {
        l->fx = c->proj_fx_px, l->fy = c->proj_fy_px, l->cx = c->proj_cx_px, l->cy = c->proj_cy_px;
        memcpy(l->dist, c->proj_dist, sizeof(l->dist));
    } else {
        l->fx = c->cam_fx_px, l->fy = c->cam_fy_px, l->cx = c->cam_cx_px, l->cy = c->cam_cy_px;
        memcpy(l->dist, c->cam_dist, sizeof(l->dist));
    }
}

/* Zhang's method on every board found; an image far worse than the rest is dropped once. */
static int solve_camera(struct solve *s)
{
    const struct calib_settings *cs = &s->cfg->calibrate;
    /* Zhang's method needs the board in several orientations: judged first from poses through
     * the starting lens (rough, but orientations differ by far more than its error). */
    struct calcv_lens start;
    calib_to_lens(&s->start, 0, &start);
    int found = 0;
    for (uint32_t i = 0; i < s->view_count; i++)
        found += s->views[i].found;
    if (found < 3) {
        say(s,
            "refused: too few views: the board was found in %d image%s; at least 3 in "
            "different orientations are needed (10 or more give a good calibration)\n",
            found, found == 1 ? "" : "s");
        return -EINVAL;
    }
    for (uint32_t i = 0; i < s->view_count; i++) {
        struct board_view *bv = &s->views[i];
        double rms;
        if (bv->found && calcv_pose(&bv->cam, &start, bv->rvec, bv->tvec, &rms) != 0)
            bv->found = 0;
    }
    double spread = orientation_spread_deg(s);
    if (spread < 5.0) {
        say(s,
            "refused: degenerate placements: every board faces the same way (the normals "
            "differ by %.1f deg at most); turn the table or tilt the board between captures\n",
            spread);
        return -EINVAL;
    }
    static struct calcv_corners sel[CALIB_MAX_VIEWS];
    static double rv[CALIB_MAX_VIEWS * 3], tv[CALIB_MAX_VIEWS * 3], vr[CALIB_MAX_VIEWS];
    uint32_t idx[CALIB_MAX_VIEWS];
    struct calcv_lens lens;
    for (int attempt = 0; attempt < 2; attempt++) {
        int n = 0;
        for (uint32_t i = 0; i < s->view_count; i++)
            if (s->views[i].found) {
                idx[n] = i;
                sel[n++] = s->views[i].cam;
            }
        if (n < 3) {
            say(s,
                "refused: too few views: the board was found in %d image%s; at least 3 in "
                "different orientations are needed (10 or more give a good calibration)\n",
                n, n == 1 ? "" : "s");
            return -EINVAL;
        }
        int rc = calcv_calibrate(sel, n, (int)s->start.cam_width, (int)s->start.cam_height,
                                 (int)cs->fix_k3, &lens, rv, tv, vr, &s->cam_rms);
        if (rc != 0) {
            say(s, "refused: the camera calibration did not converge (OpenCV: see above)\n");
            return -EINVAL;
        }
        double sorted[CALIB_MAX_VIEWS], median;
        memcpy(sorted, vr, sizeof(double) * (size_t)n);
        for (int a = 1; a < n; a++)
            for (int b = a; b > 0 && sorted[b] < sorted[b - 1]; b--) {
                double t = sorted[b];
                sorted[b] = sorted[b - 1];
                sorted[b - 1] = t;
            }
        median = sorted[n / 2];
        int dropped = 0;
        for (int k = 0; k < n; k++) {
            struct board_view *bv = &s->views[idx[k]];
            memcpy(bv->rvec, &rv[3 * k], sizeof(bv->rvec));
            memcpy(bv->tvec, &tv[3 * k], sizeof(bv->tvec));
            bv->rms = vr[k];
            if (attempt == 0 && vr[k] > 3.0 * median && vr[k] > 0.3) {
                say(s,
                    "view_%03u: rejected: reprojection RMS %.3f px, over 3x the median %.3f "
                    "(blurred, or the board moved during the capture?)\n",
                    (unsigned)bv->view, vr[k], median);
                bv->found = bv->has_proj = 0;
                dropped++;
            }
        }
        if (dropped == 0)
            break;
    }
    lens_to_calib(&lens, 0, &s->out);
    say(s,
        "camera: reprojection RMS %.4f px over the boards found; orientations spread over "
        "%.0f deg\n",
        s->cam_rms, spread);
    if (s->cam_rms > cs->max_camera_rms_px) {
        say(s,
            "refused: the camera's reprojection RMS %.3f px is above [calibrate] "
            "max_camera_rms_px = %.3f (blurred or moving captures, a board that is not flat, or "
            "square_mm wrong?)\n",
            s->cam_rms, cs->max_camera_rms_px);
        return -EINVAL;
    }
    return 0;
}

/* The uncertainty of what was solved (calcv_sigma), said in the report: a lens's focal lengths
 * and principal point, its distortion, and the pose between camera and projector. */
static void say_lens_sigma(struct solve *s, const char *name, const double sd[9])
{
    say(s,
        "%s: 1 sigma: fx %.3g, fy %.3g, cx %.3g, cy %.3g px; k1 %.2g, k2 %.2g, p1 %.2g, "
        "p2 %.2g, k3 %.2g\n",
        name, sd[0], sd[1], sd[2], sd[3], sd[4], sd[5], sd[6], sd[7], sd[8]);
}

/* The lenses @p cl and @p pl (and the pose in s->out) solved once more with each view's corners
 * weighed by their own variance (calcv_refine_weighted), and their uncertainty, said in the
 * report. Left as the unweighted solve found them when it cannot be computed. */
static void find_sigma(struct solve *s, const struct calcv_corners *cam,
                       const struct calcv_corners *proj, int n, struct calcv_lens *cl,
                       struct calcv_lens *pl)
{
    if (proj != NULL && s->draws == NULL)
        s->draws = calloc(CALIB_DEPTH_DRAWS, sizeof(*s->draws));
    s->draw_count = proj != NULL && s->draws != NULL ? CALIB_DEPTH_DRAWS : 0;
    s->have_sigma =
        calcv_refine_weighted(cam, proj, n, (int)s->cfg->calibrate.fix_k3, cl, pl, s->out.proj_rot,
                              s->out.proj_trans_mm, &s->sigma, s->draws, s->draw_count) == 0;
    if (!s->have_sigma) {
        say(s, "uncertainty: not computed (fewer corners than unknowns)\n");
        return;
    }
    say_lens_sigma(s, "camera", s->sigma.cam);
    if (proj == NULL)
        return;
    say_lens_sigma(s, "projector", s->sigma.proj);
    say(s,
        "pose camera -> projector: 1 sigma: rotation %.2g, %.2g, %.2g deg, translation %.3g, "
        "%.3g, %.3g mm (%d residuals, %d unknowns, residual %.3f px)\n",
        s->sigma.rot_deg[0], s->sigma.rot_deg[1], s->sigma.rot_deg[2], s->sigma.trans_mm[0],
        s->sigma.trans_mm[1], s->sigma.trans_mm[2], s->sigma.residuals, s->sigma.unknowns,
        s->sigma.residual_px);
}

/* Append to @p buf what of lens @p name (sigma @p sd, focal @p fx) is less certain than the
 * bounds. @retval 1 something was */
static int weak_lens(const struct calib_settings *cs, const char *name, const double sd[9],
                     double fx, char *buf, size_t len)
{
    int weak = 0;
    size_t n = strlen(buf);
    double centre = fmax(sd[2], sd[3]), focal = fmax(sd[0], sd[1]);
    if (centre > cs->max_sigma_centre_px && n < len) {
        n += (size_t)snprintf(buf + n, len - n, "%s%s principal point +-%.2g px", n ? ", " : "",
                              name, centre);
        weak = 1;
    }
    if (focal > cs->max_sigma_focal_share * fx && n < len) {
        snprintf(buf + n, len - n, "%s%s focal length +-%.2g%%", n ? ", " : "", name,
                 100.0 * focal / fx);
        weak = 1;
    }
    return weak;
}

/* A calibration whose values are less certain than [calibrate] max_sigma_*, or whose predicted
 * depth error at the working volume's edge is above max_depth_error_mm, is written, but flagged
 * weak (its file says so, check-config warns), with what would constrain them: a lens's
 * principal point and focal length are fixed by boards seen tilted and off the image's centre;
 * the projector's, and the pose between it and the camera (what a scan's depth depends on
 * beyond the camera), by boards tilted towards and away from the projector and at other
 * distances. */
static void judge_uncertainty(struct solve *s)
{
    const struct calib_settings *cs = &s->cfg->calibrate;
    char what[sizeof(s->weak)] = "";
    s->weak[0] = '\0';
    if (!s->have_sigma)
        return;
    int cam = weak_lens(cs, "camera", s->sigma.cam, s->out.cam_fx_px, what, sizeof(what));
    int proj = !s->camera_only &&
               weak_lens(cs, "projector", s->sigma.proj, s->out.proj_fx_px, what, sizeof(what));
    double t = fmax(s->sigma.trans_mm[0], fmax(s->sigma.trans_mm[1], s->sigma.trans_mm[2]));
    double r = fmax(s->sigma.rot_deg[0], fmax(s->sigma.rot_deg[1], s->sigma.rot_deg[2]));
    size_t n = strlen(what);
    int pose =
        !s->camera_only && (t > cs->max_sigma_translation_mm || r > cs->max_sigma_rotation_deg);
    if (pose)
        n += (size_t)snprintf(what + n, sizeof(what) - n, "%sprojector pose +-%.2g mm, +-%.2g deg",
                              n ? ", " : "", t, r);
    int depth = !s->camera_only && s->depth_worst_mm > cs->max_depth_error_mm;
    if (depth && n < sizeof(what)) {
        char why[64] = "";
        if (!pose) /* what the depth depends on beyond the camera */
            snprintf(why, sizeof(why), " (projector pose +-%.2g mm, +-%.2g deg)", t, r);
        snprintf(what + n, sizeof(what) - n, "%spredicted depth error %.2g mm at the edge%s",
                 n ? ", " : "", s->depth_worst_mm, why);
    }
    proj = proj || pose || depth;
    if (!cam && !proj)
        return;
    snprintf(s->weak, sizeof(s->weak), "%s", what);
    s->add_placements = proj ? "35, -35, 0@75, 0@-75" : "35@75, -35@-75";
    snprintf(s->advice, sizeof(s->advice), "add %s ([calibrate] placements = %s)",
             proj ? "placements tilted towards and away from the projector and at other offsets"
                  : "placements tilted 30 to 45 deg and offset towards the image's corners",
             s->add_placements);
    say(s, "weak: %s; %s\n", s->weak, s->advice);
    say(s,
        "to add them to these captures: a config with only those placements (and sphere_turns "
        "= 0), 'scanner calibrate --config F2 --out NEW.ini', then 'scanner calibrate --config F "
        "--from %s --add NEW-captures --out FILE'\n",
        s->dir);
}

/* Pixels of the working volume looked at, every this many in x and y. */
#define CALIB_DEPTH_STEP_PX 16

/* Where the camera-frame point @p p falls in the projector of @p c: its column (pixel centres at
 * integers, through the projector's distortion). @retval 0 outside its image or behind it */
static int projector_column(const struct scan_calib *c, vec3 p, double *u)
{
    double v;
    return camray_project_projector(c, p, u, &v) && *u >= 0.0 && *u <= c->proj_width - 1.0 &&
           v >= 0.0 && v <= c->proj_height - 1.0;
}

/* The working volume seen on CALIB_DEPTH_PLANES planes facing the camera: through the axis, and
 * half the volume's radius in front of it and behind it (the middle plane first). */
#define CALIB_DEPTH_PLANES 3

/* What the drawn calibrations are compared on. Per plane, a camera image of the projector
 * column the solved calibration puts on each sampled pixel (valid marks them); the samples as a
 * list: their plane and pixel, the point itself, where a draw puts it, and its squared errors
 * summed over the draws; which samples are the volume's centre and 50 mm either side of it. */
struct depth_samples {
    float *column;
    uint8_t *valid, *reason;
    uint32_t *pixel; /* plane * w * h + y * w + x */
    vec3 *truth, *drawn;
    double *sq;
    size_t count, centre, ends[2];
};

/* Add plane @p k of the working volume to @p d, seen through the calibration @p c. */
static void sample_plane(const struct solve *s, const struct scan_calib *c, int k,
                         struct depth_samples *d, double best[3])
{
    const uint32_t w = c->cam_width, h = c->cam_height;
    const size_t off = (size_t)k * w * h;
    const double radius = s->cfg->fusion.radius_mm, mid = 0.5 * s->cfg->fusion.top_mm;
    const double depth = k == 0 ? 0.0 : (k == 1 ? -0.5 : 0.5) * radius;
    const double half = sqrt(radius * radius - depth * depth); /* its width inside the volume */
    vec3 ad = v3_norm(v3_from(c->axis_dir));
    vec3 n = v3_norm(v3_sub(v3(0, 0, 1), v3_scale(ad, ad.z))); /* the planes face the camera */
    vec3 a0 = v3_add(v3_from(c->axis_point_mm), v3_scale(n, depth));
    vec3 across = v3_norm(v3_cross(ad, n));
    struct camray rays = camray_lookup(c);
    memset(d->valid + off, SCAN_SHADOW, (size_t)w * h);
    for (uint32_t y = 0; y < h; y += CALIB_DEPTH_STEP_PX)
        for (uint32_t x = 0; x < w; x += CALIB_DEPTH_STEP_PX) {
            vec3 ray = camray_at(c, rays, x, y);
            double den = v3_dot(n, ray), u;
            if (fabs(den) < 1e-9)
                continue;
            vec3 p = v3_scale(ray, v3_dot(n, a0) / den), e = v3_sub(p, a0);
            double up = v3_dot(e, ad), side = v3_dot(e, across);
            if (up < 0.0 || up > s->cfg->fusion.top_mm || fabs(side) > half ||
                !projector_column(c, p, &u))
                continue;
            size_t i = (size_t)y * w + x, j = d->count++;
            d->valid[off + i] = SCAN_VALID;
            d->column[off + i] = (float)u;
            d->pixel[j] = (uint32_t)(off + i);
            d->truth[j] = p;
            d->sq[j] = 0.0;
            if (k != 0)
                continue;
            double dist[3] = {hypot(up - mid, side), hypot(up - mid, side + 50.0),
                              hypot(up - mid, side - 50.0)};
            for (int m = 0; m < 3; m++)
                if (dist[m] < best[m]) {
                    best[m] = dist[m];
                    *(m == 0 ? &d->centre : &d->ends[m - 1]) = j;
                }
        }
}

/* @p drawn (@p count points) moved by the rigid motion that best brings them onto @p truth:
 * point to point as three point-to-plane pairs each (Horn's closed form would do the same).
 * @retval 0 @retval -EDOM too few points */
static int remove_rigid(vec3 *drawn, const vec3 *truth, size_t count)
{
    const vec3 axes[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
    for (int pass = 0; pass < 3; pass++) {
        struct lsq_rigid eq;
        struct frame_xform step;
        lsq_rigid_clear(&eq);
        for (size_t j = 0; j < count; j++)
            for (int a = 0; a < 3; a++)
                lsq_rigid_add(&eq, drawn[j], truth[j], axes[a]);
        if (lsq_rigid_step(&eq, &step) != 0)
            return -EDOM;
        for (size_t j = 0; j < count; j++)
            drawn[j] = frame_point(&step, drawn[j]);
    }
    return 0;
}

/* One drawn calibration @p ck: every sample triangulated again (the scanner's tri_range_image),
 * the rigid motion that best moves them back removed, the errors that remain added to d->sq, the
 * 100 mm length's change (in % of it) through @p dl_pct. Why the motion is removed: a
 * calibration that turns or shifts the camera's frame (a camera principal point 0.4 px off
 * turns it by 0.01 deg, 0.1 mm at the table) finds the turntable's axis in that same frame, from
 * the same board poses, so the model comes out the same shape, only placed differently.
 * @retval 0 @retval -EDOM a lens that folds over where a sample is, or a sample it does not see:
 * not one to judge by */
static int draw_error(const struct scan_calib *ck, struct tri_maps *maps, struct depth_samples *d,
                      double *dl_pct)
{
    const size_t plane = (size_t)ck->cam_width * ck->cam_height;
    memcpy(d->reason, d->valid, CALIB_DEPTH_PLANES * plane);
    for (size_t j = 0, k = 0; k < CALIB_DEPTH_PLANES; k++) {
        struct tri_range range;
        if (tri_range_image(ck, NULL, maps, ck->cam_width, ck->cam_height, d->column + k * plane,
                            d->reason + k * plane, &range) != 0)
            return -EDOM;
        for (; j < d->count && d->pixel[j] < (k + 1) * plane; j++) {
            size_t i = d->pixel[j] - k * plane;
            if (d->reason[d->pixel[j]] != SCAN_VALID)
                return -EDOM;
            d->drawn[j] = v3(maps->xyz_mm[3 * i], maps->xyz_mm[3 * i + 1], maps->xyz_mm[3 * i + 2]);
        }
    }
    if (remove_rigid(d->drawn, d->truth, d->count) != 0)
        return -EDOM;
    for (size_t j = 0; j < d->count; j++)
        d->sq[j] += v3_dot(v3_sub(d->drawn[j], d->truth[j]), v3_sub(d->drawn[j], d->truth[j]));
    double len0 = v3_len(v3_sub(d->truth[d->ends[0]], d->truth[d->ends[1]]));
    double len = v3_len(v3_sub(d->drawn[d->ends[0]], d->drawn[d->ends[1]]));
    *dl_pct = (len - len0) * 100.0 / fmax(len0, 1e-9);
    return 0;
}

/* The axis's share of the model's error, on a cylinder of the working volume (half its radius,
 * its height) in steps of CALIB_AXIS_STEP_DEG around and CALIB_AXIS_RINGS high. */
#define CALIB_AXIS_STEP_DEG 10
#define CALIB_AXIS_RINGS 9

/* What an axis error does to a model: a point of the object is seen by the views that face it
 * (within 60 degrees), each placed through the axis as the scanner places it
 * (frame_object_from_camera_rad); with the axis off, each view lands off by a different amount,
 * and the fused model is their mean. Unlike the lenses' errors this one is no rigid motion: a
 * point off by da across the axis moves every view by (I - R(theta)) da, which, averaged round
 * the object, changes its radius by up to |da|; a tilt shears it with height. Linear in the four
 * independent errors (the point's two directions across the axis, the direction's two tilts,
 * about the volume's middle), so each is applied at its sigma, the rigid motion removed, and the
 * squared errors summed: @p mid_mm the RMS at mid-height, @p worst_mm the largest.
 * @retval 0 @retval -ENOMEM */
static int axis_model_error(const struct solve *s, double *mid_mm, double *worst_mm)
{
    const struct scan_calib *c = &s->out;
    enum { AROUND = 360 / CALIB_AXIS_STEP_DEG, COUNT = AROUND * CALIB_AXIS_RINGS };
    const double radius = 0.5 * s->cfg->fusion.radius_mm, top = s->cfg->fusion.top_mm;
    const vec3 d = v3_norm(v3_from(c->axis_dir)), a = v3_from(c->axis_point_mm);
    const vec3 pivot = v3_add(a, v3_scale(d, 0.5 * top));
    vec3 e1, e2, *truth = malloc(COUNT * sizeof(vec3)), *model = malloc(COUNT * sizeof(vec3));
    /* the errors of the axis are drawn in the camera's frame, across it (e1, e2) */
    double *var = calloc(COUNT, sizeof(double));
    int rc = -ENOMEM;
    *mid_mm = *worst_mm = 0.0;
    if (truth == NULL || model == NULL || var == NULL)
        goto out_free;
    v3_across(d, &e1, &e2);
    const double sa = s->axis_across_sigma_mm / sqrt(2.0);
    const double st = s->axis_dir_sigma_deg * M_PI / 180.0 / sqrt(2.0);
    for (int k = 0; k < 4; k++) {
        struct scan_calib off = *c;
        vec3 ad = d, ap = a;
        if (k < 2) /* the point across the axis */
            ap = v3_add(a, v3_scale(k == 0 ? e1 : e2, sa));
        else { /* the direction tilted about the volume's middle */
            ad = v3_norm(v3_add(d, v3_scale(k == 2 ? e1 : e2, st)));
            ap = v3_sub(pivot, v3_scale(ad, 0.5 * top));
        }
        memcpy(off.axis_dir, (double[3]){ad.x, ad.y, ad.z}, sizeof(off.axis_dir));
        memcpy(off.axis_point_mm, (double[3]){ap.x, ap.y, ap.z}, sizeof(off.axis_point_mm));
        for (int ring = 0; ring < CALIB_AXIS_RINGS; ring++)
            for (int i = 0; i < AROUND; i++) {
                /* in the object's frame: the axis its z, the table at z = 0 */
                double phi = i * CALIB_AXIS_STEP_DEG * M_PI / 180.0;
                vec3 out = v3(cos(phi), sin(phi), 0.0);
                vec3 x = v3(radius * out.x, radius * out.y, top * ring / (CALIB_AXIS_RINGS - 1.0));
                vec3 sum = v3(0, 0, 0);
                int views = 0;
                for (int step = 0; step < AROUND; step++) {
                    struct frame_xform f, g;
                    double theta = step * CALIB_AXIS_STEP_DEG * M_PI / 180.0;
                    frame_object_from_camera_rad(c, theta, &f);
                    vec3 cam = v3_sub(frame_point(&f, v3(0, 0, 0)), x);
                    if (v3_dot(cam, out) < 0.5 * v3_len(cam))
                        continue; /* this view does not face the point */
                    frame_object_from_camera_rad(&off, theta, &g);
                    sum = v3_add(sum, frame_point(&g, frame_point_inv(&f, x)));
                    views++;
                }
                size_t j = (size_t)ring * AROUND + (size_t)i;
                truth[j] = x;
                model[j] = views > 0 ? v3_scale(sum, 1.0 / views) : x;
            }
        if (remove_rigid(model, truth, COUNT) != 0) {
            rc = -EDOM;
            goto out_free;
        }
        for (size_t j = 0; j < COUNT; j++)
            var[j] += v3_dot(v3_sub(model[j], truth[j]), v3_sub(model[j], truth[j]));
    }
    for (size_t j = 0; j < COUNT; j++) {
        *worst_mm = fmax(*worst_mm, sqrt(var[j]));
        if (j / AROUND == CALIB_AXIS_RINGS / 2)
            *mid_mm += var[j] / AROUND;
    }
    *mid_mm = sqrt(*mid_mm);
    rc = 0;
out_free:
    free(var);
    free(model);
    free(truth);
    return rc;
}

/* What the uncertainty does to a scan: CALIB_DEPTH_DRAWS calibrations drawn from it (lenses and
 * pose; the board poses marginalised), the working volume triangulated by each, the RMS error
 * at the volume's centre and its worst, and a 100 mm length's. */
static void predict_depth_error(struct solve *s)
{
    const struct scan_calib *c = &s->out;
    const size_t plane = (size_t)c->cam_width * c->cam_height, most = CALIB_DEPTH_PLANES * plane;
    if (!s->have_sigma || s->camera_only || s->draw_count == 0)
        return;
    struct depth_samples d = {
        .column = calloc(most, sizeof(float)),
        .valid = malloc(most),
        .reason = malloc(most),
        .pixel = malloc(most / CALIB_DEPTH_STEP_PX * sizeof(uint32_t)),
        .truth = malloc(most / CALIB_DEPTH_STEP_PX * sizeof(vec3)),
        .drawn = malloc(most / CALIB_DEPTH_STEP_PX * sizeof(vec3)),
        .sq = malloc(most / CALIB_DEPTH_STEP_PX * sizeof(double)),
    };
    struct tri_maps *maps = malloc(sizeof(*maps));
    double best[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL};
    if (d.column == NULL || d.valid == NULL || d.reason == NULL || d.pixel == NULL ||
        d.truth == NULL || d.drawn == NULL || d.sq == NULL || maps == NULL)
        goto out_free;
    for (int k = 0; k < CALIB_DEPTH_PLANES; k++)
        sample_plane(s, c, k, &d, best);
    if (best[0] == HUGE_VAL || best[1] == HUGE_VAL || best[2] == HUGE_VAL)
        goto out_free; /* the volume's middle is not in view */
    double len_sq = 0.0, dl;
    int used = 0;
    for (int k = 0; k < s->draw_count; k++) {
        struct scan_calib ck = *c;
        const struct calcv_draw *draw = &s->draws[k];
        lens_to_calib(&draw->cam, 0, &ck);
        lens_to_calib(&draw->proj, 1, &ck);
        memcpy(ck.proj_rot, draw->rot, sizeof(ck.proj_rot));
        memcpy(ck.proj_trans_mm, draw->trans, sizeof(ck.proj_trans_mm));
        if (draw_error(&ck, maps, &d, &dl) != 0)
            continue;
        len_sq += dl * dl;
        used++;
    }
    if (used == 0)
        goto out_free;
    double worst = 0.0;
    for (size_t j = 0; j < d.count; j++)
        worst = fmax(worst, sqrt(d.sq[j] / used));
    double axis_mid = 0.0, axis_worst = 0.0;
    if (s->axis_dir_sigma_deg > 0.0 && axis_model_error(s, &axis_mid, &axis_worst) != 0)
        axis_mid = axis_worst = 0.0;
    /* the lenses' and the axis's errors are independent: their variances add */
    s->depth_centre_mm = sqrt(d.sq[d.centre] / used + axis_mid * axis_mid);
    s->depth_worst_mm = sqrt(worst * worst + axis_worst * axis_worst);
    s->length_100_mm = sqrt(len_sq / used);
    say(s,
        "predicted depth error %.3g mm (centre) - %.3g mm (edge of the working volume); a 100 mm "
        "length +-%.3g mm (%d calibrations drawn from the lenses' uncertainty, and the axis's: "
        "%.3g - %.3g mm of it)\n",
        s->depth_centre_mm, s->depth_worst_mm, s->length_100_mm, used, axis_mid, axis_worst);
out_free:
    free(maps);
    free(d.sq);
    free(d.drawn);
    free(d.truth);
    free(d.pixel);
    free(d.reason);
    free(d.valid);
    free(d.column);
}

/* The projector as an inverse camera (Zhang's method on the corners' projector coordinates),
 * then camera and projector refined together with the pose between them (stereoCalibrate). */
static int solve_projector(struct solve *s)
{
    const struct calib_settings *cs = &s->cfg->calibrate;
    static struct calcv_corners cam[CALIB_MAX_VIEWS], proj[CALIB_MAX_VIEWS];
    static double rv[CALIB_MAX_VIEWS * 3], tv[CALIB_MAX_VIEWS * 3], vr[CALIB_MAX_VIEWS];
    int n = 0;
    for (uint32_t i = 0; i < s->view_count; i++)
        if (s->views[i].found && s->views[i].has_proj) {
            cam[n] = s->views[i].camp;
            proj[n++] = s->views[i].proj;
        }
    if (n == 0) {
        s->camera_only = 1;
        say(s,
            "projector: no capture has its patterns: the camera alone is calibrated (the "
            "projector, the axis and the lights stay %s)\n",
            s->start_guessed ? "guesses: there was no calibration file to start from; use this "
                               "file for the camera only"
                             : "as the starting file has them");
        for (uint32_t i = 0; i < s->view_count; i++)
            if (s->views[i].found)
                cam[n++] = s->views[i].cam;
        struct calcv_lens cl;
        calib_to_lens(&s->out, 0, &cl);
        find_sigma(s, cam, NULL, n, &cl, NULL);
        lens_to_calib(&cl, 0, &s->out);
        return 0;
    }
    if (n < 3) {
        say(s, "refused: too few views with projector coordinates: %d (at least 3)\n", n);
        return -EINVAL;
    }
    struct calcv_lens pl, cl;
    if (calcv_calibrate(proj, n, (int)s->start.proj_width, (int)s->start.proj_height,
                        (int)cs->fix_k3, &pl, rv, tv, vr, &s->proj_rms) != 0) {
        say(s, "refused: the projector calibration did not converge\n");
        return -EINVAL;
    }
    calib_to_lens(&s->out, 0, &cl);
    if (calcv_stereo(cam, proj, n, (int)cs->fix_k3, &cl, &pl, s->out.proj_rot, s->out.proj_trans_mm,
                     &s->stereo_rms) != 0) {
        say(s, "refused: the joint camera-projector calibration did not converge\n");
        return -EINVAL;
    }
    say(s, "joint camera-projector RMS %.4f px (each corner weighed alike)\n", s->stereo_rms);
    find_sigma(s, cam, proj, n, &cl, &pl);
    lens_to_calib(&cl, 0, &s->out);
    lens_to_calib(&pl, 1, &s->out);
    /* The projector's own RMS, with the joint lenses: each view's board pose from the camera,
     * carried into the projector by the stereo pose. */
    double sum = 0.0;
    int count = 0;
    for (uint32_t i = 0; i < s->view_count; i++) {
        struct board_view *bv = &s->views[i];
        if (!bv->found || !bv->has_proj)
            continue;
        double rvec[3], tvec[3], rms, rvp[3], tp[3];
        if (calcv_pose(&bv->camp, &cl, rvec, tvec, &rms) != 0)
            continue;
        /* board -> projector: the camera's pose carried through the stereo pose */
        calcv_pose_through(rvec, tvec, s->out.proj_rot, s->out.proj_trans_mm, rvp, tp);
        double e = calcv_reprojection_rms(&bv->proj, &pl, rvp, tp);
        say(s, "view_%03u: camera %.3f px, projector %.3f px\n", (unsigned)bv->view, rms, e);
        bv->joint_cam_rms = rms;
        bv->joint_proj_rms = e;
        sum += e * e * bv->proj.count;
        count += bv->proj.count;
    }
    s->proj_rms = count > 0 ? sqrt(sum / count) : 0.0;
    say(s, "projector: reprojection RMS %.4f px (joint RMS %.4f px over %d views)\n", s->proj_rms,
        s->stereo_rms, n);
    if (s->proj_rms > cs->max_projector_rms_px) {
        say(s,
            "refused: the projector's reprojection RMS %.3f px is above [calibrate] "
            "max_projector_rms_px = %.3f (patterns out of focus, or the board moved?)\n",
            s->proj_rms, cs->max_projector_rms_px);
        return -EINVAL;
    }
    return 0;
}

/* Board views @p i and @p j (rotations @p r) are a pair the axis is found from: one placement
 * at two table angles. Their relative turn R_ij = R_j R_i^T through @p rij, t_ij through @p tij. */
static int axis_pair(const struct solve *s, double r[][9], uint32_t i, uint32_t j, double rij[9],
                     double tij[3])
{
    const struct board_view *a = &s->views[i], *b = &s->views[j];
    if (!a->found || !b->found || !a->ti.has_angle || !b->ti.has_angle ||
        a->ti.placement != b->ti.placement || a->ti.angle_mdeg == b->ti.angle_mdeg)
        return 0;
    for (int x = 0; x < 3; x++)
        for (int y = 0; y < 3; y++) {
            rij[3 * x + y] = 0;
            for (int k = 0; k < 3; k++)
                rij[3 * x + y] += r[j][3 * x + k] * r[i][3 * y + k];
        }
    for (int x = 0; x < 3; x++) {
        tij[x] = b->tvec[x];
        for (int k = 0; k < 3; k++)
            tij[x] -= rij[3 * x + k] * a->tvec[k];
    }
    return 1;
}

/* The axis's uncertainty from how well it explains the pairs: the scatter of each pair's own
 * turn axis about direction @p a, and the residuals of (I - R_ij) c = t_ij at the point @p c
 * (covariance sigma^2 (A^T A)^-1, @p ata pinned as solved). The pairs of one placement share
 * captures (five captures make ten pairs, four of them independent), so the scatter counts
 * captures less placements as the independent turns. */
static void axis_sigma(struct solve *s, double r[][9], vec3 a, const double c[3],
                       const double ata[9])
{
    double ang_sq = 0.0, res_sq = 0.0, rij[9], tij[3];
    int pairs = 0, captures = 0, placements = 0;
    for (uint32_t i = 0; i < s->view_count; i++) {
        int paired = 0, first_of_placement = 1;
        for (uint32_t j = 0; j < s->view_count; j++) {
            if (j != i && axis_pair(s, r, i, j, rij, tij))
                paired = 1;
            if (j < i && s->views[j].found && s->views[j].ti.placement == s->views[i].ti.placement)
                first_of_placement = 0;
        }
        captures += paired;
        placements += paired && first_of_placement;
        for (uint32_t j = i + 1; j < s->view_count; j++) {
            if (!axis_pair(s, r, i, j, rij, tij))
                continue;
            double sgn = s->views[j].ti.angle_mdeg > s->views[i].ti.angle_mdeg ? 1.0 : -1.0;
            vec3 u = v3_norm(v3_scale(v3(rij[7] - rij[5], rij[2] - rij[6], rij[3] - rij[1]), sgn));
            double ang = acos(fmin(1.0, fmax(-1.0, v3_dot(u, a))));
            ang_sq += ang * ang;
            for (int x = 0; x < 3; x++) {
                double e = -tij[x];
                for (int k = 0; k < 3; k++)
                    e += ((x == k ? 1.0 : 0.0) - rij[3 * x + k]) * c[k];
                res_sq += e * e;
            }
            pairs++;
        }
    }
    int turns = captures - placements;
    if (pairs < 2 || turns < 2)
        return;
    double over = (double)pairs / turns; /* how many times the pairs count each turn */
    s->axis_dir_sigma_deg = sqrt(ang_sq / (pairs - 1) / turns) * 180.0 / M_PI;
    double var = res_sq / fmax(1.0, 3.0 * pairs - 3.0) * over, inv[9];
    for (int col = 0; col < 3; col++) { /* (A^T A)^-1, column by column */
        double m[9], e[3] = {col == 0, col == 1, col == 2}, x[3];
        memcpy(m, ata, sizeof(m));
        if (!calib_solve_n(m, e, x, 3))
            return;
        for (int row = 0; row < 3; row++)
            inv[3 * row + col] = x[row];
    }
    /* across the axis: the trace of the point's covariance less its part along the axis */
    double tr = inv[0] + inv[4] + inv[8], along = 0.0;
    const double av[3] = {a.x, a.y, a.z};
    for (int x = 0; x < 3; x++)
        for (int y = 0; y < 3; y++)
            along += av[x] * inv[3 * x + y] * av[y];
    s->axis_across_sigma_mm = sqrt(fmax(0.0, var * (tr - along)));
}

/* The turntable axis from the board's poses: two captures of one placement differ by a turn
 * about the axis, X_j = R_ij X_i + t_ij with R_ij = R_j R_i^T, t_ij = t_j - R_ij t_i. The turn's
 * axis (the skew part of R_ij, signed by the table's angle step) gives the direction; every
 * point c of the axis stays put, (I - R_ij) c = t_ij, stacked over all pairs by least squares.
 * The table's surface: each board's plate stands on it, so the sheet's bottom edge, less the
 * plate's thickness along the sheet's normal, lies on it. */
static int solve_axis(struct solve *s)
{
    double dir[3] = {0, 0, 0}, ata[9] = {0}, atb[3] = {0};
    int pairs = 0;
    double r[CALIB_MAX_VIEWS][9];
    for (uint32_t i = 0; i < s->view_count; i++) {
        struct board_view *bv = &s->views[i];
        if (bv->found) {
            struct calcv_lens cl;
            double rms;
            calib_to_lens(&s->out, 0, &cl);
            if (calcv_pose(&bv->cam, &cl, bv->rvec, bv->tvec, &rms) != 0)
                bv->found = 0;
            calcv_rodrigues(bv->rvec, r[i]);
        }
    }
    for (int pass = 0; pass < 2; pass++) {
        for (uint32_t i = 0; i < s->view_count; i++) {
            for (uint32_t j = i + 1; j < s->view_count; j++) {
                double rij[9], tij[3];
                if (!axis_pair(s, r, i, j, rij, tij))
                    continue;
                if (pass == 0) {
                    double sgn = s->views[j].ti.angle_mdeg > s->views[i].ti.angle_mdeg ? 1.0 : -1.0;
                    dir[0] += sgn * (rij[7] - rij[5]);
                    dir[1] += sgn * (rij[2] - rij[6]);
                    dir[2] += sgn * (rij[3] - rij[1]);
                    pairs++;
                    continue;
                }
                double m[9];
                for (int k = 0; k < 9; k++)
                    m[k] = (k % 4 == 0 ? 1.0 : 0.0) - rij[k];
                for (int x = 0; x < 3; x++) {
                    for (int y = 0; y < 3; y++)
                        for (int k = 0; k < 3; k++)
                            ata[3 * x + y] += m[3 * k + x] * m[3 * k + y];
                    for (int k = 0; k < 3; k++)
                        atb[x] += m[3 * k + x] * tij[k];
                }
            }
        }
        if (pass == 0) {
            if (pairs == 0) {
                say(s, "turntable: no placement was seen at two table angles: the axis stays as "
                       "the starting file has it\n");
                return 0;
            }
            vec3 a = v3_norm(v3(dir[0], dir[1], dir[2]));
            dir[0] = a.x, dir[1] = a.y, dir[2] = a.z;
        }
    }
    /* (I - R) has the axis as its null space: pin the point's component along it to 0. */
    for (int x = 0; x < 3; x++)
        for (int y = 0; y < 3; y++)
            ata[3 * x + y] += dir[x] * dir[y];
    double c[3], pinned[9];
    memcpy(pinned, ata, sizeof(pinned)); /* calib_solve_n consumes it */
    if (!calib_solve_n(ata, atb, c, 3)) {
        say(s, "refused: the axis cannot be located (the table turned too little?)\n");
        return -EINVAL;
    }
    const vec3 a = v3(dir[0], dir[1], dir[2]);
    axis_sigma(s, r, a, c, pinned);
    double wmm, hmm, along = 0.0, along_sq = 0.0;
    int n = 0;
    calcv_board_size_mm(&s->board, &wmm, &hmm);
    for (uint32_t i = 0; i < s->view_count; i++) {
        const struct board_view *bv = &s->views[i];
        if (!bv->found)
            continue;
        /* bottom-edge centre of the sheet, and the face's outward normal (-z of the sheet) */
        vec3 m = v3_add(m3_mul(r[i], v3(0.5 * wmm, hmm, 0.0)), v3_from(bv->tvec));
        vec3 nrm = v3(-r[i][2], -r[i][5], -r[i][8]);
        vec3 base = v3_sub(m, v3_scale(nrm, s->cfg->calibrate.board_thickness_mm));
        double h = v3_dot(v3_sub(base, v3(c[0], c[1], c[2])), a);
        along += h;
        along_sq += h * h;
        n++;
    }
    along /= n;
    /* the table's height: the mean of n board edges, each one's scatter about it */
    s->axis_along_sigma_mm = n > 1 ? sqrt(fmax(0.0, along_sq / n - along * along) / (n - 1)) : 0.0;
    vec3 point = v3_add(v3(c[0], c[1], c[2]), v3_scale(a, along));
    if (a.y > 0.0)
        say(s, "warning: the axis points down in the image: the table turns clockwise seen "
               "from above for rising angles, which the scanner does not expect\n");
    memcpy(s->out.axis_dir, dir, sizeof(dir));
    s->out.axis_point_mm[0] = point.x;
    s->out.axis_point_mm[1] = point.y;
    s->out.axis_point_mm[2] = point.z;
    /* how well one axis explains every pair: the turn of each pair against the table's */
    double worst_deg = 0.0;
    for (uint32_t i = 0; i < s->view_count; i++)
        for (uint32_t j = i + 1; j < s->view_count; j++) {
            const struct board_view *p = &s->views[i], *q = &s->views[j];
            if (!p->found || !q->found || !p->ti.has_angle || !q->ti.has_angle ||
                p->ti.placement != q->ti.placement)
                continue;
            double tr = 0;
            for (int x = 0; x < 3; x++)
                for (int k = 0; k < 3; k++)
                    tr += r[j][3 * x + k] * r[i][3 * x + k];
            double turn = acos(fmin(1.0, fmax(-1.0, 0.5 * (tr - 1.0)))) * 180.0 / M_PI;
            double table = fabs((double)(q->ti.angle_mdeg - p->ti.angle_mdeg)) / 1000.0;
            worst_deg = fmax(worst_deg, fabs(turn - table));
        }
    say(s,
        "turntable: axis from %d pairs of captures; the boards turned by the table's angles "
        "within %.3f deg; the table's surface from %d board edges\n",
        pairs, worst_deg, n);
    if (s->axis_dir_sigma_deg > 0.0)
        say(s,
            "turntable: 1 sigma: direction %.2g deg, point %.2g mm across the axis, %.2g mm "
            "along it (the table's surface)\n",
            s->axis_dir_sigma_deg, s->axis_across_sigma_mm, s->axis_along_sigma_mm);
    return 0;
}

/* ---- lights: the matte white sphere's shading ---- */

struct shade_sample {
    float p[3], n[3];             /* surface point and normal (camera frame) */
    float signal[HAL_MAX_LIGHTS]; /* each light's frame less the dark frame, grey levels */
};

/* I = k max(0, n.(L - p)) / |L - p|^3: Lambert's cosine and the inverse-square law, as the
 * colour methods assume (docs/colour.md). */
static double shade(vec3 l, vec3 p, vec3 n)
{
    vec3 d = v3_sub(l, p);
    double len = v3_len(d), c = v3_dot(n, d);
    return c > 0.0 ? c / (len * len * len) : 0.0;
}

/* Light @p li's position L and intensity k from every sample: Levenberg-Marquardt on the four
 * unknowns together (k and the distance are strongly coupled: alternating between them crawls
 * along that valley), analytic derivatives: f = k g, df/dk = g,
 * df/dL = k (n / |d|^3 - 3 (n.d) d / |d|^5) with d = L - p. From the starting file's position.
 * @retval RMS residual, grey levels @retval -1 no solution */
static double fit_light(const struct shade_sample *smp, size_t n, uint32_t li, vec3 *light,
                        double *k_out)
{
    double x[4] = {light->x, light->y, light->z, 0.0};
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++) { /* k for the starting position, in closed form */
        double g = shade(*light, v3(smp[i].p[0], smp[i].p[1], smp[i].p[2]),
                         v3(smp[i].n[0], smp[i].n[1], smp[i].n[2]));
        num += g * smp[i].signal[li];
        den += g * g;
    }
    if (den <= 0.0)
        return -1.0;
    x[3] = num / den;
    double lambda = 1e-3, cost = -1.0;
    for (int it = 0; it < 200; it++) {
        double a[16] = {0}, b[4] = {0}, c = 0.0;
        vec3 l = v3(x[0], x[1], x[2]);
        for (size_t i = 0; i < n; i++) {
            vec3 p = v3(smp[i].p[0], smp[i].p[1], smp[i].p[2]);
            vec3 nn = v3(smp[i].n[0], smp[i].n[1], smp[i].n[2]);
            vec3 d = v3_sub(l, p);
            double len = v3_len(d), nd = v3_dot(nn, d), g = nd > 0.0 ? nd / (len * len * len) : 0.0;
            double res = smp[i].signal[li] - x[3] * g, jv[4] = {0, 0, 0, g};
            if (nd > 0.0) {
                double l3 = len * len * len, l5 = l3 * len * len;
                jv[0] = x[3] * (nn.x / l3 - 3.0 * nd * d.x / l5);
                jv[1] = x[3] * (nn.y / l3 - 3.0 * nd * d.y / l5);
                jv[2] = x[3] * (nn.z / l3 - 3.0 * nd * d.z / l5);
            }
            for (int r = 0; r < 4; r++) {
                for (int q = 0; q < 4; q++)
                    a[4 * r + q] += jv[r] * jv[q];
                b[r] += jv[r] * res;
            }
            c += res * res;
        }
        cost = c;
        double step[4];
        int accepted = 0;
        for (int tries = 0; tries < 20 && !accepted; tries++) {
            double m[16], rhs[4];
            memcpy(m, a, sizeof(m));
            memcpy(rhs, b, sizeof(rhs));
            for (int r = 0; r < 4; r++)
                m[5 * r] *= 1.0 + lambda;
            if (!calib_solve_n(m, rhs, step, 4))
                break;
            double cand[4] = {x[0] + step[0], x[1] + step[1], x[2] + step[2], x[3] + step[3]};
            double cc = 0.0;
            vec3 lc = v3(cand[0], cand[1], cand[2]);
            for (size_t i = 0; i < n; i++) {
                double res = smp[i].signal[li] -
                             cand[3] * shade(lc, v3(smp[i].p[0], smp[i].p[1], smp[i].p[2]),
                                             v3(smp[i].n[0], smp[i].n[1], smp[i].n[2]));
                cc += res * res;
            }
            if (cc <= cost) {
                memcpy(x, cand, sizeof(x));
                lambda = fmax(lambda * 0.3, 1e-12);
                accepted = 1;
                if (cost - cc <= 1e-13 * cost)
                    it = 200; /* converged */
                cost = cc;
            } else {
                lambda *= 10.0;
            }
        }
        if (!accepted)
            break;
    }
    *light = v3(x[0], x[1], x[2]);
    *k_out = x[3];
    return sqrt(cost / n);
}

/* The samples of light @p li (every one not saturated, those in its shadow too: the model says 0
 * there; leaving out the samples at the noise would keep only the terminator's positive noise
 * and pull the light outwards) from each sphere capture but @p skip (@p seen: none), copied to
 * @p use with their signal as signal[0], as fit_light takes them. Capture k's samples are
 * starts[k] .. starts[k + 1]. @retval how many */
static size_t light_samples(const struct shade_sample *smp, const size_t *starts, uint32_t seen,
                            uint32_t skip, uint32_t li, struct shade_sample *use)
{
    size_t m = 0;
    for (uint32_t k = 0; k < seen; k++)
        for (size_t i = starts[k]; i < starts[k + 1] && k != skip; i++)
            if (smp[i].signal[li] > -1.0f) {
                use[m] = smp[i];
                use[m].signal[0] = smp[i].signal[li];
                m++;
            }
    return m;
}

/* The uncertainty of light @p li's position @p l: a jackknife over the sphere captures (each left
 * out in turn, the light fitted again from the rest; the variance (K - 1)/K times the sum of the
 * squared moves). The residuals of one capture are far from independent (its sphere's fitted
 * centre, the interreflections the model leaves out, move all of them together), so the
 * covariance of the 60 000 residuals would claim hundredths of a millimetre where the lights are
 * 0.1 - 1 mm off; what changes with the sphere's place is what the captures can tell.
 * @p use room for the samples. @retval one standard deviation, mm (the length of the error)
 * @retval 0 fewer than 3 captures */
static double light_sigma(const struct shade_sample *smp, const size_t *starts, uint32_t seen,
                          uint32_t li, vec3 l, struct shade_sample *use)
{
    double sum = 0.0;
    if (seen < 3)
        return 0.0;
    for (uint32_t out = 0; out < seen; out++) {
        size_t m = light_samples(smp, starts, seen, out, li, use);
        vec3 lk = l;
        double kk;
        if (m <= 100 || fit_light(use, m, 0, &lk, &kk) < 0.0)
            return 0.0;
        sum += v3_dot(v3_sub(lk, l), v3_sub(lk, l));
    }
    return sqrt(sum * (seen - 1) / seen);
}

/* Each sphere capture triangulated with the new geometry, its centre fitted (the diameter is
 * known), and each light's frame sampled over the sphere. */
static int solve_lights(struct solve *s)
{
    const uint32_t lights = s->start.light_count;
    if (s->sphere_count == 0 || lights == 0 || s->camera_only) {
        say(s, "lights: no sphere captures: the lights stay as the starting file has them\n");
        return 0;
    }
    static uint8_t dark[HAL_MAX_PIXELS * 3], lit[HAL_MAX_PIXELS * 3];
    const size_t npix = (size_t)s->out.cam_width * s->out.cam_height;
    const size_t cap = npix / 4 * s->sphere_count + 1;
    struct shade_sample *smp = calloc(cap, sizeof(*smp));
    if (smp == NULL)
        return -ENOMEM;
    size_t n = 0, starts[CALIB_MAX_VIEWS + 1];
    uint32_t seen = 0; /* sphere captures with samples: starts[k] .. starts[k + 1] */
    const double radius = 0.5 * s->cfg->calibrate.sphere_diameter_mm;
    struct gray_layout layout;
    scan_layout(&s->params, &s->out, &layout);
    const uint32_t patterns = gray_layout_count(&layout);
    char err[SCAN_DIR_PATH_MAX + 256];
    int rc = 0;
    for (uint32_t k = 0; k < s->sphere_count && rc == 0; k++) {
        uint32_t v = s->sphere_views[k];
        const char *dir = s->sphere_dirs[k];
        struct scan_view view;
        struct scan_view_info info;
        if ((rc = feed_patterns(s, dir, v, &s->out)) != 0 ||
            (rc = scan_finish_view(scan_job_views(), NULL, &s->out, 0, &view, &info)) != 0)
            break;
        vec3 centre;
        uint32_t used;
        double r = radius;
        double rms =
            calib_fit_sphere(view.range.xyz_mm, view.maps.reason, npix, 0, &r, &centre, &used);
        if (rms < 0.0) {
            say(s, "view_%03u: sphere not seen (%u points): not used\n", (unsigned)v,
                (unsigned)used);
            continue;
        }
        /* a ball's surface within a tenth of its radius, or it is not the ball: a board
         * capture marked sphere fitted 60 mm RMS and put the lights 250 m away */
        if (rms > CALIB_SPHERE_MAX_RMS_SHARE * radius) {
            say(s,
                "view_%03u: rejected: the surface is no sphere of %.1f mm (fit RMS %.2f mm, "
                "more than %.0f%% of its radius): not used\n",
                (unsigned)v, 2.0 * radius, rms, 100.0 * CALIB_SPHERE_MAX_RMS_SHARE);
            continue;
        }
        say(s, "view_%03u: sphere centre (%.2f, %.2f, %.2f) mm from %u points, fit RMS %.3f mm\n",
            (unsigned)v, centre.x, centre.y, centre.z, (unsigned)used, rms);
        /* frames after the patterns: dark, all lights, then each light (colour.h) */
        rc = scan_dir_read_frame(dir, v, patterns + COLOUR_FRAME_DARK, dark, sizeof(dark),
                                 s->out.cam_width, s->out.cam_height, 3, err, sizeof(err));
        size_t first = n;
        for (uint32_t li = 0; li < lights && rc == 0; li++) {
            rc = scan_dir_read_frame(dir, v, patterns + COLOUR_FRAME_LIGHT0 + li, lit, sizeof(lit),
                                     s->out.cam_width, s->out.cam_height, 3, err, sizeof(err));
            if (rc != 0)
                break;
            n = first;
            for (size_t i = 0; i < npix && n < cap; i += 2) {
                if (view.maps.reason[i] != SCAN_VALID || (i / s->out.cam_width) % 2 != 0)
                    continue;
                vec3 p = v3(view.range.xyz_mm[3 * i], view.range.xyz_mm[3 * i + 1],
                            view.range.xyz_mm[3 * i + 2]);
                vec3 nn = v3_norm(v3_sub(p, centre));
                p = v3_add(centre, v3_scale(nn, radius)); /* on the fitted sphere */
                double sig = 0.0;
                int saturated = 0;
                for (int ch = 0; ch < 3; ch++) {
                    saturated |= lit[3 * i + (size_t)ch] >= s->params.saturation_dn;
                    sig += ((double)lit[3 * i + (size_t)ch] - dark[3 * i + (size_t)ch]) / 3.0;
                }
                struct shade_sample *q = &smp[n++];
                if (li == 0) {
                    q->p[0] = (float)p.x, q->p[1] = (float)p.y, q->p[2] = (float)p.z;
                    q->n[0] = (float)nn.x, q->n[1] = (float)nn.y, q->n[2] = (float)nn.z;
                }
                q->signal[li] = saturated ? -1.0f : (float)fmax(sig, -0.99);
            }
        }
        if (rc != 0)
            fprintf(stderr, "scanner: error: %s\n", err);
        else if (n > first)
            starts[seen++] = first;
    }
    starts[seen] = n;
    if (rc == 0 && n < 1000) {
        say(s, "refused: the sphere was seen in too few captures (%zu samples)\n", n);
        rc = -EINVAL;
    }
    /* Per light: its samples from every capture (light_samples). */
    double intensity[HAL_MAX_LIGHTS], mean = 0.0;
    struct shade_sample *use = rc == 0 ? calloc(n, sizeof(*use)) : NULL;
    if (rc == 0 && use == NULL)
        rc = -ENOMEM;
    for (uint32_t li = 0; li < lights && rc == 0; li++) {
        size_t m = light_samples(smp, starts, seen, seen, li, use);
        vec3 l = v3_from(s->out.light_pos_mm[li]);
        double k = 0.0, res = m > 100 ? fit_light(use, m, 0, &l, &k) : -1.0;
        if (res < 0.0) {
            say(s, "refused: light %u lights too little of the sphere (%zu samples)\n",
                (unsigned)li, m);
            rc = -EINVAL;
            break;
        }
        double from_axis = v3_len(v3_sub(l, v3_from(s->out.axis_point_mm)));
        if (from_axis > CALIB_LIGHT_MAX_MM) {
            say(s,
                "refused: light %u comes out %.1f m from the table, farther than any rig's "
                "%.0f m (does the sphere show its light?)\n",
                (unsigned)li, from_axis / 1000.0, CALIB_LIGHT_MAX_MM / 1000.0);
            rc = -EINVAL;
            break;
        }
        s->out.light_pos_mm[li][0] = l.x;
        s->out.light_pos_mm[li][1] = l.y;
        s->out.light_pos_mm[li][2] = l.z;
        s->light_sigma_mm[li] = light_sigma(smp, starts, seen, li, l, use);
        intensity[li] = k;
        mean += k / lights;
        say(s,
            "light %u: (%.2f, %.2f, %.2f) mm (1 sigma %.2g mm) from %zu samples, shading RMS "
            "%.2f grey levels, intensity %.4g (grey levels at 1 m, head-on)\n",
            (unsigned)li, l.x, l.y, l.z, s->light_sigma_mm[li], m, res, k * 1e-6);
    }
    for (uint32_t li = 0; li < lights && rc == 0; li++) {
        s->out.light_gain[li] = intensity[li] / mean;
        say(s, "light %u: gain %.4f (its intensity over the lights' mean)\n", (unsigned)li,
            s->out.light_gain[li]);
    }
    free(use);
    free(smp);
    return rc;
}

/* ---- the file ---- */

/* An existing file is kept beside the new one, named by when it was replaced. */
static int keep_old(const char *path, char *kept, size_t len)
{
    struct stat sb;
    kept[0] = '\0';
    if (stat(path, &sb) != 0)
        return 0;
    char stamp[32];
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(stamp, sizeof(stamp), "%Y%m%dT%H%M%SZ", &tm);
    snprintf(kept, len, "%s.%s", path, stamp);
    if (rename(path, kept) != 0) {
        int e = errno;
        fprintf(stderr, "scanner: error: cannot keep the old %s as %s: %s\n", path, kept,
                strerror(e));
        return -e;
    }
    return 0;
}

static int write_outputs(struct solve *s, const struct hal_storage *st, const char *out_path)
{
    char comment[3072], kept[HAL_MAX_PATH + 40], report_path[HAL_MAX_PATH + 16];
    /* the quality line is read back by calib_read_quality (verify, measure-calib), the weak
     * line by calib_read_weak (check-config) */
    int n = snprintf(comment, sizeof(comment),
                     "; written by scanner calibrate from %s%s%s\n"
                     "; quality: camera_rms_px = %.4f, projector_rms_px = %.4f, boards = %u\n",
                     s->dir, s->dir_count > 1 ? " and " : "", s->dir_count > 1 ? s->dirs[1] : "",
                     s->cam_rms, s->proj_rms, (unsigned)s->view_count);
    const double *c = s->sigma.cam, *p = s->sigma.proj;
    if (s->have_sigma && n > 0 && (size_t)n < sizeof(comment)) /* lines under 198 characters */
        n += snprintf(comment + n, sizeof(comment) - (size_t)n,
                      "; uncertainty (one standard deviation):\n"
                      ";   camera fx %.3g, fy %.3g, cx %.3g, cy %.3g px\n"
                      ";   camera distortion %.2g, %.2g, %.2g, %.2g, %.2g\n",
                      c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8]);
    if (s->have_sigma && !s->camera_only && n > 0 && (size_t)n < sizeof(comment))
        n += snprintf(
            comment + n, sizeof(comment) - (size_t)n,
            ";   projector fx %.3g, fy %.3g, cx %.3g, cy %.3g px\n"
            ";   projector distortion %.2g, %.2g, %.2g, %.2g, %.2g\n"
            ";   projector rotation %.2g, %.2g, %.2g deg, translation %.3g, %.3g, %.3g mm\n",
            p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], s->sigma.rot_deg[0],
            s->sigma.rot_deg[1], s->sigma.rot_deg[2], s->sigma.trans_mm[0], s->sigma.trans_mm[1],
            s->sigma.trans_mm[2]);
    if (s->axis_dir_sigma_deg > 0.0 && n > 0 && (size_t)n < sizeof(comment))
        n += snprintf(comment + n, sizeof(comment) - (size_t)n,
                      ";   axis direction %.2g deg, point %.2g mm across, %.2g mm along\n",
                      s->axis_dir_sigma_deg, s->axis_across_sigma_mm, s->axis_along_sigma_mm);
    for (uint32_t li = 0; li < s->out.light_count && s->light_sigma_mm[li] > 0.0; li++)
        if (n > 0 && (size_t)n < sizeof(comment))
            n += snprintf(comment + n, sizeof(comment) - (size_t)n, ";   light %u %.2g mm\n",
                          (unsigned)li, s->light_sigma_mm[li]);
    if (s->depth_worst_mm > 0.0 && n > 0 && (size_t)n < sizeof(comment))
        n += snprintf(comment + n, sizeof(comment) - (size_t)n,
                      "; predicted depth error %.3g mm (centre) - %.3g mm (edge); a 100 mm length "
                      "+-%.3g mm\n",
                      s->depth_centre_mm, s->depth_worst_mm, s->length_100_mm);
    if (s->weak[0] && n > 0 && (size_t)n < sizeof(comment))
        n += snprintf(comment + n, sizeof(comment) - (size_t)n, "; weak: %s\n; to fix: %s\n",
                      s->weak, s->advice);
    if (n > 0 && (size_t)n < sizeof(comment))
        snprintf(comment + n, sizeof(comment) - (size_t)n,
                 "; camera frame: x right, y down, z forward; millimetres\n");
    /* Written beside it first, and what calib_load accepts is the test of what was written:
     * only a file that loads replaces the one in use (which is then kept beside it). */
    char fresh[HAL_MAX_PATH + 16];
    calib_path_beside(out_path, ".new.ini", fresh, sizeof(fresh));
    int rc = calib_save(st, fresh, &s->out, comment);
    if (rc != 0) {
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", fresh, strerror(-rc));
        return rc;
    }
    struct scan_calib back;
    char err[512];
    if ((rc = calib_load(&back, fresh, s->out.light_count, err, sizeof(err))) != 0) {
        fprintf(stderr,
                "scanner: error: the calibration computed does not load: %s; %s is "
                "unchanged\n",
                err, out_path);
        unlink(fresh);
        return rc;
    }
    rc = keep_old(out_path, kept, sizeof(kept));
    if (rc == 0 && rename(fresh, out_path) != 0) {
        rc = -errno;
        fprintf(stderr, "scanner: error: cannot put %s in place of %s: %s\n", fresh, out_path,
                strerror(-rc));
    }
    if (rc != 0)
        return rc;
    calib_path_beside(out_path, ".report.txt", report_path, sizeof(report_path));
    rc = hal_storage_write_file(st, report_path, s->report, s->report_len);
    if (rc != 0)
        fprintf(stderr, "scanner: error: cannot write %s: %s\n", report_path, strerror(-rc));
    fprintf(s->json ? stderr : stdout, "calibration written: %s (report: %s)%s%s\n", out_path,
            report_path, kept[0] ? "; the previous file is kept as " : "", kept);
    return rc;
}

/* Folder @p added holds captures of the same rig as the first: the same folder refused (its
 * captures would count twice), and its captures' image sizes those of the first folder's.
 * @retval 0 @retval -EINVAL (said) */
static int check_added(struct solve *s, const char *added)
{
    struct stat a, b;
    struct scan_calib c;
    char path[SCAN_DIR_PATH_MAX], err[512];
    if (stat(s->dir, &a) != 0 || stat(added, &b) != 0 || !S_ISDIR(b.st_mode)) {
        say(s, "refused: --add %s: not a folder of captures\n", added);
        return -EINVAL;
    }
    if (a.st_dev == b.st_dev && a.st_ino == b.st_ino) {
        say(s, "refused: --add %s is the folder of --from itself\n", added);
        return -EINVAL;
    }
    scan_dir_path(path, sizeof(path), added, -1, SCAN_FILE_CALIBRATION);
    int rc = calib_load(&c, path, s->cfg->light_count, err, sizeof(err));
    if (rc == -ENOENT)
        return 0; /* captures made elsewhere: sizes checked frame by frame as they are read */
    if (rc != 0) {
        say(s, "refused: --add %s: %s\n", added, err);
        return -EINVAL;
    }
    if (c.cam_width != s->start.cam_width || c.cam_height != s->start.cam_height ||
        c.proj_width != s->start.proj_width || c.proj_height != s->start.proj_height) {
        say(s,
            "refused: --add %s: its captures are %ux%u (projector %ux%u), those of %s %ux%u "
            "(projector %ux%u): not the same rig\n",
            added, (unsigned)c.cam_width, (unsigned)c.cam_height, (unsigned)c.proj_width,
            (unsigned)c.proj_height, s->dir, (unsigned)s->start.cam_width,
            (unsigned)s->start.cam_height, (unsigned)s->start.proj_width,
            (unsigned)s->start.proj_height);
        return -EINVAL;
    }
    return 0;
}

/* --json: the result as one JSON object on stdout (calib_json.c). */
static void say_json(const struct solve *s, const char *out_path, int written)
{
    char report_path[HAL_MAX_PATH + 16];
    calib_path_beside(out_path, ".report.txt", report_path, sizeof(report_path));
    static struct calib_result r;
    r = (struct calib_result){
        .file = written ? out_path : NULL,
        .report = report_path,
        .refusal = s->refusal[0] ? s->refusal : "see the messages on stderr",
        .calib = &s->out,
        .camera_only = s->camera_only,
        .have_sigma = s->have_sigma,
        .sigma = &s->sigma,
        .axis_dir_sigma_deg = s->axis_dir_sigma_deg,
        .axis_across_sigma_mm = s->axis_across_sigma_mm,
        .axis_along_sigma_mm = s->axis_along_sigma_mm,
        .light_sigma_mm = s->light_sigma_mm,
        .camera_rms_px = s->cam_rms,
        .projector_rms_px = s->proj_rms,
        .boards = s->view_count,
        .depth_centre_mm = s->depth_centre_mm,
        .depth_edge_mm = s->depth_worst_mm,
        .length_100_mm = s->length_100_mm,
        .weak = s->weak,
        .advice = s->advice,
        .add_placements = s->add_placements,
    };
    for (uint32_t i = 0; i < s->view_count && r.residual_views < CALIB_MAX_VIEWS; i++) {
        const struct board_view *bv = &s->views[i];
        if (!bv->found)
            continue;
        r.residual_view[r.residual_views] = bv->view;
        r.residual_camera_px[r.residual_views] =
            bv->has_proj && bv->joint_cam_rms >= 0.0 ? bv->joint_cam_rms : bv->rms;
        r.residual_projector_px[r.residual_views++] = bv->has_proj ? bv->joint_proj_rms : -1.0;
    }
    calib_json_write(stdout, &r);
}

int calibrate_solve(const struct hal_storage *st, const struct app_config *cfg, const char *dir,
                    const char *added, const char *out_path, int json)
{
    struct solve s;
    memset(&s, 0, sizeof(s));
    s.cfg = cfg;
    s.json = json;
    s.dir = s.dirs[s.dir_count++] = dir;
    if (added != NULL)
        s.dirs[s.dir_count++] = added;
    char path[SCAN_DIR_PATH_MAX], err[512];
    scan_dir_path(path, sizeof(path), dir, -1, SCAN_FILE_CALIBRATION);
    int rc = calib_load(&s.start, path, cfg->light_count, err, sizeof(err));
    if (rc == -ENOENT) { /* captures made elsewhere: the config's calibration, or a guess */
        rc = calib_load(&s.start, cfg->calibration_file, cfg->light_count, err, sizeof(err));
        if (rc == -ENOENT)
            calibrate_guess(cfg, &s.start);
        s.start_guessed = rc == -ENOENT;
        if (rc == -ENOENT || rc == 0)
            rc = 0;
        else
            fprintf(stderr, "scanner: error: %s\n", err);
        if (rc != 0)
            return rc;
    } else if (rc != 0) {
        fprintf(stderr, "scanner: error: %s\n", err);
        return rc;
    }
    s.out = s.start;
    calib_capture_params(cfg, &s.params);
    s.params.colour.method = COLOUR_NONE; /* the light frames are read here, not compensated */
    calib_board_from_settings(&cfg->calibrate, &s.board);
    s.views = calloc(CALIB_MAX_VIEWS, sizeof(*s.views));
    if (s.views == NULL)
        return -ENOMEM;
    say(&s, "calibration from %s%s%s (board: %s, %ux%u squares of %.2f mm)\n", dir,
        added != NULL ? " and " : "", added != NULL ? added : "", cfg->calibrate.board,
        (unsigned)cfg->calibrate.squares_x, (unsigned)cfg->calibrate.squares_y,
        cfg->calibrate.square_mm);
    rc = added != NULL ? check_added(&s, added) : 0;
    if (rc == 0)
        rc = load_views(&s);
    if (rc == 0 && s.view_count == 0 && s.sphere_count == 0) {
        say(&s, "refused: %s holds no captures (view_NNN/frame_00.png)\n", dir);
        rc = -EINVAL;
    }
    if (rc == 0)
        rc = solve_camera(&s);
    if (rc == 0)
        rc = solve_projector(&s);
    if (rc == 0 && !s.camera_only)
        rc = solve_axis(&s);
    if (rc == 0)
        rc = solve_lights(&s);
    if (rc == 0)
        predict_depth_error(&s);
    if (rc == 0) /* after the prediction: a depth error too large makes it weak too */
        judge_uncertainty(&s);
    if (!json) /* with --json the report is in its file only */
        fputs(s.report != NULL ? s.report : "", stdout);
    if (rc == 0)
        rc = write_outputs(&s, st, out_path);
    if (json)
        say_json(&s, out_path, rc == 0);
    if (rc == -EINVAL)
        fprintf(stderr, "scanner: error: calibration refused: %s; %s is unchanged\n",
                s.refusal[0] ? s.refusal : "see above", out_path);
    free(s.report);
    free(s.draws);
    free(s.views);
    return rc;
}
