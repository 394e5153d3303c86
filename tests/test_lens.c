/* Lens distortion, camera rays and triangulation through distorted camera and projector lenses. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>

#include "camray.h"
#include "config.h"
#include "lens.h"
#include "tri.h"

static const double demo_lens[LENS_COEFFS] = {-0.1, 0.06, 0.0006, -0.0004, 0.01};

/* OpenCV's documented model, written out independently of lens.c. */
static void opencv_distort(const double d[5], double x, double y, double *xd, double *yd)
{
    double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
    double radial = 1 + d[0] * r2 + d[1] * r4 + d[4] * r6;
    *xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
    *yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
}

static void test_distort_matches_the_model(void **state)
{
    (void)state;
    for (double x = -0.4; x <= 0.4; x += 0.05) {
        for (double y = -0.3; y <= 0.3; y += 0.05) {
            double a, b, c, d;
            lens_distort(demo_lens, x, y, &a, &b);
            opencv_distort(demo_lens, x, y, &c, &d);
            assert_true(fabs(a - c) < 1e-15 && fabs(b - d) < 1e-15);
        }
    }
}

static void test_undistort_inverts_distort(void **state)
{
    (void)state;
    double worst = 0.0;
    for (double x = -0.4; x <= 0.4; x += 0.01) {
        for (double y = -0.3; y <= 0.3; y += 0.01) {
            double xd, yd, u, v;
            opencv_distort(demo_lens, x, y, &xd, &yd);
            assert_int_equal(lens_undistort(demo_lens, xd, yd, &u, &v), 0);
            worst = fmax(worst, fmax(fabs(u - x), fabs(v - y)));
        }
    }
    assert_true(worst < 1e-12);
}

static void test_jacobian_matches_differences(void **state)
{
    (void)state;
    const double h = 1e-7, x = 0.23, y = -0.17;
    double j[4], x0, y0, x1, y1, x2, y2;
    lens_jacobian(demo_lens, x, y, j);
    lens_distort(demo_lens, x - h, y, &x0, &y0);
    lens_distort(demo_lens, x + h, y, &x1, &y1);
    assert_true(fabs(j[0] - (x1 - x0) / (2 * h)) < 1e-7 && fabs(j[2] - (y1 - y0) / (2 * h)) < 1e-7);
    lens_distort(demo_lens, x, y - h, &x0, &y0);
    lens_distort(demo_lens, x, y + h, &x2, &y2);
    assert_true(fabs(j[1] - (x2 - x0) / (2 * h)) < 1e-7 && fabs(j[3] - (y2 - y0) / (2 * h)) < 1e-7);
}

/* Strong barrel distortion folds the image over beyond r ~ 1/sqrt(3 |k1|): no inverse there. */
static void test_undistort_refuses_a_fold(void **state)
{
    (void)state;
    const double barrel[LENS_COEFFS] = {-0.5, 0, 0, 0, 0};
    double u, v;
    assert_int_equal(lens_undistort(barrel, 0.9, 0.0, &u, &v), -EDOM);
}

static struct scan_calib rig;

static int setup(void **state)
{
    (void)state;
    char err[512];
    return calib_load(&rig, "config/demo-rig.ini", 4, err, sizeof(err));
}

/* Each pixel's tabulated ray projects back onto the pixel through the forward model. */
static void test_camera_rays_project_back(void **state)
{
    (void)state;
    struct camray rays;
    assert_int_equal(camray_prepare(&rig, &rays), 0);
    double worst = 0.0;
    for (uint32_t y = 0; y < rig.cam_height; y += 7) {
        for (uint32_t x = 0; x < rig.cam_width; x += 7) {
            vec3 d = camray_at(&rig, rays, x, y);
            double xd, yd;
            opencv_distort(rig.cam_dist, d.x, d.y, &xd, &yd);
            double u = rig.cam_fx_px * xd + rig.cam_cx_px, v = rig.cam_fy_px * yd + rig.cam_cy_px;
            worst = fmax(worst, fmax(fabs(u - x), fabs(v - y)));
        }
    }
    assert_true(worst < 1e-3); /* the table is float: 1e-7 of the ray */
}

