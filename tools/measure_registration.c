/* build/measure-registration SCAN_DIR: each view's turntable angle as the controller reported
 * it, as registration left it (the pose it was fused with), and as the simulated table really
 * stood (truth_angle.ini), with the errors; the numbers issue 15 asks of registration. */
#define _POSIX_C_SOURCE 200809L
#include "config.h"
#include "frames.h"
#include "scan_dir.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* "key = a, b, c" from an INI file: the @p n numbers after "key =". @retval 0 found */
static int read_numbers(const char *path, const char *key, double *v, int n)
{
    char line[512];
    size_t kl = strlen(key);
    int found = -1;
    FILE *f = fopen(path, "r");
    while (f != NULL && found != 0 && fgets(line, sizeof(line), f) != NULL) {
        if (strncmp(line, key, kl) != 0 || strchr(line, '=') == NULL)
            continue;
        char *p = strchr(line, '=') + 1;
        int k = 0;
        for (; k < n; k++) {
            char *end;
            v[k] = strtod(p, &end);
            if (end == p)
                break;
            p = end + strspn(end, " ,");
        }
        found = k == n ? 0 : -1;
    }
    if (f != NULL)
        fclose(f);
    return found;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: measure-registration SCAN_DIR\n");
        return 2;
    }
    static struct app_config cfg;
    struct scan_calib calib;
    char path[SCAN_DIR_PATH_MAX], err[512];
    scan_dir_path(path, sizeof(path), argv[1], -1, "config.ini");
    int rc = config_load(&cfg, path, err, sizeof(err));
    scan_dir_path(path, sizeof(path), argv[1], -1, "calibration.ini");
    if (rc == 0)
        rc = calib_load(&calib, path, cfg.light_count, err, sizeof(err));
    if (rc != 0) {
        fprintf(stderr, "measure-registration: %s\n", err);
        return 1;
    }
    struct frame_xform table;
    frame_table_from_camera(&calib, &table);
    printf("| view | reported (deg) | registered (deg) | true (deg) | table's error (deg) | "
           "registered error (deg) | registered, relative to view 0 (deg) |\n"
           "|---|---|---|---|---|---|---|\n");
    double worst_table = 0.0, worst_reg = 0.0, worst_rel = 0.0, first_err = 0.0;
    uint32_t views = 0;
    for (uint32_t v = 0; v < cfg.views; v++) {
        static struct scan_dir_view meta;
        struct frame_xform pose;
        double truth;
        if (scan_dir_read_view(argv[1], v, &meta, err, sizeof(err)) != 0)
            continue;
        if (scan_dir_read_pose(argv[1], v, &pose) != 0)
            continue;
        const double *rot = pose.rot;
        scan_dir_path(path, sizeof(path), argv[1], (int)v, "truth_angle.ini");
        if (read_numbers(path, "angle_mdeg", &truth, 1) != 0)
            continue;
        /* pose = Rz(-angle) table: Rz(-angle) = pose.rot table.rot^T, angle from its first row */
        double m0 = 0.0, m1 = 0.0;
        for (int k = 0; k < 3; k++) {
            m0 += rot[k] * table.rot[k];
            m1 += rot[k] * table.rot[3 + k];
        }
        double reg = atan2(m1, m0) * 180.0 / M_PI, rep = meta.angle_mdeg / 1000.0;
        reg += reg < 0.0 ? 360.0 : 0.0;
        truth /= 1000.0;
        double e_table = remainder(rep - truth, 360.0), e_reg = remainder(reg - truth, 360.0);
        if (views == 0)
            first_err = e_reg; /* the model's frame is view 0's: the shape needs the rest right */
        double e_rel = e_reg - first_err;
        printf("| %u | %.3f | %.3f | %.3f | %+.3f | %+.3f | %+.3f |\n", (unsigned)v, rep, reg,
               truth, e_table, e_reg, e_rel);
        worst_table = fmax(worst_table, fabs(e_table));
        worst_reg = fmax(worst_reg, fabs(e_reg));
        worst_rel = fmax(worst_rel, fabs(e_rel));
        views++;
    }
    printf("views %u: worst angle error %.3f deg as reported, %.3f deg after registration "
           "(%.3f deg relative to view 0)\n",
           (unsigned)views, worst_table, worst_reg, worst_rel);
    return views > 0 ? 0 : 1;
}
