/* GPIO device interface: the named output lines that drive the projector and the lights. */
#ifndef HAL_GPIO_H
#define HAL_GPIO_H

#include "hal_limits.h"

#include <stdint.h>

/** Logical output lines; the backend maps them to chip lines from the config. */
enum hal_gpio_line {
    HAL_GPIO_PROJECTOR_ENABLE = 0, /**< projector lamp on (1) / off (0) */
    HAL_GPIO_PROJECTOR_TRIGGER,    /**< rising edge advances the stored pattern sequence */
    HAL_GPIO_PROJECTOR_RESET,      /**< rising edge returns the sequence to pattern 0 */
    HAL_GPIO_LIGHT_0,              /**< first white light; light i is HAL_GPIO_LIGHT_0 + i */
    HAL_GPIO_LINE_COUNT = HAL_GPIO_LIGHT_0 + HAL_MAX_LIGHTS
};

#define HAL_GPIO_NAME_LEN 32u

/** Where a logical line is wired: a chip line offset, or the line's name as the chip (device
 *  tree) calls it. Offset -1 and an empty name: not wired. */
struct hal_gpio_line_ref {
    int32_t offset;               /**< line offset on the chip; -1 when named or not wired */
    char name[HAL_GPIO_NAME_LEN]; /**< line name ("GPIO17"); "" when given by offset */
};

/** Where the rig's lines are: a chip and a reference per line ([gpio] in a config). */
struct hal_gpio_config {
    char chip[64];                                      /**< gpiochip device or name */
    struct hal_gpio_line_ref line[HAL_GPIO_LINE_COUNT]; /**< offset or name; -1 and "": not wired */
};

struct hal_gpio_ops {
    /** Drive a line. @retval 0 ok @retval -EINVAL unknown or unmapped line @retval -EIO device
     * error */
    int (*set)(void *priv, enum hal_gpio_line line, int value);
    /** Read back the driven value (optional). @retval 0 ok, *value set */
    int (*get)(void *priv, enum hal_gpio_line line, int *value);
    /** Drive every line to its safe value: lights and projector off. Required. */
    int (*safe_state)(void *priv);
};

struct hal_gpio {
    const struct hal_gpio_ops *ops;
    void *priv;
};

/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_gpio_set(const struct hal_gpio *gpio, enum hal_gpio_line line, int value);
/** @retval -ENOSYS when the backend lacks the op; otherwise what the op returns. */
int hal_gpio_get(const struct hal_gpio *gpio, enum hal_gpio_line line, int *value);
/** Pulse a line high for @p width_us using @p clock. @retval 0 or the first error */
struct hal_clock;
int hal_gpio_pulse(const struct hal_gpio *gpio, const struct hal_clock *clock,
                   enum hal_gpio_line line, uint32_t width_us);

#endif
