/* calibration.ini, the rig's calibration file (docs/config.md's second table): its one key
 * table, its reader (every value checked against the image and a real lens) and its writer. */
#define _POSIX_C_SOURCE 200809L
#include "calib_file.h"

#include "file_posix.h"
#include "ini_schema.h"
#include "vec3.h"

#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#define K(member) offsetof(struct scan_calib, member)
#define CF(sec, key, member, lo, hi, doc)                                                          \
    {                                                                                              \
        sec, key, INI_F64, K(member), 0, lo, hi, 0, NULL, NULL, doc, NULL, NULL                    \
    }
#define CU(sec, key, member, hi, limit, doc)                                                       \
    {                                                                                              \
        sec, key, INI_U32, K(member), 0, 1, hi, limit, NULL, NULL, doc, NULL, NULL                 \
    }
#define CV(sec, key, member, n, lo, hi, def, doc)                                                  \
    {                                                                                              \
        sec, key, INI_VEC, K(member), n, lo, hi, 0, def, NULL, doc, NULL, NULL                     \
    }
#define LIGHT(i)                                                                                   \
    CV("lights", "light_" #i "_mm", light_pos_mm[i], 3, -1e5, 1e5, "0, 0, 0",                      \
       "position of light " #i " (camera frame)"),                                                 \
    {                                                                                              \
        "lights", "light_" #i "_gain", INI_F64, K(light_gain[i]), 0, 0.01, 100, 0, "1", NULL,      \
            "intensity of light " #i                                                               \
            " relative to the lights' mean (scanner calibrate measures it)",                       \
            "%.6f", NULL                                                                           \
    }

static const struct ini_key calib_keys[] = {
    CF("camera", "fx_px", cam_fx_px, 1, 1e6, "focal length x"),
    CF("camera", "fy_px", cam_fy_px, 1, 1e6, "focal length y"),
    CF("camera", "cx_px", cam_cx_px, -1e5, 1e5, "principal point x"),
    CF("camera", "cy_px", cam_cy_px, -1e5, 1e5, "principal point y"),
    CU("camera", "width", cam_width, HAL_MAX_WIDTH, HAL_FRAME_LIMIT_ADVICE,
       "image width the intrinsics belong to"),
    CU("camera", "height", cam_height, HAL_MAX_HEIGHT, HAL_FRAME_LIMIT_ADVICE, "image height"),
    CV("camera", "distortion", cam_dist, 5, -100, 100, "0, 0, 0, 0, 0",
       "lens distortion k1, k2, p1, p2, k3 (Brown-Conrady, OpenCV's order; 0: a pinhole)"),
    CF("projector", "fx_px", proj_fx_px, 1, 1e6, "focal length x"),
    CF("projector", "fy_px", proj_fy_px, 1, 1e6, "focal length y"),
    CF("projector", "cx_px", proj_cx_px, -1e5, 1e5, "principal point x"),
    CF("projector", "cy_px", proj_cy_px, -1e5, 1e5, "principal point y"),
    CU("projector", "width", proj_width, HAL_MAX_PROJECTOR_WIDTH, "", "projector columns"),
    CU("projector", "height", proj_height, HAL_MAX_PROJECTOR_HEIGHT, "", "projector rows"),
    CV("projector", "distortion", proj_dist, 5, -100, 100, "0, 0, 0, 0, 0",
       "lens distortion k1, k2, p1, p2, k3, as for the camera"),
    CV("projector", "rotation", proj_rot, 9, -1, 1, NULL,
       "rotation camera -> projector, row-major 3x3 (p_proj = R p_cam + t)"),
    CV("projector", "translation_mm", proj_trans_mm, 3, -1e5, 1e5, NULL,
       "translation camera -> projector"),
    CV("turntable", "axis_point_mm", axis_point_mm, 3, -1e5, 1e5, NULL,
       "a point of the turntable axis on the table surface (camera frame)"),
    CV("turntable", "axis_dir", axis_dir, 3, -1, 1, NULL, "unit direction of the axis, upwards"),
    LIGHT(0),
    LIGHT(1),
    LIGHT(2),
    LIGHT(3),
    LIGHT(4),
    LIGHT(5),
    LIGHT(6),
    LIGHT(7),
};

_Static_assert(HAL_MAX_LIGHTS == 8, "calib_keys lists light_0 .. light_7");

/* A lens a camera or projector can have, for its image of @p w x @p h: the principal point on
 * the image (a projector's lens shift puts it up to an image height or width outside), a field
 * of view between about 0.6 and 170 degrees, square-ish pixels, and a distortion that keeps the
 * image in one piece: the radial mapping r -> r (1 + k1 r^2 + k2 r^4 + k3 r^6) still rising at
 * the farthest corner and moving no point by half its distance from the centre (OpenCV's
 * Brown-Conrady model, docs/equations.md). A file that breaks one names the key. */
static int check_lens(const char *path, const char *sec, double fx, double fy, double cx, double cy,
                      uint32_t w, uint32_t h, const double dist[5], int projector, char *err,
                      size_t err_len)
{
    double margin = projector ? 1.0 : 0.0; /* in image sizes */
    if (cx < -margin * w || cx > (1.0 + margin) * w || cy < -margin * h ||
        cy > (1.0 + margin) * h) {
        snprintf(err, err_len, "%s: [%s] %s: %.1f is off the %ux%u image%s", path, sec,
                 cx < -margin * w || cx > (1.0 + margin) * w ? "cx_px" : "cy_px",
                 cx < -margin * w || cx > (1.0 + margin) * w ? cx : cy, (unsigned)w, (unsigned)h,
                 projector ? " by more than its size" : "");
        return -EINVAL;
    }
    if (fx < 0.05 * w || fx > 100.0 * w || fy / fx < 0.5 || fy / fx > 2.0) {
        snprintf(err, err_len,
                 "%s: [%s] fx_px = %.1f, fy_px = %.1f: no lens of a %u pixel wide "
                 "image (the focal lengths are %.2f..%.0f px, within 2x of each other)",
                 path, sec, fx, fy, (unsigned)w, 0.05 * w, 100.0 * w);
        return -EINVAL;
    }
    double ux = fmax(cx, w - cx) / fx, uy = fmax(cy, h - cy) / fy;
    double r_max = sqrt(ux * ux + uy * uy);
    double k1 = dist[0], k2 = dist[1], p1 = dist[2], p2 = dist[3], k3 = dist[4];
    for (int i = 1; i <= 100; i++) {
        double r = r_max * i / 100.0, r2 = r * r;
        double slope = 1.0 + 3.0 * k1 * r2 + 5.0 * k2 * r2 * r2 + 7.0 * k3 * r2 * r2 * r2;
        double factor = 1.0 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
        if (slope <= 0.0 || fabs(factor - 1.0) > 0.5) {
            snprintf(err, err_len,
                     "%s: [%s] distortion: k1 %g, k2 %g, k3 %g %s from %d%% of "
                     "the way to the image's corner on: no lens does that (a calibration from "
                     "too few or too alike views?)",
                     path, sec, k1, k2, k3,
                     slope <= 0.0 ? "fold the image over itself"
                                  : "move points by half their distance from the centre or more",
                     i);
            return -EINVAL;
        }
    }
    if (fabs(p1) > 0.1 || fabs(p2) > 0.1) {
        snprintf(err, err_len,
                 "%s: [%s] distortion: tangential p1 %g, p2 %g: beyond +-0.1, a "
                 "lens mounted far off its sensor",
                 path, sec, p1, p2);
        return -EINVAL;
    }
    return 0;
}

int calib_load(struct scan_calib *calib, const char *path, uint32_t light_count, char *err,
               size_t err_len)
{
    memset(calib, 0, sizeof(*calib));
    int rc = ini_schema_load(calib_keys, sizeof(calib_keys) / sizeof(calib_keys[0]), calib, path,
                             err, err_len);
    if (rc != 0)
        return rc;
    vec3 axis = v3_from(calib->axis_dir);
    if (fabs(v3_len(axis) - 1.0) > 1e-3) {
        snprintf(err, err_len, "%s: [turntable] axis_dir: not a unit vector (length %.4f)", path,
                 v3_len(axis));
        return -EINVAL;
    }
    /* R must be a rotation: R R^T = I within calibration-file rounding. */
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++) {
            double dot = 0.0;
            for (int k = 0; k < 3; k++)
                dot += calib->proj_rot[r * 3 + k] * calib->proj_rot[c * 3 + k];
            if (fabs(dot - (r == c ? 1.0 : 0.0)) > 1e-4) {
                snprintf(err, err_len, "%s: [projector] rotation: not a rotation matrix", path);
                return -EINVAL;
            }
        }
    }
    /* Triangulation needs the projector off the camera's centre: a baseline of a few mm or less
     * gives rays that meet nowhere useful (and 0 gives a scan of no points at all). */
    double baseline_mm = v3_len(v3_from(calib->proj_trans_mm));
    if (baseline_mm < 10.0) {
        snprintf(err, err_len,
                 "%s: [projector] translation_mm: the projector is %.1f mm from the camera; "
                 "triangulation needs a baseline (typically 100-300 mm)",
                 path, baseline_mm);
        return -EINVAL;
    }
    if ((rc = check_lens(path, "camera", calib->cam_fx_px, calib->cam_fy_px, calib->cam_cx_px,
                         calib->cam_cy_px, calib->cam_width, calib->cam_height, calib->cam_dist, 0,
                         err, err_len)) != 0 ||
        (rc = check_lens(path, "projector", calib->proj_fx_px, calib->proj_fy_px, calib->proj_cx_px,
                         calib->proj_cy_px, calib->proj_width, calib->proj_height, calib->proj_dist,
                         1, err, err_len)) != 0)
        return rc;
    calib->light_count = light_count;
    for (uint32_t i = 0; i < light_count; i++) {
        if (v3_len(v3_from(calib->light_pos_mm[i])) == 0.0) {
            snprintf(err, err_len, "%s: [lights] light_%u_mm: required, [lights] count is %u", path,
                     (unsigned)i, (unsigned)light_count);
            return -EINVAL;
        }
    }
    return 0;
}

