/* GPIO backend on libgpiod (v1.6 API, Debian 12): the scanner's named lines as chip outputs. */
#ifndef GPIO_GPIOD_H
#define GPIO_GPIOD_H

#include "hal.h"

#include <stddef.h>

struct gpiod_chip;
struct gpiod_line;

struct gpio_gpiod {
    struct gpiod_chip *chip;
    struct gpiod_line *line[HAL_GPIO_LINE_COUNT]; /* NULL = not wired */
    int value[HAL_GPIO_LINE_COUNT];
};

/** Open @p chip_name and request every wired line (by offset, or by its name on that chip) as
 *  an output driven low, consumer "scanner". On failure nothing stays requested and @p err
 *  names chip, line and why.
 *  @retval 0 ok @retval -ENODEV no such chip or no line of that name @retval -EBUSY line used
 *  by another program @retval -errno */
int gpio_gpiod_open(struct gpio_gpiod *g, const char *chip_name,
                    const struct hal_gpio_line_ref lines[HAL_GPIO_LINE_COUNT], struct hal_gpio *out,
                    char *err, size_t err_len);
/** Drive every line low, release them and close the chip. */
void gpio_gpiod_close(struct gpio_gpiod *g);
/** Name of a logical line as the config writes it ("projector_enable", "light_3"). */
const char *gpio_line_name(enum hal_gpio_line line, char *buf, size_t len);

#endif
