/* scanner patterns: the written PNGs, read back, code every projector pixel's column and row. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gray.h"
#include "image_io.h"
#include "patterns.h"
#include "scan.h"
#include "storage_posix.h"
#include "test_util.h"

#define DIR "build/test_patterns"

static void test_patterns_code_every_pixel(void **state)
{
    (void)state;
    static struct test_rig t;
    assert_int_equal(test_rig_load(&t, "config/sim.ini"), 0);
    struct hal_storage st;
    storage_posix_init(&st);
    assert_int_equal(system("rm -rf " DIR), 0);
    assert_int_equal(patterns_write(&st, &t.cfg, &t.calib, DIR), 0);
    const uint32_t w = t.calib.proj_width, h = t.calib.proj_height;
    struct gray_layout l;
    gray_layout_for(w, h, 1, &l);
    uint32_t count = gray_layout_count(&l);
    assert_int_equal(count, 2u + 2u * (10u + 10u)); /* 1024 x 768: 10 bits each */
    size_t n = (size_t)w * h;
    uint8_t *img = malloc(n), *white = malloc(n);
    uint16_t *col = calloc(n, sizeof(uint16_t)), *row = calloc(n, sizeof(uint16_t));
    assert_non_null(img);
    assert_non_null(white);
    assert_non_null(col);
    assert_non_null(row);
    char path[256], why[128];
    uint32_t iw, ih;
    uint8_t *prev = white; /* a bit's frame, kept to compare with its inverse */
    for (uint32_t i = 0; i < count; i++) {
        snprintf(path, sizeof(path), DIR "/pattern_%02u.png", i);
        uint8_t *dst = i < 2 || (i - GRAY_PATTERN_FIRST_BIT) % 2u == 0 ? prev : img;
        assert_int_equal(image_read_png(path, dst, n, &iw, &ih, 1, why, sizeof(why)), 0);
        assert_int_equal(iw, w);
        assert_int_equal(ih, h);
        if (i == GRAY_PATTERN_WHITE || i == GRAY_PATTERN_BLACK) {
            for (size_t p = 0; p < n; p++)
                assert_int_equal(dst[p], i == GRAY_PATTERN_WHITE ? 255 : 0);
            continue;
        }
        if (dst == prev)
            continue;
        uint32_t k = (i - GRAY_PATTERN_FIRST_BIT) / 2u;
        for (size_t p = 0; p < n; p++) {
            assert_int_equal(prev[p] ^ img[p], 255); /* exactly the inverse */
            uint16_t *code = k < l.col_bits ? &col[p] : &row[p];
            *code = (uint16_t)((*code << 1) | (prev[p] == 255));
        }
    }
    for (uint32_t y = 0; y < h; y++)
        for (uint32_t x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            assert_int_equal(gray_decode(col[p]), x);
            assert_int_equal(gray_decode(row[p]), y);
        }
    FILE *f = fopen(DIR "/patterns.txt", "r");
    assert_non_null(f);
    char line[256];
    int said_scan = 0;
    while (fgets(line, sizeof(line), f) != NULL)
        said_scan |= strstr(line, "A scan steps through patterns 0..21") != NULL;
    fclose(f);
    assert_true(said_scan);
    free(img);
    free(white);
    free(col);
    free(row);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_patterns_code_every_pixel),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
