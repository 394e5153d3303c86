/* The simulated rig: meshes, ray casting, determinism and the camera's noise model. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_bvh.h"
#include "sim_material.h"
#include "test_util.h"

/* Load a mesh the test needs, failing with the file's name and the reader's message. */
static void load_mesh(struct sim_mesh *m, const char *path)
{
    char err[256];
    if (sim_mesh_load_ply(m, path, err, sizeof(err)) != 0)
        fail_msg("%s", err);
}

static void test_bunny_ply_loads(void **state)
{
    (void)state;
    struct sim_mesh m;
    char err[256];
    load_mesh(&m, "data/bunny/bun_zipper.ply");
    assert_int_equal(m.vert_count, 35947);
    assert_int_equal(m.tri_count, 69451);
    sim_mesh_y_up_to_z_up(&m);
    sim_mesh_place(&m, 150.0);
    float zmin = 1e9f, zmax = -1e9f;
    for (uint32_t i = 0; i < m.vert_count; i++) {
        zmin = fminf(zmin, m.pos[3 * i + 2]);
        zmax = fmaxf(zmax, m.pos[3 * i + 2]);
    }
    assert_true(fabsf(zmin) < 1e-3f && fabsf(zmax - 150.0f) < 1e-3f);
    sim_mesh_free(&m);
    assert_int_not_equal(sim_mesh_load_ply(&m, "config/sim.ini", err, sizeof(err)), 0);
    assert_non_null(strstr(err, "not a PLY file"));
}

/* A scan's mesh.ply carries its colour twice, sRGB bytes and linear floats: the reader keeps the
 * floats as written (sim_mesh_linear), finer than a byte, and their bytes; a file of bytes with a
 * stray float channel (no red_linear) keeps bytes only, that channel from its float (it crashed
 * the reader once: tests/fuzz/crashes/ply/bytes-and-a-stray-linear-float). */
static void test_ply_linear_colours(void **state)
{
    (void)state;
    struct sim_mesh m;
    double lin[3];
    FILE *f = fopen("build/test_sim_linear.ply", "w");
    assert_non_null(f);
    fputs("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
          "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
          "property float red_linear\nproperty float green_linear\nproperty float blue_linear\n"
          "end_header\n1 2 3 9 99 255 0.0123 0.5 1.5\n",
          f);
    fclose(f);
    char err[256];
    assert_int_equal(sim_mesh_load_ply_points(&m, "build/test_sim_linear.ply", err, sizeof(err)),
                     0);
    assert_non_null(m.lin);
    sim_mesh_linear(&m, 0, lin);
    assert_true(fabs(lin[0] - 0.0123) < 1e-7 && lin[1] == 0.5 && lin[2] == 1.0); /* clamped */
    assert_true(m.rgb[0] == 3 && m.rgb[1] == 128 && m.rgb[2] == 255);
    sim_mesh_free(&m);
    assert_int_equal(sim_mesh_load_ply(&m, "tests/fuzz/crashes/ply/bytes-and-a-stray-linear-float",
                                       err, sizeof(err)),
                     0);
    assert_null(m.lin);
    sim_mesh_linear(&m, 0, lin);
    assert_true(lin[0] == 1.0 && fabs(lin[1] - 128 / 255.0) < 1e-12 && lin[2] == 0.0);
    sim_mesh_free(&m);
}

/* The BVH finds the same closest hit as testing every triangle. */
static void test_bvh_matches_brute_force(void **state)
{
    (void)state;
    struct sim_mesh m;
    load_mesh(&m, "data/bunny/bun_zipper_res3.ply");
    sim_mesh_place(&m, 150.0);
    struct sim_bvh bvh;
    assert_int_equal(sim_bvh_build(&bvh, &m), 0);
    struct sim_mesh one = m;
    uint32_t hits = 0;
    srand(7);
    for (int r = 0; r < 300; r++) {
        vec3 o = v3(300.0, (rand() % 200) - 100.0, (rand() % 200) - 20.0);
        vec3 d = v3(-1.0, (rand() % 100 - 50) / 500.0, (rand() % 100 - 50) / 500.0);
        struct sim_hit h;
        int got = sim_bvh_intersect(&bvh, o, d, 1e-6, 1e9, &h);
        double best = 1e18;
        for (uint32_t t = 0; t < m.tri_count; t++) { /* one-triangle BVHs: brute force */
            struct sim_bvh single;
            one.tri = &m.tri[3 * t];
            one.tri_count = 1;
            assert_int_equal(sim_bvh_build(&single, &one), 0);
            struct sim_hit hh;
            if (sim_bvh_intersect(&single, o, d, 1e-6, 1e9, &hh) && hh.t < best)
                best = hh.t;
            sim_bvh_free(&single);
        }
        assert_int_equal(got, best < 1e18);
        if (got) {
            assert_true(fabs(h.t - best) < 1e-9);
            assert_int_equal(sim_bvh_occluded(&bvh, o, d, 1e-6, 1e9), 1);
            hits++;
        }
    }
    assert_true(hits > 30);
    sim_bvh_free(&bvh);
    sim_mesh_free(&m);
}

