/* build/measure-calib TRUE.ini NOMINAL.ini RECOVERED.ini [LIGHTS]: how far a calibration is from
 * the rig it describes (make calibrate-demo, make measure-calib): the table of every quantity,
 * true | nominal | recovered | the recovered file's error. */
#define _POSIX_C_SOURCE 200809L
#include "config.h"
#include "lens.h"

#include <stdio.h>
#include <stdlib.h>

/* Largest difference over the image between where two lenses put the same ray, px: the true
 * focal length and principal point for both, so that only the distortion is compared. */
static double distortion_error_px(double fx, double fy, double cx, double cy, uint32_t w,
                                  uint32_t h, const double *truth, const double *est)
{
    double worst = 0.0;
    for (uint32_t y = 0; y < h; y += 8) {
        for (uint32_t x = 0; x < w; x += 8) {
            double nx, ny, ax, ay, bx, by;
            if (lens_undistort(truth, (x - cx) / fx, (y - cy) / fy, &nx, &ny) != 0)
                continue;
            lens_distort(truth, nx, ny, &ax, &ay);
            lens_distort(est, nx, ny, &bx, &by);
            worst = fmax(worst, hypot(fx * (ax - bx), fy * (ay - by)));
        }
    }
    return worst;
}

static double rotation_deg(const double *a, const double *b)
{
    double tr = 0.0; /* trace of a b^T */
    for (int i = 0; i < 9; i++)
        tr += a[i] * b[i];
    return acos(fmin(1.0, fmax(-1.0, 0.5 * (tr - 1.0)))) * 180.0 / M_PI;
}

static void row(const char *name, const char *unit, double t, double n, double r, double err)
{
    printf("| %-34s | %12.4f | %12.4f | %12.4f | %10.4f %-3s |\n", name, t, n, r, err, unit);
}

static void row3(const char *name, const double *t, const double *n, const double *r,
                 const char *what)
{
    printf("| %-34s | %6.1f %6.1f %6.1f | %6.1f %6.1f %6.1f | %6.1f %6.1f %6.1f | %10.4f %-3s |\n",
           name, t[0], t[1], t[2], n[0], n[1], n[2], r[0], r[1], r[2],
           v3_len(v3_sub(v3_from(t), v3_from(r))), what);
}

