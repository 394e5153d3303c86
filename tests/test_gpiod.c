/* libgpiod backend without hardware: a missing chip gives a clear error and requests nothing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "gpio_gpiod.h"

static void test_missing_chip(void **state)
{
    (void)state;
    struct gpio_gpiod g;
    struct hal_gpio out = {NULL, NULL};
    struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT];
    char err[256];
    memset(lines, 0, sizeof(lines));
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++)
        lines[i].offset = (int32_t)i;
    int rc = gpio_gpiod_open(&g, "/dev/gpiochip-does-not-exist", lines, &out, err, sizeof(err));
    assert_true(rc < 0);
    assert_non_null(strstr(err, "cannot open chip '/dev/gpiochip-does-not-exist'"));
    assert_null(out.ops); /* no device handed to the firmware */
    assert_null(g.chip);  /* nothing left open */
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++)
        assert_null(g.line[i]);
}

static void test_line_names_match_config_keys(void **state)
{
    (void)state;
    char buf[32];
    assert_string_equal(gpio_line_name(HAL_GPIO_PROJECTOR_TRIGGER, buf, sizeof(buf)),
                        "projector_trigger");
    assert_string_equal(gpio_line_name(HAL_GPIO_LIGHT_0 + 3, buf, sizeof(buf)), "light_3");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_chip),
        cmocka_unit_test(test_line_names_match_config_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