static float column[HAL_MAX_PIXELS];
static uint8_t reason[HAL_MAX_PIXELS];
static double true_z[HAL_MAX_PIXELS];

/* The ray table belongs to a calibration by what it says, not by where it is kept (issue 29):
 * a copy elsewhere finds it; the same place holding another calibration does not. */
static void test_ray_table_keyed_by_content(void **state)
{
    (void)state;
    static struct scan_calib copy, other;
    struct camray rays;
    assert_int_equal(camray_prepare(&rig, &rays), 0);
    assert_non_null(rays.xy);
    copy = rig;
    assert_ptr_equal(camray_lookup(&copy).xy, rays.xy);
    other = rig;
    other.cam_dist[0] += 0.01; /* changed in place: its rays are no longer the table's */
    assert_null(camray_lookup(&other).xy);
    vec3 a = camray_at(&other, camray_lookup(&other), 10, 10);
    vec3 b = camray_at(&rig, rays, 10, 10);
    assert_true(fabs(a.x - b.x) > 1e-6);
}

/* The projector's distorted column of a camera-frame point (forward model only). */
static double proj_column(const struct scan_calib *c, vec3 p)
{
    vec3 q = v3_add(m3_mul(c->proj_rot, p), v3_from(c->proj_trans_mm));
    double xd, yd;
    opencv_distort(c->proj_dist, q.x / q.z, q.y / q.z, &xd, &yd);
    return c->proj_fx_px * xd + c->proj_cx_px;
}

/* A slanted surface seen through both distorted lenses, exact continuous columns: the points
 * come back at their true depth. With the projector's distortion ignored (treated as a
 * pinhole), the same columns give depth errors of millimetres: what modelling it buys. */
static void test_triangulates_through_both_lenses(void **state)
{
    (void)state;
    const uint32_t w = rig.cam_width, h = rig.cam_height;
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            true_z[i] = 580.0 + 60.0 * x / w + 20.0 * y / h;
            double u =
                proj_column(&rig, v3_scale(camray_at(&rig, camray_lookup(&rig), x, y), true_z[i]));
            reason[i] = (u >= 0 && u < rig.proj_width - 0.5) ? SCAN_VALID : SCAN_SHADOW;
            column[i] = (float)u;
        }
    }
    static struct tri_maps out;
    struct tri_range r;
    assert_int_equal(tri_range_image(&rig, NULL, &out, w, h, column, reason, &r), 0);
    assert_true(r.valid_count > w * h / 2);
    double worst = 0.0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (reason[i] == SCAN_VALID)
            worst = fmax(worst, fabs(r.xyz_mm[3 * i + 2] - true_z[i]));
    assert_true(worst < 1e-3);

    struct scan_calib pinhole = rig;
    for (int k = 0; k < LENS_COEFFS; k++)
        pinhole.proj_dist[k] = 0.0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        reason[i] = column[i] >= 0 && column[i] < rig.proj_width - 0.5 ? SCAN_VALID : SCAN_SHADOW;
    assert_int_equal(tri_range_image(&pinhole, NULL, &out, w, h, column, reason, &r), 0);
    worst = 0.0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (reason[i] == SCAN_VALID)
            worst = fmax(worst, fabs(r.xyz_mm[3 * i + 2] - true_z[i]));
    assert_true(worst > 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_distort_matches_the_model),
        cmocka_unit_test(test_undistort_inverts_distort),
        cmocka_unit_test(test_jacobian_matches_differences),
        cmocka_unit_test(test_undistort_refuses_a_fold),
        cmocka_unit_test(test_camera_rays_project_back),
        cmocka_unit_test(test_ray_table_keyed_by_content),
        cmocka_unit_test(test_triangulates_through_both_lenses),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
