/* The PLY file of a view: header as MeshLab and Open3D expect, and every vertex as computed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "frames.h"
#include "outbuf.h"
#include "storage_posix.h"
#include "srgb.h"
#include "test_util.h"

static void test_ply_roundtrip(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_start_box(&t), 0);
    struct scan_view view;
    struct scan_view_info info;
    const int32_t angle_mdeg = 30000;
    assert_int_equal(hal_table_move_to(&t.hal.turntable, angle_mdeg), 0);
    assert_int_equal(
        scan_take_view(t.scan, &t.hal, &t.cfg.scan, &t.calib, angle_mdeg, NULL, &view, &info), 0);
    assert_int_equal(scan_save_cloud_at_turntable_pose(&t, &view, "build/test_ply.ply"), 0);

    FILE *f = fopen("build/test_ply.ply", "rb");
    assert_non_null(f);
    char line[128];
    unsigned count = 0;
    int props = 0;
    while (fgets(line, sizeof(line), f) != NULL && strcmp(line, "end_header\n") != 0) {
        sscanf(line, "element vertex %u", &count);
        props += strncmp(line, "property", 8) == 0;
        if (strncmp(line, "format", 6) == 0)
            assert_string_equal(line, "format binary_little_endian 1.0\n");
    }
    assert_int_equal(count, info.valid_points);
    assert_int_equal(props, 13);
    /* Vertices are in the object frame: rotating back by the angle gives the camera points. */
    struct frame_xform obj;
    frame_object_from_camera(&t.calib, angle_mdeg, &obj);
    const struct decode_maps *maps = &view.maps;
    const struct tri_range *r = &view.range;
    const uint8_t *rgb = view.rgb; /* the view's colour: intrinsic in config/sim.ini */
    size_t n = (size_t)maps->width * maps->height, seen = 0;
    for (size_t i = 0; i < n; i++) {
        if (maps->reason[i] != SCAN_VALID)
            continue;
        unsigned char rec[43];
        assert_int_equal(fread(rec, 1, 43, f), 43);
        float v[6];
        memcpy(v, rec, sizeof(v)); /* little-endian host, as the file */
        vec3 p = frame_point_inv(&obj, v3(v[0], v[1], v[2]));
        assert_true(fabs(p.x - r->xyz_mm[3 * i]) < 1e-3 && fabs(p.z - r->xyz_mm[3 * i + 2]) < 1e-3);
        assert_true(fabs(sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5]) - 1.0) < 1e-4);
        float linear[3], quality;
        memcpy(linear, rec + 27, sizeof(linear));
        for (int k = 0; k < 3; k++) { /* sRGB bytes for viewers, the linear colour as floats */
            assert_int_equal(rec[24 + k], srgb_encode(rgb[3 * i + (size_t)k]));
            assert_true(linear[k] == rgb[3 * i + (size_t)k] / 255.0f);
        }
        memcpy(&quality, rec + 39, sizeof(quality));
        assert_true(quality == view.confidence[i]);
        seen++;
    }
    assert_int_equal(fread(line, 1, 1, f), 0); /* nothing after the last vertex */
    fclose(f);
    assert_int_equal(seen, count);
    /* The object frame puts the table at z = 0: the box stands on it. */
    test_rig_stop(&t);
}

/* Every entry of the encoding table is the sRGB formula (IEC 61966-2-1), and it rises. */
static void test_srgb_table(void **state)
{
    (void)state;
    for (int i = 0; i < 256; i++) {
        double x = i / 255.0;
        double e = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
        assert_int_equal(srgb_encode((uint8_t)i), (int)(e * 255.0 + 0.5));
        if (i > 0)
            assert_true(srgb_encode((uint8_t)i) >= srgb_encode((uint8_t)(i - 1)));
    }
    assert_int_equal(srgb_encode(0), 0);
    assert_int_equal(srgb_encode(255), 255);
    assert_int_equal(srgb_encode(46), 118); /* 18% grey reads as the middle of the scale */
}

