/* libgpiod backend without hardware: a missing chip or a line another program holds gives a
 * clear error, and nothing stays requested or lit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <gpiod.h>
#include <stdio.h>
#include <string.h>

#include "gpio_gpiod.h"

/* ---- libgpiod, stood in for (linked with --wrap, see the Makefile) ----
 * Without a GPIO chip on the test machine (no gpio-sim in a container), the calls the backend
 * makes are answered here as libgpiod 1.6 answers them: a line that another program requested
 * makes gpiod_line_request_output() fail with EBUSY, and gpiod_line_consumer() then names that
 * program. With fake_chip off, every call goes to the real library. */
static int fake_chip;
static int busy_offset = -1; /* the line another program holds */
static char chip_obj, line_obj[HAL_GPIO_LINE_COUNT + 8];
static int requested[HAL_GPIO_LINE_COUNT + 8], driven[HAL_GPIO_LINE_COUNT + 8];
static int chip_open;

struct gpiod_chip *__real_gpiod_chip_open_lookup(const char *descr);
struct gpiod_line *__real_gpiod_chip_get_line(struct gpiod_chip *chip, unsigned int offset);
int __real_gpiod_line_request_output(struct gpiod_line *line, const char *consumer,
                                     int default_val);
const char *__real_gpiod_line_consumer(struct gpiod_line *line);
int __real_gpiod_line_set_value(struct gpiod_line *line, int value);
void __real_gpiod_line_release(struct gpiod_line *line);
void __real_gpiod_chip_close(struct gpiod_chip *chip);

static int offset_of(struct gpiod_line *line)
{
    return (int)((char *)line - line_obj);
}

struct gpiod_chip *__wrap_gpiod_chip_open_lookup(const char *descr)
{
    if (!fake_chip)
        return __real_gpiod_chip_open_lookup(descr);
    chip_open = 1;
    return (struct gpiod_chip *)&chip_obj;
}

struct gpiod_line *__wrap_gpiod_chip_get_line(struct gpiod_chip *chip, unsigned int offset)
{
    if (!fake_chip)
        return __real_gpiod_chip_get_line(chip, offset);
    if (offset >= sizeof(line_obj)) {
        errno = EINVAL;
        return NULL;
    }
    return (struct gpiod_line *)&line_obj[offset];
}

int __wrap_gpiod_line_request_output(struct gpiod_line *line, const char *consumer, int default_val)
{
    if (!fake_chip)
        return __real_gpiod_line_request_output(line, consumer, default_val);
    if (offset_of(line) == busy_offset) {
        errno = EBUSY;
        return -1;
    }
    requested[offset_of(line)] = 1;
    driven[offset_of(line)] = default_val;
    return 0;
}

const char *__wrap_gpiod_line_consumer(struct gpiod_line *line)
{
    if (!fake_chip)
        return __real_gpiod_line_consumer(line);
    return offset_of(line) == busy_offset ? "gpioset" : NULL;
}

int __wrap_gpiod_line_set_value(struct gpiod_line *line, int value)
{
    if (!fake_chip)
        return __real_gpiod_line_set_value(line, value);
    if (!requested[offset_of(line)]) {
        errno = EPERM;
        return -1;
    }
    driven[offset_of(line)] = value;
    return 0;
}

void __wrap_gpiod_line_release(struct gpiod_line *line)
{
    if (!fake_chip) {
        __real_gpiod_line_release(line);
        return;
    }
    requested[offset_of(line)] = 0;
}

void __wrap_gpiod_chip_close(struct gpiod_chip *chip)
{
    if (!fake_chip) {
        __real_gpiod_chip_close(chip);
        return;
    }
    chip_open = 0;
}

static void wire_by_offset(struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT])
{
    memset(lines, 0, sizeof(lines[0]) * HAL_GPIO_LINE_COUNT);
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++)
        lines[i].offset = (int32_t)i;
}

static void use_fake_chip(int busy)
{
    fake_chip = 1;
    busy_offset = busy;
    chip_open = 0;
    memset(requested, 0, sizeof(requested));
    memset(driven, 0, sizeof(driven));
}

static void assert_nothing_held(const struct gpio_gpiod *g, const struct hal_gpio *out)
{
    assert_null(out->ops); /* no device handed to the firmware */
    assert_null(g->chip);
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++) {
        assert_null(g->line[i]);
        assert_int_equal(requested[i], 0); /* given back to the kernel... */
        assert_int_equal(driven[i], 0);    /* ...low: lights and projector off */
    }
    assert_int_equal(chip_open, 0);
}

static void test_missing_chip(void **state)
{
    (void)state;
    struct gpio_gpiod g;
    struct hal_gpio out = {NULL, NULL};
    struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT];
    char err[256];
    fake_chip = 0; /* the real libgpiod, on a path that is no chip */
    wire_by_offset(lines);
    int rc = gpio_gpiod_open(&g, "/dev/gpiochip-does-not-exist", lines, &out, err, sizeof(err));
    assert_true(rc < 0);
    assert_non_null(strstr(err, "cannot open chip '/dev/gpiochip-does-not-exist'"));
    assert_null(out.ops);
    assert_null(g.chip);
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++)
        assert_null(g.line[i]);
}

/* Another program (gpioset, a light controller) holds one of the lights: the scanner says
 * which line and who has it, and gives back the lines it had already taken, driven low. */
static void test_line_in_use_by_another_program(void **state)
{
    (void)state;
    struct gpio_gpiod g;
    struct hal_gpio out = {NULL, NULL};
    struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT];
    char err[256], name[32], want[96];
    const unsigned busy = HAL_GPIO_LIGHT_0 + 1;
    wire_by_offset(lines);
    use_fake_chip((int)busy);
    int rc = gpio_gpiod_open(&g, "gpiochip0", lines, &out, err, sizeof(err));
    assert_int_equal(rc, -EBUSY);
    snprintf(want, sizeof(want), "gpio: %s: cannot request gpiochip0 line %u, in use by gpioset",
             gpio_line_name((enum hal_gpio_line)busy, name, sizeof(name)), busy);
    assert_non_null(strstr(err, want));
    assert_nothing_held(&g, &out);
    fake_chip = 0;
}

/* The same chip with every line free: all requested low, and closing gives them back low. */
static void test_free_lines_requested_low_and_released(void **state)
{
    (void)state;
    struct gpio_gpiod g;
    struct hal_gpio out = {NULL, NULL};
    struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT];
    char err[256];
    wire_by_offset(lines);
    use_fake_chip(-1);
    assert_int_equal(gpio_gpiod_open(&g, "gpiochip0", lines, &out, err, sizeof(err)), 0);
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++) {
        assert_int_equal(requested[i], 1);
        assert_int_equal(driven[i], 0);
    }
    assert_int_equal(hal_gpio_set(&out, HAL_GPIO_LIGHT_0 + 2, 1), 0);
    assert_int_equal(driven[HAL_GPIO_LIGHT_0 + 2], 1);
    gpio_gpiod_close(&g);
    out.ops = NULL;
    assert_nothing_held(&g, &out);
    fake_chip = 0;
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
        cmocka_unit_test(test_line_in_use_by_another_program),
        cmocka_unit_test(test_free_lines_requested_low_and_released),
        cmocka_unit_test(test_line_names_match_config_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
