/* CIEDE2000 against the published test pairs of Sharma, Wu and Dalal (2005), Table 1. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "colour_metrics.h"

static void test_sharma_pairs(void **state)
{
    (void)state;
    static const double pairs[][7] = {
        {50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425},
        {50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615},
        {50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412},
        {50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000},
        {50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669},
        {50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792},
        {50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492},
        {60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644},
    };
    for (size_t i = 0; i < sizeof(pairs) / sizeof(pairs[0]); i++) {
        double d = colour_ciede2000(pairs[i], pairs[i] + 3);
        if (fabs(d - pairs[i][6]) > 1e-4)
            fail_msg("pair %zu: %.4f, expected %.4f", i + 1, d, pairs[i][6]);
        assert_true(fabs(colour_ciede2000(pairs[i] + 3, pairs[i]) - d) < 1e-9); /* symmetric */
    }
}

static void test_lab_of_white_and_grey(void **state)
{
    (void)state;
    double lab[3];
    colour_linear_rgb_to_lab((const double[3]){1, 1, 1}, lab);
    assert_true(fabs(lab[0] - 100.0) < 0.01 && fabs(lab[1]) < 0.01 && fabs(lab[2]) < 0.01);
    colour_linear_rgb_to_lab((const double[3]){0.18, 0.18, 0.18}, lab); /* 18% grey: L* ~ 49.5 */
    assert_true(fabs(lab[0] - 49.5) < 0.1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sharma_pairs),
        cmocka_unit_test(test_lab_of_white_and_grey),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