/* Two meshes the surface-area split meets badly: 500 copies of one square (every centroid in one
 * bin: halved instead) and 500 squares at x = +-2^-125 ... +-2^124 mm (each split parts a few from
 * the rest: 64 levels, where the build stops so that traversal's stack cannot overflow, with a
 * leaf of many). Every closest hit is still the nearest square, and a ray beside them misses. */
static void test_bvh_degenerate_meshes(void **state)
{
    (void)state;
    enum { N = 500 };
    static float pos[3 * 4 * N];
    static uint32_t tri[3 * 2 * N];
    struct sim_mesh m = {.vert_count = 4 * N, .tri_count = 2 * N, .pos = pos, .tri = tri};
    for (int stacked = 0; stacked < 2; stacked++) {
        for (uint32_t k = 0; k < N; k++) {
            int e = (int)(k % (N / 2)) - 125;
            float x = stacked ? 5.0f : k < N / 2 ? ldexpf(1.0f, e) : -ldexpf(1.0f, e);
            const float corner[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
            for (int c = 0; c < 4; c++) {
                pos[3 * (4 * k + c)] = x;
                pos[3 * (4 * k + c) + 1] = corner[c][0];
                pos[3 * (4 * k + c) + 2] = corner[c][1];
            }
            const uint32_t q[6] = {0, 1, 2, 0, 2, 3};
            for (int i = 0; i < 6; i++)
                tri[6 * k + i] = 4 * k + q[i];
        }
        struct sim_bvh bvh;
        assert_int_equal(sim_bvh_build(&bvh, &m), 0);
        for (int r = 0; r < 49; r++) {
            struct sim_hit h;
            vec3 o = v3(0.75, (r % 7 - 3) * 0.25, (r / 7 - 3) * 0.25); /* towards +x: 1 or 5 */
            assert_int_equal(sim_bvh_intersect(&bvh, o, v3(1, 0, 0), 1e-6, 1e39, &h), 1);
            assert_true(fabs(h.t - (stacked ? 4.25 : 0.25)) < 1e-12);
            assert_int_equal(sim_bvh_occluded(&bvh, o, v3(1, 0, 0), 1e-6, 1e39), 1);
            int got = sim_bvh_intersect(&bvh, o, v3(-1, 0, 0), 1e-6, 1e39, &h); /* 0.5 or none */
            assert_int_equal(got, !stacked);
            assert_true(stacked || fabs(h.t - 0.25) < 1e-12);
            o.x = 1e38; /* from beyond the far end, towards -x: 2^124 or 5 */
            assert_int_equal(sim_bvh_intersect(&bvh, o, v3(-1, 0, 0), 1e-6, 1e39, &h), 1);
            double want = 1e38 - (stacked ? 5.0 : ldexp(1.0, 124));
            assert_true(fabs(h.t - want) <= 1e-12 * want);
        }
        assert_int_equal(sim_bvh_occluded(&bvh, v3(0.75, 3, 0), v3(1, 0, 0), 1e-6, 1e39), 0);
        sim_bvh_free(&bvh);
    }
}

static void test_closed_shapes_have_outward_normals(void **state)
{
    (void)state;
    struct sim_mesh m;
    for (int s = 0; s < 4; s++) {
        int rc = s == 0   ? sim_mesh_sphere(&m, 50, 64)
                 : s == 1 ? sim_mesh_cylinder(&m, 30, 100, 64)
                 : s == 2 ? sim_mesh_box(&m, 60, 40, 100, 32)
                          : sim_mesh_torus(&m, 50, 20, 64);
        assert_int_equal(rc, 0);
        sim_mesh_place(&m, 100.0);
        /* Outward: the normal points away from the centroid of the axis at that height for
         * convex shapes; the torus: away from its tube centre. */
        for (uint32_t i = 0; i < m.vert_count; i++) {
            vec3 p = v3(m.pos[3 * i], m.pos[3 * i + 1], m.pos[3 * i + 2]);
            vec3 n = v3(m.normal[3 * i], m.normal[3 * i + 1], m.normal[3 * i + 2]);
            vec3 c = v3(0, 0, 50.0);
            if (s == 3) {
                double r = hypot(p.x, p.y);
                double major = 50.0 * 100.0 / 40.0;
                c = r > 1e-9 ? v3(p.x / r * major, p.y / r * major, 50.0) : c;
            }
            if (v3_len(n) > 0.5)
                assert_true(v3_dot(n, v3_sub(p, c)) > -1e-6);
        }
        sim_mesh_free(&m);
    }
}

/* Same seed, same frame; another seed, other noise. Black frame statistics as configured. */
static void test_deterministic_noise_and_black_level(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_start_box(&t), 0);
    struct sim_rig *rig = sim_ctl_rig();
    size_t n = (size_t)rig->width * rig->height * 3;
    static uint8_t a[HAL_MAX_PIXELS * 3], b[HAL_MAX_PIXELS * 3];
    struct sim_sources dark = {.exposure_us = 10000, .gain_milli = 1000};
    sim_rig_render(rig, &dark, 1, a);
    sim_rig_render(rig, &dark, 1, b);
    assert_memory_equal(a, b, n);
    sim_rig_render(rig, &dark, 2, b);
    assert_true(memcmp(a, b, n) != 0);
    /* Background pixels of the dark frame: offset 51, read noise 1.5 */
    double sum = 0, sum_sq = 0;
    size_t count = 0;
    for (size_t i = 0; i < n / 3; i++) {
        if (rig->truth.hit[i])
            continue;
        sum += a[3 * i];
        sum_sq += (double)a[3 * i] * a[3 * i];
        count++;
    }
    double mean = sum / count, sd = sqrt(sum_sq / count - mean * mean);
    print_message("dark frame: mean %.2f, sd %.2f over %zu pixels\n", mean, sd, count);
    assert_true(fabs(mean - 51.0) < 0.05);
    assert_true(fabs(sd - 1.5) < 0.1 + 0.3); /* rounding to integers adds 1/12 variance */
    /* A strong exposure saturates at 255, never wraps */
    struct sim_sources bright = {
        .projector_on = 1, .pattern_index = 0, .exposure_us = 80000, .gain_milli = 1000};
    sim_rig_render(rig, &bright, 3, a);
    size_t saturated = 0;
    for (size_t i = 0; i < n; i++)
        saturated += a[i] == 255;
    assert_true(saturated > 1000);
    test_rig_stop(&t);
}

