/* Triangulation and frames against the simulated rig's calibration. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <math.h>
#include <string.h>

#include "camray.h"
#include "config.h"
#include "frames.h"
#include "refine.h"
#include "thread_posix.h"
#include "tri.h"

static struct scan_calib calib;
static uint16_t column[HAL_MAX_PIXELS];
static uint8_t reason[HAL_MAX_PIXELS];

static int setup(void **state)
{
    (void)state;
    char err[512];
    return calib_load(&calib, "config/sim-calib.ini", 4, err, sizeof(err));
}

static vec3 ray(uint32_t x, uint32_t y)
{
    return v3(((double)x - calib.cam_cx_px) / calib.cam_fx_px,
              ((double)y - calib.cam_cy_px) / calib.cam_fy_px, 1.0);
}

static double proj_u(vec3 p)
{
    vec3 q = v3_add(m3_mul(calib.proj_rot, p), v3_from(calib.proj_trans_mm));
    return calib.proj_fx_px * q.x / q.z + calib.proj_cx_px;
}

/* A surface at 600-650 mm: every reconstructed point lies on its pixel's ray and on its
 * column's plane, and within half a column of the true point. */
static void test_points_on_ray_and_plane(void **state)
{
    (void)state;
    const uint32_t w = calib.cam_width, h = calib.cam_height;
    struct decode_maps maps = {.column = column, .reason = reason, .width = w, .height = h};
    static double true_z[HAL_MAX_PIXELS];
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            true_z[i] = 600.0 + 50.0 * x / w;
            double u = proj_u(v3_scale(ray(x, y), true_z[i]));
            reason[i] = (u >= 0 && u < calib.proj_width - 0.5) ? SCAN_VALID : SCAN_SHADOW;
            column[i] = reason[i] == SCAN_VALID ? (uint16_t)floor(u + 0.5) : 0;
        }
    }
    static float refined[HAL_MAX_PIXELS];
    static struct tri_maps out;
    struct tri_range range;
    assert_int_equal(refine_columns(&maps, NULL, 0, refined), 0);
    assert_int_equal(tri_range_image(&calib, NULL, &out, w, h, refined, reason, &range), 0);
    const struct tri_range *r = &range;
    uint32_t checked = 0;
    for (size_t i = 0; i < (size_t)w * h; i += 97) {
        if (reason[i] != SCAN_VALID)
            continue;
        vec3 p = v3(r->xyz_mm[3 * i], r->xyz_mm[3 * i + 1], r->xyz_mm[3 * i + 2]);
        vec3 d = ray((uint32_t)(i % w), (uint32_t)(i / w));
        assert_true(fabs(p.x / p.z - d.x) < 1e-6 && fabs(p.y / p.z - d.y) < 1e-6);
        assert_true(fabs(proj_u(p) - column[i]) < 1e-3);
        assert_true(fabs(p.z - true_z[i]) < 1.0); /* half a column is ~0.4 mm here */
        checked++;
    }
    assert_true(checked > 5000);
}

/* Through a distorted lens, a range image triangulated whole (its rays tabulated once) and the
 * same columns at every 97th pixel alone (rays inverted one by one: the calibration's depth-error
 * prediction) give the same points. */
