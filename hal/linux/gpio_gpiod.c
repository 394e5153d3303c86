/* libgpiod v1.6 backend: lines requested once at start, driven low on every exit path. */
#define _POSIX_C_SOURCE 200809L
#include "gpio_gpiod.h"

#include <errno.h>
#include <gpiod.h>
#include <stdio.h>
#include <string.h>

const char *gpio_line_name(enum hal_gpio_line line, char *buf, size_t len)
{
    static const char *const fixed[] = {"projector_enable", "projector_trigger", "projector_reset"};
    if ((unsigned)line < HAL_GPIO_LIGHT_0)
        snprintf(buf, len, "%s", fixed[line]);
    else
        snprintf(buf, len, "light_%u", (unsigned)(line - HAL_GPIO_LIGHT_0));
    return buf;
}

static int gpiod_set(void *priv, enum hal_gpio_line line, int value)
{
    struct gpio_gpiod *g = priv;
    if ((unsigned)line >= HAL_GPIO_LINE_COUNT)
        return -EINVAL;
    if (g->line[line] == NULL)
        return value ? -EINVAL : 0; /* an unwired line can always be "off" */
    if (gpiod_line_set_value(g->line[line], value ? 1 : 0) != 0)
        return -errno;
    g->value[line] = value ? 1 : 0;
    return 0;
}

static int gpiod_get(void *priv, enum hal_gpio_line line, int *value)
{
    struct gpio_gpiod *g = priv;
    if ((unsigned)line >= HAL_GPIO_LINE_COUNT)
        return -EINVAL;
    *value = g->value[line];
    return 0;
}

static int gpiod_safe_state(void *priv)
{
    struct gpio_gpiod *g = priv;
    int first_rc = 0;
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++) {
        int rc = gpiod_set(g, (enum hal_gpio_line)i, 0);
        if (rc != 0 && first_rc == 0)
            first_rc = rc;
    }
    return first_rc;
}

static const struct hal_gpio_ops gpiod_ops = {
    .set = gpiod_set,
    .get = gpiod_get,
    .safe_state = gpiod_safe_state,
};

/* The chip's line for @p ref, by offset or by name; @p where says which, for messages.
 * @retval NULL with errno set */
static struct gpiod_line *find_line(struct gpiod_chip *chip, const struct hal_gpio_line_ref *ref,
                                    char *where, size_t len)
{
    if (ref->name[0] == '\0') {
        snprintf(where, len, "line %d", (int)ref->offset);
        return gpiod_chip_get_line(chip, (unsigned)ref->offset);
    }
    snprintf(where, len, "line '%s'", ref->name);
    struct gpiod_line *line = gpiod_chip_find_line(chip, ref->name);
    if (line == NULL && errno == ENOENT)
        errno = ENODEV; /* libgpiod 1.6 says ENOENT when no line of the chip has the name */
    return line;
}

int gpio_gpiod_open(struct gpio_gpiod *g, const char *chip_name,
                    const struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT], struct hal_gpio *out,
                    char *err, size_t err_len)
{
    char name[32], where[HAL_GPIO_NAME_LEN + 16];
    int rc = 0;
    memset(g, 0, sizeof(*g));
    g->chip = gpiod_chip_open_lookup(chip_name);
    if (g->chip == NULL) {
        rc = -(errno != 0 ? errno : ENODEV);
        snprintf(err, err_len, "gpio: cannot open chip '%s': %s", chip_name, strerror(-rc));
        return rc;
    }
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++) {
        if (lines[i].offset < 0 && lines[i].name[0] == '\0')
            continue;
        gpio_line_name((enum hal_gpio_line)i, name, sizeof(name));
        struct gpiod_line *line = find_line(g->chip, &lines[i], where, sizeof(where));
        if (line == NULL) {
            rc = -errno;
            snprintf(err, err_len, "gpio: %s: chip '%s' has no %s: %s", name, chip_name, where,
                     strerror(-rc));
            goto out_release;
        }
        if (gpiod_line_request_output(line, "scanner", 0) != 0) {
            rc = -errno;
            const char *user = gpiod_line_consumer(line);
            snprintf(err, err_len, "gpio: %s: cannot request %s %s%s%s: %s", name, chip_name, where,
                     user ? ", in use by " : "", user ? user : "", strerror(-rc));
            goto out_release;
        }
        g->line[i] = line;
    }
    out->ops = &gpiod_ops;
    out->priv = g;
    return 0;
out_release:
    gpio_gpiod_close(g);
    return rc;
}

void gpio_gpiod_close(struct gpio_gpiod *g)
{
    for (unsigned i = 0; i < HAL_GPIO_LINE_COUNT; i++) {
        if (g->line[i] == NULL)
            continue;
        gpiod_line_set_value(g->line[i], 0);
        gpiod_line_release(g->line[i]);
        g->line[i] = NULL;
    }
    if (g->chip != NULL)
        gpiod_chip_close(g->chip);
    g->chip = NULL;
}