/* Dark-paint and object pixels of the rig at @p angle_mdeg, with the object posed as @p pose
 * (and stood @p offset_mm off the axis, if not NULL; where its middle came into @p centre_mm). */
static void posed_counts_at(const double pose[3], const double *offset_mm, int32_t angle_mdeg,
                            size_t *hit, size_t *dark, double *height_mm, double centre_mm[2])
{
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "box");
    t.cfg.sim.segments = 16;
    memcpy(t.cfg.sim.object_pose_deg, pose, 3 * sizeof(double));
    if (offset_mm != NULL)
        memcpy(t.cfg.sim.object_offset_mm, offset_mm, 2 * sizeof(double));
    assert_int_equal(test_rig_start(&t), 0);
    struct sim_rig *rig = sim_ctl_rig();
    rig->table_angle_mdeg = angle_mdeg;
    sim_rig_update(rig);
    *hit = *dark = 0;
    for (size_t i = 0; i < (size_t)rig->width * rig->height; i++) {
        *hit += rig->truth.hit[i];
        *dark += rig->truth.dark[i];
    }
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t v = 0; v < rig->mesh.vert_count; v++)
        for (int c = 0; c < 3; c++) {
            lo[c] = fminf(lo[c], rig->mesh.pos[3 * v + (uint32_t)c]);
            hi[c] = fmaxf(hi[c], rig->mesh.pos[3 * v + (uint32_t)c]);
        }
    assert_true(fabsf(lo[2]) < 1e-3f); /* stood on the table */
    *height_mm = hi[2] - lo[2];
    centre_mm[0] = 0.5 * (lo[0] + hi[0]);
    centre_mm[1] = 0.5 * (lo[1] + hi[1]);
    test_rig_stop(&t);
}

