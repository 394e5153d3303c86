/* What the calibration's procedure (calibrate.c) and its computation (calib_solve.c) share, so
 * that neither calls into the other: the first guess of a new rig, the board and the capture's
 * settings from the config, the sphere fit, and the names beside the calibration file. */
#define _POSIX_C_SOURCE 200809L
#include "calib_priv.h"

#include "scan.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Solve the n x n system a x = b (row-major), Gauss-Jordan with partial pivoting; a and b are
 * destroyed. @retval 0 singular */
int calib_solve_n(double *a, double *b, double *x, int n)
{
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int k = c + 1; k < n; k++)
            if (fabs(a[k * n + c]) > fabs(a[p * n + c]))
                p = k;
        if (fabs(a[p * n + c]) < 1e-30)
            return 0;
        for (int k = 0; k < n; k++) {
            double t = a[c * n + k];
            a[c * n + k] = a[p * n + k];
            a[p * n + k] = t;
        }
        double t = b[c];
        b[c] = b[p];
        b[p] = t;
        for (int k = 0; k < n; k++) {
            if (k == c)
                continue;
            double f = a[k * n + c] / a[c * n + c];
            for (int j = c; j < n; j++)
                a[k * n + j] -= f * a[c * n + j];
            b[k] -= f * b[c];
        }
    }
    for (int k = 0; k < n; k++)
        x[k] = b[k] / a[k * n + k];
    return 1;
}

void calibrate_guess(const struct app_config *cfg, struct scan_calib *g)
{
    memset(g, 0, sizeof(*g));
    /* A 50-degree lens on each, the projector 200 mm to the camera's left and turned 20 degrees
     * towards it, the table 600 mm away: only sizes matter for capturing. */
    g->cam_width = cfg->camera.width;
    g->cam_height = cfg->camera.height;
    g->cam_fx_px = g->cam_fy_px = 1.07 * g->cam_width;
    g->cam_cx_px = 0.5 * (g->cam_width - 1.0);
    g->cam_cy_px = 0.5 * (g->cam_height - 1.0);
    g->proj_width = cfg->calibrate.projector_width;
    g->proj_height = cfg->calibrate.projector_height;
    g->proj_fx_px = g->proj_fy_px = 1.07 * g->proj_width;
    g->proj_cx_px = 0.5 * (g->proj_width - 1.0);
    g->proj_cy_px = 0.5 * (g->proj_height - 1.0);
    const double a = 20.0 * M_PI / 180.0;
    const double rot[9] = {cos(a), 0, sin(a), 0, 1, 0, -sin(a), 0, cos(a)};
    memcpy(g->proj_rot, rot, sizeof(rot));
    g->proj_trans_mm[0] = -200.0;
    g->axis_point_mm[1] = 75.0;
    g->axis_point_mm[2] = 600.0;
    g->axis_dir[1] = -1.0;
    g->light_count = cfg->light_count;
    for (uint32_t i = 0; i < cfg->light_count; i++) {
        g->light_pos_mm[i][0] = 100.0 * i - 150.0;
        g->light_pos_mm[i][1] = -200.0;
        g->light_pos_mm[i][2] = 300.0;
        g->light_gain[i] = 1.0;
    }
}

void calib_board_from_settings(const struct calib_settings *s, struct calcv_board *b)
{
    static const struct {
        const char *name;
        int id; /* cv::aruco::PREDEFINED_DICTIONARY_NAME */
    } dicts[] = {{"4x4_50", 0}, {"4x4_100", 1}, {"5x5_50", 4}, {"5x5_100", 5}, {"6x6_250", 10}};
    memset(b, 0, sizeof(*b));
    b->kind = strcmp(s->board, "chessboard") == 0 ? CALCV_CHESSBOARD : CALCV_CHARUCO;
    b->squares_x = (int)s->squares_x;
    b->squares_y = (int)s->squares_y;
    b->square_mm = s->square_mm;
    b->marker_mm = s->marker_mm;
    b->margin_mm = s->margin_mm;
    b->dictionary = -1;
    for (size_t i = 0; i < sizeof(dicts) / sizeof(dicts[0]); i++)
        if (strcmp(s->dictionary, dicts[i].name) == 0)
            b->dictionary = dicts[i].id;
}

/* The scan parameters of a calibration capture: columns and rows (the projector's coordinates
 * at the board's corners), and with lights, every light's own frame (the sphere's shading). */
void calib_capture_params(const struct app_config *cfg, struct scan_params *p)
{
    *p = cfg->scan;
    p->decode_rows = 1;
    p->refine = 1;
    p->colour.method = cfg->light_count > 0 ? COLOUR_MULTI : COLOUR_NONE;
    p->colour.all_lights_exposure_us = 0;
    p->colour.light_exposure_us = 0;
}

double calib_fit_sphere(const float *xyz, const uint8_t *reason, size_t n, int fit_radius,
                        double *radius, vec3 *centre, uint32_t *used)
{
    vec3 c = v3(0, 0, 0);
    uint32_t count = 0;
    for (size_t i = 0; i < n; i++)
        if (reason[i] == SCAN_VALID) {
            c = v3_add(c, v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
            count++;
        }
    *used = count;
    if (count < 100)
        return -1.0;
    double r = *radius;
    c = v3_scale(c, 1.0 / count);
    c = v3_add(c, v3_scale(v3_norm(c), r)); /* the visible cap's centroid, pushed back */
    double rms = 0.0;
    const int np = fit_radius ? 4 : 3;
    for (int it = 0; it < 50; it++) {
        double a[16] = {0}, b[4] = {0}, sum = 0.0;
        for (size_t i = 0; i < n; i++) {
            if (reason[i] != SCAN_VALID)
                continue;
            vec3 d = v3_sub(v3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), c);
            double len = v3_len(d), res = len - r;
            double g[4] = {-d.x / len, -d.y / len, -d.z / len, -1.0}; /* d(res)/d(c, r) */
            for (int x = 0; x < np; x++) {
                for (int y = 0; y < np; y++)
                    a[np * x + y] += g[x] * g[y];
                b[x] -= g[x] * res;
            }
            sum += res * res;
        }
        rms = sqrt(sum / count);
        double step[4] = {0, 0, 0, 0};
        if (!calib_solve_n(a, b, step, np))
            return -1.0;
        c = v3_add(c, v3(step[0], step[1], step[2]));
        r += step[3];
        if (fabs(step[0]) + fabs(step[1]) + fabs(step[2]) + fabs(step[3]) < 1e-8)
            break;
    }
    *centre = c;
    *radius = r;
    return rms;
}