static void test_few_pixels_same_points(void **state)
{
    (void)state;
    const struct scan_calib pinhole = calib;
    const double dist[5] = {-0.12, 0.05, 0.001, -0.001, 0.0};
    memcpy(calib.cam_dist, dist, sizeof(dist));
    const uint32_t w = calib.cam_width, h = calib.cam_height;
    static float col[HAL_MAX_PIXELS];
    static uint8_t sparse[HAL_MAX_PIXELS];
    for (size_t i = 0; i < (size_t)w * h; i++) {
        col[i] = (float)(200.0 + 0.5 * (double)(i % w) + 0.01 * (double)(i / w));
        reason[i] = SCAN_VALID;
        sparse[i] = i % 97 == 0 ? SCAN_VALID : SCAN_SHADOW;
    }
    static struct tri_maps whole, few;
    struct tri_range a, b;
    /* the few first: no table of this lens exists yet, and they must not make one */
    assert_int_equal(tri_range_image(&calib, NULL, &few, w, h, col, sparse, &b), 0);
    assert_null(camray_lookup(&calib).xy);
    assert_int_equal(tri_range_image(&calib, NULL, &whole, w, h, col, reason, &a), 0);
    assert_non_null(camray_lookup(&calib).xy);
    uint32_t checked = 0;
    for (size_t i = 0; i < (size_t)w * h; i += 97) {
        if (reason[i] != SCAN_VALID || sparse[i] != SCAN_VALID)
            continue;
        for (int k = 0; k < 3; k++)
            assert_true(fabs(a.xyz_mm[3 * i + k] - b.xyz_mm[3 * i + k]) < 1e-3);
        checked++;
    }
    assert_true(checked > 10000);
    /* a lens folding over in the image's corners is refused either way, as the table refuses
     * it: the few include pixel 0, a corner */
    const double fold[5] = {-5.0, 0.0, 0.0, 0.0, 0.0};
    memcpy(calib.cam_dist, fold, sizeof(fold));
    assert_int_equal(tri_range_image(&calib, NULL, &few, w, h, col, sparse, &b), -EDOM);
    assert_int_equal(tri_range_image(&calib, NULL, &whole, w, h, col, reason, &a), -EDOM);
    calib = pinhole;
}

/* A plane seen head-on gives normals that point back at the camera; refinement makes them
 * better. @retval mean cosine between estimated and true normals */
static double plane_normals(int refine)
{
    const uint32_t w = calib.cam_width, h = calib.cam_height;
    struct decode_maps maps = {.column = column, .reason = reason, .width = w, .height = h};
    /* plane z = 620 + 0.2 x (camera frame): normal ~ (0.196, 0, -0.98) */
    for (uint32_t y = 0; y < h; y++) {
        for (uint32_t x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            vec3 d = ray(x, y);
            double z = 620.0 / (1.0 - 0.2 * d.x);
            double u = proj_u(v3_scale(d, z));
            reason[i] = (u >= 0 && u < calib.proj_width - 0.5) ? SCAN_VALID : SCAN_SHADOW;
            column[i] = reason[i] == SCAN_VALID ? (uint16_t)floor(u + 0.5) : 0;
        }
    }
    static float refined[HAL_MAX_PIXELS];
    static struct tri_maps out;
    struct tri_range range;
    assert_int_equal(refine_columns(&maps, NULL, refine, refined), 0);
    assert_int_equal(tri_range_image(&calib, NULL, &out, w, h, refined, reason, &range), 0);
    assert_int_equal(tri_normals(&out, NULL, &range, reason, 4, 3.0), 0);
    const struct tri_range *r = &range;
    vec3 expect = v3_norm(v3(0.2, 0.0, -1.0));
    double sum = 0.0;
    uint32_t n = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        if (reason[i] != SCAN_VALID)
            continue;
        sum += v3_dot(v3(r->normal[3 * i], r->normal[3 * i + 1], r->normal[3 * i + 2]), expect);
        n++;
    }
    assert_true(n > 100000);
    return sum / n;
}

static void test_normals_of_a_plane(void **state)
{
    (void)state;
    double plain = plane_normals(0), refined = plane_normals(1);
    print_message("mean cos to the true normal: %.4f plain, %.4f refined\n", plain, refined);
    assert_true(plain > 0.95);           /* staircase of whole columns */
    assert_true(refined > plain + 0.01); /* 13 -> 8 degrees mean error on a noise-free plane */
}

/* Pixels lit on the plane z = 500 (facing the camera) in a W x H image, their normals made on
 * @p threads threads. @retval the normals' count */