static void posed_counts(const double pose[3], int32_t angle_mdeg, size_t *hit, size_t *dark,
                         double *height_mm)
{
    double centre[2];
    posed_counts_at(pose, NULL, angle_mdeg, hit, dark, height_mm, centre);
}

/* [sim] object_pose: the box (0.6 h x 0.45 h x h) laid on its side is 0.45 h tall; turned a
 * quarter about the vertical and seen with the table a quarter back, it is the unturned box,
 * its paint (the dark stripe) included: the paint stays on the object. */
static void test_object_pose(void **state)
{
    (void)state;
    const double none[3] = {0, 0, 0}, side[3] = {90, 0, 0}, turned[3] = {0, 0, 90};
    size_t hit0, dark0, hit1, dark1, hit2, dark2;
    double h0, h1, h2;
    posed_counts(none, 0, &hit0, &dark0, &h0);
    posed_counts(side, 0, &hit1, &dark1, &h1);
    posed_counts(turned, -90000, &hit2, &dark2, &h2);
    print_message("standing %.1f mm, on its side %.1f mm; pixels %zu / %zu, dark %zu / %zu\n", h0,
                  h1, hit0, hit2, dark0, dark2);
    assert_true(fabs(h0 - 150.0) < 0.01 && fabs(h1 - 0.45 * 150.0) < 0.01);
    assert_true(fabs(h2 - 150.0) < 0.01);
    assert_true(dark0 > 1000);
    assert_true(labs((long)hit2 - (long)hit0) <= (long)(hit0 / 1000));
    assert_true(labs((long)dark2 - (long)dark0) <= (long)(dark0 / 100) + 5);
    assert_true(hit1 != hit0);
}

/* [sim] object_offset_mm: the box stands that far off the axis (truth_mesh.ply is written from
 * the same mesh), its height and paint with it: seen from the table turned half a turn, the box
 * stood at -offset shows the camera the same pixels, dark stripe included, as the box stood at
 * +offset seen from the front turned half a turn too (the same object, the same place). */
static void test_object_offset(void **state)
{
    (void)state;
    const double none[3] = {0, 0, 0}, off[2] = {30, -20}, minus[2] = {-30, 20};
    const double turned[3] = {0, 0, 180};
    size_t hit0, dark0, hit1, dark1, hit2, dark2;
    double h0, h1, h2, c0[2], c1[2], c2[2];
    posed_counts_at(none, NULL, 0, &hit0, &dark0, &h0, c0);
    posed_counts_at(none, off, 0, &hit1, &dark1, &h1, c1);
    posed_counts_at(turned, minus, -180000, &hit2, &dark2, &h2, c2);
    print_message("centred %zu px (%zu dark); 30, -20 mm off %zu (%zu); turned, -30, 20 mm off, "
                  "the table half a turn back %zu (%zu)\n",
                  hit0, dark0, hit1, dark1, hit2, dark2);
    assert_true(fabs(c1[0] - 30.0) < 1e-3 && fabs(c1[1] + 20.0) < 1e-3);
    assert_true(fabs(c2[0] + 30.0) < 1e-3 && fabs(c2[1] - 20.0) < 1e-3);
    assert_true(fabs(h1 - h0) < 1e-3 && fabs(h2 - h0) < 1e-3);
    assert_true(hit1 != hit0); /* it moved in the picture */
    assert_true(labs((long)hit2 - (long)hit1) <= (long)(hit1 / 1000));
    assert_true(labs((long)dark2 - (long)dark1) <= (long)(dark1 / 100) + 5);
}

/* Where a paint boundary lies in column @p x of the box's picture, to a fraction of a row: between
 * the paints seen @p reach rows above and below row @p y (two rows of each, the rows between
 * them the boundary's), on one side face (the same normal throughout, not the top), as the
 * rows' shares of the lower paint sum up (a pixel's albedo taken as a mix of the two).
 * @retval 0 found, @p normal_x its face's normal's x (camera frame) @retval -1 none there */