/* distance of point p from the line through q along unit d */
static double off_line(vec3 p, vec3 q, vec3 d)
{
    vec3 v = v3_sub(p, q);
    return v3_len(v3_sub(v, v3_scale(d, v3_dot(v, d))));
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: measure-calib TRUE.ini NOMINAL.ini RECOVERED.ini [LIGHTS]\n");
        return 2;
    }
    uint32_t lights = argc > 4 ? (uint32_t)atoi(argv[4]) : 4;
    struct scan_calib t, n, r;
    char err[512];
    if (calib_load(&t, argv[1], lights, err, sizeof(err)) != 0 ||
        calib_load(&n, argv[2], lights, err, sizeof(err)) != 0 ||
        calib_load(&r, argv[3], lights, err, sizeof(err)) != 0) {
        fprintf(stderr, "measure-calib: %s\n", err);
        return 1;
    }
    double cam_rms, proj_rms; /* what scanner calibrate recorded in the file */
    calib_read_quality(argv[3], &cam_rms, &proj_rms);
    printf("| %-34s | %12s | %12s | %12s | %14s |\n", "parameter", "true", "nominal", "recovered",
           "error");
    printf("|%s|%s|%s|%s|%s|\n", "------------------------------------", "--------------",
           "--------------", "--------------", "----------------");
    row("camera reprojection RMS (px)", "px", 0.0, 0.0, cam_rms, cam_rms);
    row("projector reprojection RMS (px)", "px", 0.0, 0.0, proj_rms, proj_rms);
    row("camera fx (px)", "%", t.cam_fx_px, n.cam_fx_px, r.cam_fx_px,
        100.0 * (r.cam_fx_px - t.cam_fx_px) / t.cam_fx_px);
    row("camera fy (px)", "%", t.cam_fy_px, n.cam_fy_px, r.cam_fy_px,
        100.0 * (r.cam_fy_px - t.cam_fy_px) / t.cam_fy_px);
    row("camera cx (px)", "px", t.cam_cx_px, n.cam_cx_px, r.cam_cx_px, r.cam_cx_px - t.cam_cx_px);
    row("camera cy (px)", "px", t.cam_cy_px, n.cam_cy_px, r.cam_cy_px, r.cam_cy_px - t.cam_cy_px);
    row("camera k1", "", t.cam_dist[0], n.cam_dist[0], r.cam_dist[0],
        r.cam_dist[0] - t.cam_dist[0]);
    row("camera k2", "", t.cam_dist[1], n.cam_dist[1], r.cam_dist[1],
        r.cam_dist[1] - t.cam_dist[1]);
    double cam_dn = distortion_error_px(t.cam_fx_px, t.cam_fy_px, t.cam_cx_px, t.cam_cy_px,
                                        t.cam_width, t.cam_height, t.cam_dist, n.cam_dist);
    double cam_dr = distortion_error_px(t.cam_fx_px, t.cam_fy_px, t.cam_cx_px, t.cam_cy_px,
                                        t.cam_width, t.cam_height, t.cam_dist, r.cam_dist);
    row("camera distortion, max over image", "px", 0.0, cam_dn, cam_dr, cam_dr);
    row("projector fx (px)", "%", t.proj_fx_px, n.proj_fx_px, r.proj_fx_px,
        100.0 * (r.proj_fx_px - t.proj_fx_px) / t.proj_fx_px);
    row("projector fy (px)", "%", t.proj_fy_px, n.proj_fy_px, r.proj_fy_px,
        100.0 * (r.proj_fy_px - t.proj_fy_px) / t.proj_fy_px);
    row("projector cx (px)", "px", t.proj_cx_px, n.proj_cx_px, r.proj_cx_px,
        r.proj_cx_px - t.proj_cx_px);
    row("projector cy (px)", "px", t.proj_cy_px, n.proj_cy_px, r.proj_cy_px,
        r.proj_cy_px - t.proj_cy_px);
    row("projector k1", "", t.proj_dist[0], n.proj_dist[0], r.proj_dist[0],
        r.proj_dist[0] - t.proj_dist[0]);
    double proj_dn = distortion_error_px(t.proj_fx_px, t.proj_fy_px, t.proj_cx_px, t.proj_cy_px,
                                         t.proj_width, t.proj_height, t.proj_dist, n.proj_dist);
    double proj_dr = distortion_error_px(t.proj_fx_px, t.proj_fy_px, t.proj_cx_px, t.proj_cy_px,
                                         t.proj_width, t.proj_height, t.proj_dist, r.proj_dist);
    row("projector distortion, max over image", "px", 0.0, proj_dn, proj_dr, proj_dr);
    row3("projector translation (mm)", t.proj_trans_mm, n.proj_trans_mm, r.proj_trans_mm, "mm");
    row("projector rotation off the true (deg)", "deg", 0.0, rotation_deg(t.proj_rot, n.proj_rot),
        rotation_deg(t.proj_rot, r.proj_rot), rotation_deg(t.proj_rot, r.proj_rot));
    vec3 td = v3_from(t.axis_dir), tp = v3_from(t.axis_point_mm);
    double ang_n = acos(fmin(1.0, v3_dot(td, v3_norm(v3_from(n.axis_dir))))) * 180.0 / M_PI;
    double ang_r = acos(fmin(1.0, v3_dot(td, v3_norm(v3_from(r.axis_dir))))) * 180.0 / M_PI;
    row("axis direction off the true (deg)", "deg", 0.0, ang_n, ang_r, ang_r);
    double off_n = off_line(tp, v3_from(n.axis_point_mm), v3_norm(v3_from(n.axis_dir)));
    double off_r = off_line(tp, v3_from(r.axis_point_mm), v3_norm(v3_from(r.axis_dir)));
    row("axis: true point off the line (mm)", "mm", 0.0, off_n, off_r, off_r);
    double h_n = v3_dot(v3_sub(v3_from(n.axis_point_mm), tp), td);
    double h_r = v3_dot(v3_sub(v3_from(r.axis_point_mm), tp), td);
    row("table surface height (mm)", "mm", 0.0, h_n, h_r, h_r);
    for (uint32_t i = 0; i < lights; i++) {
        char name[40];
        snprintf(name, sizeof(name), "light %u (mm)", (unsigned)i);
        row3(name, t.light_pos_mm[i], n.light_pos_mm[i], r.light_pos_mm[i], "mm");
        snprintf(name, sizeof(name), "light %u gain (relative intensity)", (unsigned)i);
        row(name, "", t.light_gain[i], n.light_gain[i], r.light_gain[i],
            r.light_gain[i] - t.light_gain[i]);
    }
    return 0;
}