/* A mesh vertex's 16-bit linear colour: a linear byte b given as b x 257 is encoded as the table
 * encodes b (a vertex the fusion grid coloured is written as before); every value the formula
 * rounded, rising. */
static void test_srgb_of_sixteen_bits(void **state)
{
    (void)state;
    for (int b = 0; b < 256; b++)
        assert_int_equal(srgb_encode16((uint16_t)(b * 257)), srgb_encode((uint8_t)b));
    for (int i = 0; i <= 65535; i++) {
        double x = i / 65535.0;
        double e = x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
        assert_true(fabs(srgb_encode16((uint16_t)i) - e * 255.0) <= 0.5);
        if (i > 0)
            assert_true(srgb_encode16((uint16_t)i) >= srgb_encode16((uint16_t)(i - 1)));
    }
}

/* outbuf_fixed and outbuf_u32 (the OBJ writer's numbers) write what printf's "%.*f" and "%u"
 * write: values of a mesh (mm, unit normals, colours, texture coordinates), their negatives,
 * negative zero, exact halves at the last digit (rounded to even, as printf), and values beyond
 * the integers' reach, which go through printf itself. */
static void test_outbuf_numbers(void **state)
{
    (void)state;
    struct hal_storage st;
    storage_posix_init(&st);
    const char *path = "build/test_outbuf.txt";
    static const double edge[] = {0.0,       -0.0,     -0.00001,  0.00005,       0.00015,
                                  1.0 / 32,  3.0 / 32, 1.0 / 128, -1.0 / 128,    0.5,
                                  999.99995, 1e9 - 1,  1e9,       -3e12,         123456.78901234,
                                  2.5 / 1e4, 1.0,      -1.0,      4095.0 / 4096, 1e-300};
    static const unsigned decimals[] = {0, 1, 4, 5, 6, 9, 12};
    char expect[64 * 1024], line[64];
    size_t len = 0;
    struct outbuf o;
    assert_int_equal(outbuf_open(&o, &st, path), 0);
    uint64_t seed = 12345;
    for (int i = 0; i < 600; i++) {
        double v;
        if (i < (int)(sizeof(edge) / sizeof(edge[0]))) {
            v = edge[i];
        } else { /* a mesh's spread of magnitudes */
            seed = seed * 6364136223846793005ull + 1442695040888963407ull;
            v = ((double)(seed >> 11) / 9007199254740992.0 - 0.5) * pow(10.0, (double)(i % 7) - 2);
        }
        for (size_t d = 0; d < sizeof(decimals) / sizeof(decimals[0]); d++) {
            int n =
                snprintf(line, sizeof(line), "%.*f ", (int)(decimals[d] > 9 ? 9 : decimals[d]), v);
            assert_true(n > 0 && len + (size_t)n < sizeof(expect));
            memcpy(expect + len, line, (size_t)n);
            len += (size_t)n;
            outbuf_fixed(&o, v, decimals[d]);
            outbuf_put(&o, " ", 1);
        }
        uint32_t u = i < 3 ? (uint32_t[]){0u, 9u, 4294967295u}[i] : (uint32_t)(seed >> 40);
        int n = snprintf(line, sizeof(line), "%u\n", u);
        memcpy(expect + len, line, (size_t)n);
        len += (size_t)n;
        outbuf_u32(&o, u);
        outbuf_put(&o, "\n", 1);
    }
    assert_int_equal(outbuf_close(&o), 0);
    static char got[64 * 1024];
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    size_t read = fread(got, 1, sizeof(got), f);
    fclose(f);
    assert_int_equal(read, len);
    assert_memory_equal(got, expect, len);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_srgb_table),
        cmocka_unit_test(test_srgb_of_sixteen_bits),
        cmocka_unit_test(test_outbuf_numbers),
        cmocka_unit_test(test_ply_roundtrip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