static int boundary_row(const struct sim_rig *rig, uint32_t x, uint32_t y, uint32_t reach,
                        double *row, double *normal_x)
{
    const float *al = rig->truth.albedo, *nc = rig->truth.normal_cam;
    const size_t w = rig->width, top = ((size_t)y - reach) * w + x, bottom = top + 2 * reach * w;
    double diff = 0.0, below = 0.0;
    for (int c = 0; c < 3; c++) {
        diff += (al[3 * bottom + c] - al[3 * top + c]) * (al[3 * bottom + c] - al[3 * top + c]);
        if (al[3 * top + c] != al[3 * (top + w) + c] ||
            al[3 * bottom + c] != al[3 * (bottom - w) + c])
            return -1; /* not two paints, each whole at its end */
    }
    if (diff < 0.01 || fabs(nc[3 * top + 1]) > 0.3)
        return -1; /* one paint, or the top */
    for (size_t i = top; i <= bottom; i += w) {
        double share = 0.0;
        if (!rig->truth.hit[i] || rig->truth.dark[i] ||
            nc[3 * i] * nc[3 * top] + nc[3 * i + 1] * nc[3 * top + 1] +
                    nc[3 * i + 2] * nc[3 * top + 2] <
                0.9999)
            return -1; /* another face, or off the object */
        for (int c = 0; c < 3; c++)
            share += (al[3 * i + c] - al[3 * top + c]) * (al[3 * bottom + c] - al[3 * top + c]);
        share /= diff;
        if (share < -0.01 || share > 1.01)
            return -1; /* a third paint */
        below += share;
    }
    *row = (double)(y + reach) + 0.5 - below; /* from the boundary down: the lower paint */
    *normal_x = nc[3 * top];
    return 0;
}

/* How far points (@p x, @p y) lie from the straight line fitted through them. @retval RMS */
static double line_rms(const double *x, const double *y, uint32_t n, double *slope)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0, sq = 0;
    for (uint32_t i = 0; i < n; i++)
        sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
    *slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    double icpt = (sy - *slope * sx) / n;
    for (uint32_t i = 0; i < n; i++)
        sq += (y[i] - icpt - *slope * x[i]) * (y[i] - icpt - *slope * x[i]);
    return sqrt(sq / n);
}

/* A camera pixel takes the paint over its area: a painted boundary falls between pixels as a
 * mix of both paints, not on the pixel grid. The box's bands meet its side faces in straight
 * horizontal lines; seen with the table turned 45 degrees, each a straight line sloping across
 * the picture, and the boundary read from the mixed pixels of each column (on the face seen the
 * more squarely) lies on it to a tenth of a pixel (0.02 px RMS). Taken from the one point under
 * each pixel's centre, as before 2026-12-06, no pixel mixed the paints and the boundary stepped
 * from row to row (0.76 px RMS). */
static void test_paint_edges_between_pixels(void **state)
{
    (void)state;
    static struct test_rig t;
    static double xs[2][2048], rows[2][2048];
    uint32_t count[2] = {0, 0};
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    snprintf(t.cfg.sim.object, sizeof(t.cfg.sim.object), "box");
    assert_int_equal(test_rig_start(&t), 0);
    struct sim_rig *rig = sim_ctl_rig();
    assert_true(rig->width <= 2048);
    rig->table_angle_mdeg = 45000;
    sim_rig_update(rig);
    double first[2] = {-1.0, -1.0}; /* each face's first boundary from the top: one band's */
    for (uint32_t x = 0; x < rig->width; x++) {
        double row = 0.0, normal_x = 0.0;
        uint32_t y = 4;
        for (; y + 4 < rig->height; y++)
            if (boundary_row(rig, x, y, 3, &row, &normal_x) == 0)
                break;
        int face = normal_x > 0.0;
        if (y + 4 >= rig->height || (first[face] >= 0.0 && fabs(row - first[face]) > 30.0))
            continue;
        first[face] = row;
        xs[face][count[face]] = x, rows[face][count[face]++] = row;
    }
    int face = count[1] > count[0]; /* the face seen the more squarely */
    double slope, rms = line_rms(xs[face], rows[face], count[face], &slope);
    uint32_t mixed = 0;
    for (uint32_t i = 0; i < count[face]; i++)
        mixed += fabs(rows[face][i] - floor(rows[face][i]) - 0.5) > 0.02; /* not at an edge */
    print_message("a band's boundary over %u columns, slope %.4f, %.3f px from its line (RMS), "
                  "%u columns mixing the paints\n",
                  count[face], slope, rms, mixed);
    assert_true(count[face] > 100);
    assert_true(fabs(slope) > 0.01); /* sloping: the pixel grid would show */
    assert_true(rms < 0.1);
    assert_true(mixed > count[face] / 2);
    test_rig_stop(&t);
}