enum { NW = 4, NH = 3 };
static uint32_t normals_of(const uint32_t lit[][2], size_t count, unsigned threads, uint8_t *why)
{
    static struct tri_maps maps;
    memset(why, SCAN_SHADOW, NW * NH);
    for (size_t k = 0; k < count; k++) {
        size_t i = lit[k][1] * NW + lit[k][0];
        why[i] = SCAN_VALID;
        maps.xyz_mm[3 * i + 0] = (float)lit[k][0];
        maps.xyz_mm[3 * i + 1] = (float)lit[k][1];
        maps.xyz_mm[3 * i + 2] = 500.0f;
    }
    struct hal_thread cores;
    thread_posix_init(&cores, threads);
    struct tri_range range = {maps.xyz_mm, maps.normal, NW, NH, (uint32_t)count};
    assert_int_equal(tri_normals(&maps, &cores, &range, why, 4, 3.0), 0);
    for (size_t i = 0; i < NW * NH; i++)
        if (why[i] == SCAN_VALID)
            assert_float_equal(maps.normal[3 * i + 2], -1.0f, 1e-6f);
    return range.valid_count;
}

/* A pixel that finds no normal (no neighbour on its surface along one axis) stops the reach of
 * the pixels after it in the image (to its right, below it), not of those before it, as when the
 * normals were made one pixel after another in the image's order and each such pixel marked as
 * they went; now in two passes, so that the rows can be split across threads with the same
 * result. (2,1) has no pixel above or below: (1,1) before it reaches it and keeps its normal;
 * (0,1) likewise, but (1,1) after it cannot reach it and has no other neighbour along x. The
 * pixels above and below (1,1) have no neighbour along x: never a normal. One thread and four. */
static void test_normals_stop_after_a_pixel_without_one(void **state)
{
    (void)state;
    for (unsigned threads = 1; threads <= 4; threads *= 4) {
        uint8_t why[NW * NH];
        const uint32_t right[][2] = {{1, 1}, {2, 1}, {1, 0}, {1, 2}};
        assert_int_equal(normals_of(right, 4, threads, why), 1);
        assert_int_equal(why[1 * NW + 1], SCAN_VALID);
        assert_int_equal(why[1 * NW + 2], SCAN_INCONSISTENT);
        assert_int_equal(why[0 * NW + 1], SCAN_INCONSISTENT);
        assert_int_equal(why[2 * NW + 1], SCAN_INCONSISTENT);
        const uint32_t left[][2] = {{0, 1}, {1, 1}, {1, 0}, {1, 2}};
        assert_int_equal(normals_of(left, 4, threads, why), 0);
        assert_int_equal(why[1 * NW + 0], SCAN_INCONSISTENT);
        assert_int_equal(why[1 * NW + 1], SCAN_INCONSISTENT);
    }
}

static void test_turntable_frame(void **state)
{
    (void)state;
    struct frame_xform t, o;
    frame_table_from_camera(&calib, &t);
    vec3 origin = frame_point(&t, v3_from(calib.axis_point_mm));
    assert_true(v3_len(origin) < 1e-9);
    vec3 up = frame_dir(&t, v3_from(calib.axis_dir));
    assert_true(fabs(up.z - 1.0) < 1e-9);
    vec3 cam = frame_point(&t, v3(0, 0, 0)); /* the camera: on +x, above the table */
    assert_true(cam.x > 500.0 && fabs(cam.y) < 1e-9 && cam.z > 0.0);
    /* At 90 degrees the object frame sees the camera on -y (the table turned the object). */
    frame_object_from_camera(&calib, 90000, &o);
    vec3 cam_o = frame_point(&o, v3(0, 0, 0));
    assert_true(fabs(cam_o.x) < 1e-6 && fabs(cam_o.y + cam.x) < 1e-6);
    vec3 back = frame_point_inv(&o, cam_o);
    assert_true(v3_len(back) < 1e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_points_on_ray_and_plane),
        cmocka_unit_test(test_few_pixels_same_points),
        cmocka_unit_test(test_normals_of_a_plane),
        cmocka_unit_test(test_normals_stop_after_a_pixel_without_one),
        cmocka_unit_test(test_turntable_frame),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