void calib_read_quality(const char *path, double *camera_rms_px, double *projector_rms_px)
{
    char line[256];
    *camera_rms_px = *projector_rms_px = -1.0;
    FILE *f = file_open_regular(path, "r");
    while (f != NULL && fgets(line, sizeof(line), f) != NULL)
        if (sscanf(line, "; quality: camera_rms_px = %lf, projector_rms_px = %lf", camera_rms_px,
                   projector_rms_px) == 2)
            break;
    if (f != NULL)
        fclose(f);
}

int calib_read_weak(const char *path, char *why, size_t why_len)
{
    char line[1024];
    int weak = 0;
    FILE *f = file_open_regular(path, "r");
    while (f != NULL && !weak && fgets(line, sizeof(line), f) != NULL) {
        if (strncmp(line, "; weak: ", 8) != 0)
            continue;
        line[strcspn(line, "\n")] = '\0';
        snprintf(why, why_len, "%s", line + 8);
        weak = 1;
    }
    if (f != NULL)
        fclose(f);
    return weak;
}

/* The lights the calibration has (light_N_... keys of N < light_count) are written. */
static int skip_absent_light(const struct ini_key *k, const void *target)
{
    const struct scan_calib *c = target;
    unsigned i;
    return sscanf(k->name, "light_%u_", &i) == 1 && i >= c->light_count;
}

/* Numbers to 12 significant digits (1e-12: far below any calibration's uncertainty; the loader
 * refuses lines over 198 characters), the lights' gains to 6 decimals: calib_keys' formats. */
int calib_save(const struct hal_storage *st, const char *path, const struct scan_calib *c,
               const char *comment)
{
    char buf[16384];
    int n = ini_schema_write(calib_keys, sizeof(calib_keys) / sizeof(calib_keys[0]), c, comment,
                             skip_absent_light, "\n", buf, sizeof(buf));
    if (n < 0)
        return n == -ENOSPC ? -EFBIG : n;
    return hal_storage_write_file(st, path, buf, (size_t)n);
}

void calib_print_doc(FILE *out)
{
    ini_schema_print_doc(calib_keys, sizeof(calib_keys) / sizeof(calib_keys[0]), out);
}

void calib_path_beside(const char *cal_path, const char *suffix, char *buf, size_t len)
{
    size_t l = strlen(cal_path);
    if (l > 4 && strcmp(cal_path + l - 4, ".ini") == 0)
        l -= 4;
    snprintf(buf, len, "%.*s%s", (int)l, cal_path, suffix);
}
