/* Fusion side by side with Open3D (issue 17): the views of a finished scan, each from its
 * range.bin at the pose its registration.ini gives, fused into the scanner's volume and meshed
 * (timed, best of three), and written out as depth maps, colours and poses for
 * bench/fusion_open3d.py, which fuses the same depth with Open3D's ScalableTSDFVolume at the
 * same voxel and truncation. Only what lies inside the scanner's volume goes to Open3D, so that
 * both fuse the same points. make bench.
 *   bench-fusion SCAN_DIR OUT_DIR   (OUT_DIR/mesh.ply, OUT_DIR/view_K.depth, .rgb, poses.txt) */
#define _POSIX_C_SOURCE 200809L
#include "config.h"
#include "fusion.h"
#include "scan.h"
#include "scan_dir.h"
#include "storage_posix.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static struct scan_ctx view_buffers; /* each view read back from its range.bin */
static struct fusion_volume vol;     /* the views fused */

static double cpu_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* View @p v's depth (mm, 0: none) and colour, the points outside the volume left out. */
static int dump_view(const char *out, uint32_t v, const struct scan_view *view,
                     const struct frame_xform *pose, const struct fusion_params *fp)
{
    size_t n = (size_t)view->width * view->height;
    float *depth = calloc(n, sizeof(float));
    char path[SCAN_DIR_PATH_MAX];
    if (depth == NULL)
        return -ENOMEM;
    for (size_t i = 0; i < n; i++) {
        if (view->maps.reason[i] != SCAN_VALID)
            continue;
        const float *p = view->range.xyz_mm + 3 * i;
        vec3 q = frame_point(pose, v3(p[0], p[1], p[2]));
        if (q.x * q.x + q.y * q.y <= fp->radius_mm * fp->radius_mm && q.z >= fp->bottom_mm &&
            q.z <= fp->top_mm)
            depth[i] = p[2];
    }
    snprintf(path, sizeof(path), "%s/view_%u.depth", out, (unsigned)v);
    FILE *f = fopen(path, "wb");
    int rc = f != NULL && fwrite(depth, sizeof(float), n, f) == n ? 0 : -EIO;
    if (f != NULL)
        fclose(f);
    snprintf(path, sizeof(path), "%s/view_%u.rgb", out, (unsigned)v);
    f = fopen(path, "wb");
    if (rc == 0 && (f == NULL || fwrite(view->rgb, 3, n, f) != n))
        rc = -EIO;
    if (f != NULL)
        fclose(f);
    free(depth);
    return rc;
}

int main(int argc, char **argv)
{
    static struct app_config cfg;
    static struct scan_calib calib;
    char err[1024], path[SCAN_DIR_PATH_MAX];
    if (argc != 3) {
        fprintf(stderr, "usage: bench-fusion SCAN_DIR OUT_DIR\n");
        return 2;
    }
    const char *dir = argv[1], *out = argv[2];
    snprintf(path, sizeof(path), "%s/config.ini", dir);
    if (config_load(&cfg, path, err, sizeof(err)) != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    snprintf(path, sizeof(path), "%s/calibration.ini", dir);
    if (calib_load(&calib, path, cfg.light_count, err, sizeof(err)) != 0) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    uint32_t views = cfg.views * cfg.passes;
    struct hal_storage st;
    storage_posix_init(&st);
    FILE *poses = NULL;
    snprintf(path, sizeof(path), "%s/poses.txt", out);
    if (hal_storage_mkdir_p(&st, out) != 0 || (poses = fopen(path, "w")) == NULL)
        return 1;
    fprintf(poses, "%u %u %g %g %g %g %g %g %g %g %g %g\n", (unsigned)calib.cam_width,
            (unsigned)calib.cam_height, calib.cam_fx_px, calib.cam_fy_px, calib.cam_cx_px,
            calib.cam_cy_px, cfg.fusion.voxel_mm, cfg.fusion.truncation_mm, cfg.fusion.radius_mm,
            cfg.fusion.bottom_mm, cfg.fusion.top_mm, (double)views);
    double best_integrate = 1e30, best_extract = 1e30;
    struct mesh_summary ms;
    for (int run = 0; run < 3; run++) {
        double integrate = 0.0;
        if (fusion_begin(&vol, &cfg.fusion) != 0)
            return 1;
        for (uint32_t v = 0; v < views; v++) {
            struct scan_view view;
            struct frame_xform pose;
            if (scan_dir_read_range(&view_buffers, dir, v, calib.cam_width, calib.cam_height, &view,
                                    err, sizeof(err)) != 0 ||
                scan_dir_read_pose(dir, v, &pose) != 0) {
                fprintf(stderr, "view %u: %s\n", (unsigned)v, err);
                return 1;
            }
            double t0 = cpu_ms();
            scan_fuse_view(&vol, NULL, &calib, &view, &pose);
            integrate += cpu_ms() - t0;
            if (run == 0) {
                const double *r = pose.rot;
                /* Open3D's extrinsic, object to camera: p_camera = R^T p_object + origin */
                fprintf(poses, "%g %g %g %g %g %g %g %g %g %g %g %g\n", r[0], r[3], r[6],
                        pose.origin.x, r[1], r[4], r[7], pose.origin.y, r[2], r[5], r[8],
                        pose.origin.z);
                if (dump_view(out, v, &view, &pose, &cfg.fusion) != 0)
                    return 1;
            }
        }
        double t0 = cpu_ms();
        fusion_mesh_prepare(&vol, 0.0, &ms); /* every piece, as Open3D keeps them */
        double extract = cpu_ms() - t0;
        best_integrate = integrate < best_integrate ? integrate : best_integrate;
        best_extract = extract < best_extract ? extract : best_extract;
    }
    fclose(poses);
    snprintf(path, sizeof(path), "%s/mesh.ply", out);
    if (fusion_write_ply(&vol, &st, path) != 0)
        return 1;
    /* one line for the table bench/fusion_open3d.py prints */
    printf("scanner %u %.1f %.1f %u %u\n", (unsigned)views, best_integrate, best_extract,
           (unsigned)ms.vertices, (unsigned)ms.triangles);
    return 0;
}