/* The ABC model of a measured material reflects more near the mirror direction. */
static void test_merl_material(void **state)
{
    (void)state;
    struct sim_material mat;
    const char *csv = "data/materials/merl_abc_lowetal2012.csv";
    int rc = sim_material_load_abc(&mat, csv, "red-plastic");
    if (rc != 0)
        fail_msg("%s: %s", csv, strerror(-rc));
    assert_int_not_equal(sim_material_load_abc(&mat, csv, "unobtainium"), 0);
    assert_int_equal(sim_material_load_abc(&mat, csv, "gold-metallic-paint"), 0);
    double albedo[3] = {mat.abc_kd[0], mat.abc_kd[1], mat.abc_kd[2]}, mirror[3], off[3];
    vec3 n = v3(0, 0, 1), l = v3_norm(v3(1, 0, 1));
    sim_material_eval(&mat, albedo, n, l, v3_norm(v3(-1, 0, 1)), mirror);
    sim_material_eval(&mat, albedo, n, l, v3_norm(v3(1, 0.3, 1)), off);
    assert_true(mirror[0] > 5.0 * off[0]);
    sim_material_eval(&mat, albedo, n, v3(0, 0, -1), v3(0, 0, 1), off); /* lit from behind */
    assert_true(off[0] == 0.0 && off[1] == 0.0 && off[2] == 0.0);
}

/* [sim] placement_jitter_mm and _deg: a board stands about where the step asks (the same for
 * every capture of one placement, within the bounds, another for another seed); 0: exactly. */
static void test_board_placement_jitter(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_start_box(&t), 0);
    struct sim_rig *rig = sim_ctl_rig();
    static const uint8_t sheet[16 * 16] = {0};
    const struct board_target asked = {.kind = BOARD_TARGET_BOARD,
                                       .sheet = sheet,
                                       .sheet_width = 16,
                                       .sheet_height = 16,
                                       .sheet_px_per_mm = 0.1,
                                       .thickness_mm = 3.0,
                                       .tilt_deg = 25.0,
                                       .position_mm = {0.0, 40.0}};
    char err[256];
    double placed[3][3]; /* exact; jittered; jittered again */
    for (int k = 0; k < 3; k++) {
        rig->cfg.placement_jitter_mm = k == 0 ? 0.0 : 5.0;
        rig->cfg.placement_jitter_deg = k == 0 ? 0.0 : 3.0;
        assert_int_equal(board_place_target(&t.hal, &asked, err, sizeof(err)), 0);
        placed[k][0] = rig->target.position_mm[0], placed[k][1] = rig->target.position_mm[1];
        placed[k][2] = rig->target.tilt_deg;
    }
    assert_true(placed[0][0] == 0.0 && placed[0][1] == 40.0 && placed[0][2] == 25.0);
    assert_true(fabs(placed[1][0]) <= 5.0 && fabs(placed[1][1] - 40.0) <= 5.0 &&
                fabs(placed[1][2] - 25.0) <= 3.0);
    assert_true(placed[1][0] != 0.0 && placed[1][2] != 25.0);
    assert_memory_equal(placed[1], placed[2], sizeof(placed[1])); /* one placement, one stance */
    rig->cfg.seed++;
    assert_int_equal(board_place_target(&t.hal, &asked, err, sizeof(err)), 0);
    assert_true(rig->target.position_mm[0] != placed[1][0] && rig->target.tilt_deg != placed[1][2]);
    test_rig_stop(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bunny_ply_loads),
        cmocka_unit_test(test_ply_linear_colours),
        cmocka_unit_test(test_bvh_matches_brute_force),
        cmocka_unit_test(test_bvh_degenerate_meshes),
        cmocka_unit_test(test_closed_shapes_have_outward_normals),
        cmocka_unit_test(test_deterministic_noise_and_black_level),
        cmocka_unit_test(test_merl_material),
        cmocka_unit_test(test_object_pose),
        cmocka_unit_test(test_object_offset),
        cmocka_unit_test(test_paint_edges_between_pixels),
        cmocka_unit_test(test_board_placement_jitter),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
